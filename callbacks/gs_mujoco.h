// gs_mujoco.h: MuJoCo set-up shared by every gaitsim program: error and warning handlers that
// never prompt on stdin or write MUJOCO_LOG.TXT, and model loading with a one-line reason.
#ifndef GAITSIM_CALLBACKS_GS_MUJOCO_H_
#define GAITSIM_CALLBACKS_GS_MUJOCO_H_

#include <mujoco/mujoco.h>

// Install mju_user_error and mju_user_warning. Call once at start-up, before any thread starts.
// Errors raised by MuJoCo inside gs_mujoco_guard()ed code return to the guard; outside a guard
// the message is printed as "gaitsim: MuJoCo: <message>" and the process exits with status 1
// (MuJoCo's error contract forbids returning into it). Warnings go to stderr once per distinct
// text, prefixed "gaitsim: MuJoCo warning: ".
void gs_mujoco_install_handlers(void);

// Load and compile an MJCF (or MJB, by extension) model. Returns NULL on failure and writes the
// reason into err (one line, no file prefix; the caller prints "gaitsim: PATH: reason"). The
// caller frees the model with mj_deleteModel.
mjModel* gs_model_load(const char* path, char* err, int errsz);

// Body-frame name of joint j's type, for people: "slide", "hinge", "ball" or "free".
const char* gs_joint_type_name(int type);

#endif  // GAITSIM_CALLBACKS_GS_MUJOCO_H_
