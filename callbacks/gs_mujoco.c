// gs_mujoco.c: MuJoCo error handling and model loading (see gs_mujoco.h).
#include "callbacks/gs_mujoco.h"

#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// per-thread landing point for MuJoCo errors, set while loading a model
static _Thread_local jmp_buf* gs_error_landing = NULL;
static _Thread_local char gs_error_message[1024];

// MuJoCo calls this from mju_error; it must not return into MuJoCo
static void gs_on_mujoco_error(const char* msg) {
  if (gs_error_landing) {
    snprintf(gs_error_message, sizeof(gs_error_message), "%s", msg);
    longjmp(*gs_error_landing, 1);
  }
  fprintf(stderr, "gaitsim: MuJoCo: %s\n", msg);
  exit(1);
}

// warnings once per text; MuJoCo repeats some every step
static void gs_on_mujoco_warning(const char* msg) {
  static _Thread_local char last[512];
  if (strncmp(last, msg, sizeof(last) - 1) == 0) {
    return;
  }
  snprintf(last, sizeof(last), "%s", msg);
  fprintf(stderr, "gaitsim: MuJoCo warning: %s\n", msg);
}

void gs_mujoco_install_handlers(void) {
  mju_user_error = gs_on_mujoco_error;
  mju_user_warning = gs_on_mujoco_warning;
}

// one line from a MuJoCo message: newlines become "; ", a leading "Error: " goes
static void gs_one_line(char* s) {
  const char* prefix = "Error: ";
  size_t plen = strlen(prefix);
  if (strncmp(s, prefix, plen) == 0) {
    memmove(s, s + plen, strlen(s + plen) + 1);
  }
  char out[1024];
  size_t o = 0;
  for (const char* p = s; *p && o + 3 < sizeof(out); p++) {
    if (*p == '\n' || *p == '\r') {
      while (o > 0 && (out[o - 1] == ' ' || out[o - 1] == ':' || out[o - 1] == ';')) {
        o--;
      }
      if (o > 0 && p[1] && p[1] != '\n') {
        out[o++] = ';';
        out[o++] = ' ';
      }
    } else {
      out[o++] = *p;
    }
  }
  while (o > 0 && (out[o - 1] == ' ' || out[o - 1] == ';')) {
    o--;
  }
  out[o] = '\0';
  memcpy(s, out, o + 1);
}

mjModel* gs_model_load(const char* path, char* err, int errsz) {
  err[0] = '\0';
  FILE* probe = fopen(path, "rb");
  if (!probe) {
    snprintf(err, errsz, "cannot open file");
    return NULL;
  }
  fclose(probe);

  jmp_buf landing;
  jmp_buf* outer = gs_error_landing;
  mjModel* volatile m = NULL;
  if (setjmp(landing) == 0) {
    gs_error_landing = &landing;
    size_t n = strlen(path);
    if (n > 4 && strcmp(path + n - 4, ".mjb") == 0) {
      m = mj_loadModel(path, NULL);
      if (!m) {
        snprintf(err, errsz, "not a valid MJB model file");
      }
    } else {
      char msg[1024] = "";
      m = mj_loadXML(path, NULL, msg, sizeof(msg));
      if (!m) {
        gs_one_line(msg);
        snprintf(err, errsz, "%s", msg[0] ? msg : "model failed to compile");
      }
    }
  } else {
    gs_one_line(gs_error_message);
    snprintf(err, errsz, "%s", gs_error_message);
    m = NULL;
  }
  gs_error_landing = outer;
  return m;
}

const char* gs_joint_type_name(int type) {
  switch (type) {
    case mjJNT_FREE:
      return "free";
    case mjJNT_BALL:
      return "ball";
    case mjJNT_SLIDE:
      return "slide";
    case mjJNT_HINGE:
      return "hinge";
    default:
      return "unknown";
  }
}
