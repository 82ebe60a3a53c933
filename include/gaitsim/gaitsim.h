// gaitsim.h: gaitsim's physics for a MuJoCo 2.2 C/C++ program (libgaitsim, pkg-config gaitsim).
//
// gaitsim adds to MuJoCo, through its callbacks, the physics MuJoCo lacks for human gait:
// Hill-type muscle-tendon units (rigid or elastic tendon) with first-order activation dynamics,
// smooth Hunt-Crossley foot-ground contact spheres, passive moments at the knees' extension
// limits (gs_limit_* numerics), and, in models that carry it, the implant knee's contact
// surrogate and ligaments. Models are gaitsim's MJCF files (the project's
// mjmodels/): parameters sit in actuator `user` rows and `numeric` elements, which stock MuJoCo
// ignores. Typical use:
//
//   mjModel* m = mj_loadXML(path, NULL, err, sizeof(err));
//   if (gs_lib_prepare(m, err, sizeof(err)) != 0) { ... }   // before mj_makeData
//   gs_lib_install();                                       // once, before any thread starts
//   mjData* d = mj_makeData(m);
//   ... set qpos, qvel, act, ctrl ...
//   gs_lib_equilibrate(m, d);                              // elastic tendons at rest
//   for (...) { ... set ctrl ...; gs_lib_step(m, d); }
//
// Ownership: the library returns nothing the caller must free. mjModel and mjData stay the
// caller's (mj_deleteModel, mj_deleteData, at any time after the last call that uses them).
// gs_lib_prepare changes the model in place; for an implant-knee model it also caches the knee's
// numbers inside the library, keyed by the model's address and re-checked against the model's
// contents on use, and keeps that small cache until the process ends. Messages are written into
// the caller's buffers.
//
// Threads: the callbacks are process-global MuJoCo pointers (mjcb_act_dyn, mjcb_act_gain,
// mjcb_act_bias, mjcb_passive): gs_lib_install sets them for every model in the process, so a
// program that also simulates models without gaitsim's physics must not call it. Call
// gs_lib_prepare and gs_lib_install from one thread before other threads start. After that
// everything here is thread-safe with one mjData per thread: the callbacks read parameters from
// the (then read-only) mjModel and state from the mjData they are given only. Several prepared
// models may be used at once. mjData must not be shared between threads.
//
// State beyond MuJoCo's: the normalised tendon force of each elastic-tendon muscle lives in
// d->userdata[i] (actuator i, dimensionless F_tendon / F_max); gs_lib_step integrates it with
// q, qdot and act. mj_step alone would leave it constant.
//
// Errors: functions that can fail return 0 on success and -1 on failure with one line in err
// (errsz bytes). Nothing is printed and nothing exits.
#ifndef GAITSIM_GAITSIM_H_
#define GAITSIM_GAITSIM_H_

#include <mujoco/mujoco.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define GS_LIB_API __attribute__((visibility("default")))
#else
#define GS_LIB_API
#endif

// The library's version, e.g. "0.1.0" (static string).
GS_LIB_API const char* gs_lib_version(void);

// Switch model m to gaitsim's physics: its muscles get gaitsim's gain, bias and activation
// dynamics; MuJoCo's own contact solver is disabled (the foot spheres become gaitsim's smooth
// contact); nuserdata grows to nu. Checks every muscle's and contact sphere's parameters, the
// joint-limit laws and the implant-knee numerics when present. Call before mj_makeData. Returns
// 0, or -1 with the reason (naming the actuator, geom or numeric) in err.
GS_LIB_API int gs_lib_prepare(mjModel* m, char* err, int errsz);

// Install gaitsim's callbacks (process-global). Idempotent. Call once before threads start.
GS_LIB_API void gs_lib_install(void);

// Put every elastic tendon of d in static equilibrium (zero fibre velocity) at d's positions and
// activations: sets d->userdata. Runs mj_fwdPosition. Call after setting qpos and act.
GS_LIB_API void gs_lib_equilibrate(const mjModel* m, mjData* d);

// One time step of m->opt.timestep: MuJoCo's integrator for q, qdot and act (mj_step1, mj_step2)
// and semi-implicit Euler for the tendon states. Returns 0, or -1 when a state became non-finite.
GS_LIB_API int gs_lib_step(const mjModel* m, mjData* d);

// Tendon tension of actuator i (N, >= 0 when pulling) at d's current state, after mj_forward.
// For a gaitsim muscle the Hill model's; for any other actuator -actuator_force.
GS_LIB_API double gs_lib_muscle_force(const mjModel* m, const mjData* d, int i);

// Ground reaction on one foot (side 'r' or 'l') from its contact spheres at d's state, after
// mj_forward: force (N, world frame, z up) and centre of pressure (m, world; zeros when the foot
// carries under 5 N). Returns 1 when the foot carries load, 0 when not, -1 for a bad side.
GS_LIB_API int gs_lib_foot_force(const mjModel* m, const mjData* d, char side, double force[3],
                                 double cop[3]);

#ifdef __cplusplus
}
#endif

#endif  // GAITSIM_GAITSIM_H_
