// path_probe.c: MuJoCo's own muscle-path lengths and moment arms for scripts/fit_wraps.py, which
// moves the wrap geoms and sites of a loaded model in place (no recompilation) and asks for the
// paths again. Model preparation only (built as `path_probe`; not part of gaitsim's commands).
//
// usage: path_probe MODEL.xml
// Prints "joints NAME..." (qpos order; hinge/slide models only, qpos k = dof k) and "ready", then
// reads commands from stdin, one per line:
//   pose Q0 .. Q(nq-1)                      add a pose (qpos: rad, m)
//   clear                                   forget the poses
//   geom NAME PX PY PZ QW QX QY QZ S0 S1    set geom_pos (m, parent body frame), geom_quat and
//                                           geom_size[0..1] (radius, half-length; m)
//   site NAME PX PY PZ                      set site_pos (m, parent body frame)
//   eval TENDON                             one line per pose: "L R0 .. R(nv-1) C", the path
//                                           length (m), the moment arms r = -dL/dq (m/rad, m/m)
//                                           and the clearance C (m): the least distance of a site
//                                           next to a wrap geom from its surface (sphere: from the
//                                           centre, cylinder: from the axis, minus the radius;
//                                           negative inside, where MuJoCo's wrap is ill-posed),
//                                           then "end"
//   quit
// Errors (unknown name, wrong count) print "error REASON" and keep reading.
#include <mujoco/mujoco.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "callbacks/gs_mujoco.h"

#define MAX_LINE 65536  // longest command line (bytes)
#define MAX_POSE 4096   // poses kept at once (count)

// parse exactly n doubles from s into v; returns 1 on success
static int parse_doubles(char* s, double* v, int n) {
  for (int k = 0; k < n; k++) {
    char* end = NULL;
    v[k] = strtod(s, &end);
    if (end == s) {
      return 0;
    }
    s = end;
  }
  while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r') {
    s++;
  }
  return *s == '\0';
}

// least distance (m) of the sites next to tendon t's wrap geoms from their surfaces (after
// mj_kinematics); 1 (m) if the tendon has no wrap geom
static double wrap_clearance(const mjModel* m, const mjData* d, int t) {
  double least = 1.0;
  int adr = m->tendon_adr[t], num = m->tendon_num[t];
  for (int k = 1; k + 1 < num; k++) {
    int type = m->wrap_type[adr + k], g = m->wrap_objid[adr + k];
    if (type != mjWRAP_SPHERE && type != mjWRAP_CYLINDER) {
      continue;
    }
    for (int nb = -1; nb <= 1; nb += 2) {
      if (m->wrap_type[adr + k + nb] != mjWRAP_SITE) {
        continue;
      }
      const mjtNum* x = d->site_xpos + 3 * m->wrap_objid[adr + k + nb];
      mjtNum rel[3], local[3];
      mju_sub3(rel, x, d->geom_xpos + 3 * g);
      mju_mulMatTVec(local, d->geom_xmat + 9 * g, rel, 3, 3);
      double dist = type == mjWRAP_SPHERE ? mju_norm3(local)
                                          : mju_sqrt(local[0] * local[0] + local[1] * local[1]);
      dist -= m->geom_size[3 * g];
      least = dist < least ? dist : least;
    }
  }
  return least;
}

// the first word of *s (NUL-terminated in place); *s moves past it
static char* word(char** s) {
  char* p = *s + strspn(*s, " \t");
  size_t n = strcspn(p, " \t\r\n");
  *s = p + n + (p[n] ? 1 : 0);
  p[n] = '\0';
  return p;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: path_probe MODEL.xml\n");
    return 2;
  }
  gs_mujoco_install_handlers();
  char err[1000];
  mjModel* m = gs_model_load(argv[1], err, sizeof(err));
  if (!m) {
    fprintf(stderr, "path_probe: %s: %s\n", argv[1], err);
    return 1;
  }
  if (m->nq != m->nv) {
    fprintf(stderr, "path_probe: %s: ball or free joints (nq %d != nv %d)\n", argv[1], m->nq,
            m->nv);
    return 1;
  }
  mjData* d = mj_makeData(m);
  mjtNum* poses = (mjtNum*)malloc(sizeof(mjtNum) * MAX_POSE * m->nq);
  char* line = (char*)malloc(MAX_LINE);
  double* v = (double*)malloc(sizeof(double) * (m->nq > 9 ? m->nq : 9));
  if (!d || !poses || !line || !v) {
    fprintf(stderr, "path_probe: out of memory\n");
    return 1;
  }
  int npose = 0;
  printf("joints");
  for (int j = 0; j < m->njnt; j++) {
    printf(" %s", mj_id2name(m, mjOBJ_JOINT, j));
  }
  printf("\nready\n");
  fflush(stdout);
  while (fgets(line, MAX_LINE, stdin)) {
    char* rest = line;
    char* cmd = word(&rest);
    if (!strcmp(cmd, "quit")) {
      break;
    } else if (!strcmp(cmd, "clear")) {
      npose = 0;
    } else if (!strcmp(cmd, "pose")) {
      if (npose == MAX_POSE || !parse_doubles(rest, v, m->nq)) {
        printf("error pose: %d values wanted (or too many poses)\n", m->nq);
      } else {
        memcpy(poses + npose++ * m->nq, v, sizeof(mjtNum) * m->nq);
      }
    } else if (!strcmp(cmd, "geom") || !strcmp(cmd, "site")) {
      int is_geom = !strcmp(cmd, "geom");
      char* name = word(&rest);
      int id = mj_name2id(m, is_geom ? mjOBJ_GEOM : mjOBJ_SITE, name);
      if (id < 0 || !parse_doubles(rest, v, is_geom ? 9 : 3)) {
        printf("error %s %s: unknown, or not %d numbers\n", cmd, name, is_geom ? 9 : 3);
      } else if (is_geom) {
        mju_copy3(m->geom_pos + 3 * id, v);
        mju_copy4(m->geom_quat + 4 * id, v + 3);
        mju_normalize4(m->geom_quat + 4 * id);
        m->geom_size[3 * id] = v[7];
        m->geom_size[3 * id + 1] = v[8];
      } else {
        mju_copy3(m->site_pos + 3 * id, v);
      }
    } else if (!strcmp(cmd, "eval")) {
      char* name = word(&rest);
      int t = mj_name2id(m, mjOBJ_TENDON, name);
      if (t < 0) {
        printf("error eval %s: no such tendon\n", name);
      } else {
        for (int k = 0; k < npose; k++) {
          mju_copy(d->qpos, poses + k * m->nq, m->nq);
          mj_kinematics(m, d);
          mj_comPos(m, d);
          mj_tendon(m, d);
          mju_zero(v, m->nv);  // dL/dq of tendon t: row t of ten_J, sparse or dense
          if (mj_isSparse(m)) {
            for (int k2 = 0; k2 < d->ten_J_rownnz[t]; k2++) {
              int adr = d->ten_J_rowadr[t] + k2;
              v[d->ten_J_colind[adr]] = d->ten_J[adr];
            }
          } else {
            mju_copy(v, d->ten_J + t * m->nv, m->nv);
          }
          printf("%.12g", d->ten_length[t]);
          for (int i = 0; i < m->nv; i++) {
            printf(" %.12g", -v[i]);
          }
          printf(" %.12g", wrap_clearance(m, d, t));
          printf("\n");
        }
        printf("end\n");
      }
    } else if (cmd[0]) {
      printf("error unknown command %s\n", cmd);
    }
    fflush(stdout);
  }
  free(v);
  free(line);
  free(poses);
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
