// gs_physics.h: gaitsim's physics inside MuJoCo. This is the one file that installs mjcb_*.
//
// MuJoCo computes the multibody dynamics; gaitsim adds through MuJoCo's callbacks what MuJoCo
// lacks (DESIGN.md, "Contacts are ours"):
//   mjcb_act_dyn    first-order activation dynamics of each Hill muscle (gs_activation.h)
//   mjcb_act_gain   Hill muscle-tendon force (gs_muscle.h): rigid tendons from fibre kinematics,
//   mjcb_act_bias   elastic tendons from the normalised tendon force state in d->userdata
//   mjcb_passive    smooth Hunt-Crossley foot-ground contact of every contact sphere
//                   (gs_contact.h), applied to qfrc_passive; MuJoCo's own contacts are disabled;
//                   the implant knee (gs_knee.h); coordinate couplings written as MJCF joint
//                   equalities, held by a stiff spring (gs_coupling.h)
// Callbacks are pure functions of (m, d, i): every parameter comes from the model
// (gs_model_layout.h), every per-evaluation state from d (d->userdata). They are thread-safe with
// one mjData per thread.
//
// Per-evaluation muscle state (d->userdata, GS_USERDATA_SIZE(m) doubles):
//   userdata[i], i < nu   normalised tendon force f~T = F_T / Fmax of actuator i   (-)
//                         (elastic-tendon muscles; ignored for the others)
#ifndef GAITSIM_CALLBACKS_GS_PHYSICS_H_
#define GAITSIM_CALLBACKS_GS_PHYSICS_H_

#include <mujoco/mujoco.h>

#include "callbacks/gs_contact.h"
#include "callbacks/gs_metabolics.h"
#include "callbacks/gs_muscle.h"

// doubles of d->userdata the physics uses
#define GS_USERDATA_SIZE(m) ((m)->nu)

// Switch model m to gaitsim's physics: gaitsim muscles get user gain, bias and dynamics; MuJoCo's
// contact solver is disabled (the spheres become ours); active joint equalities become
// gaitsim's couplings (gs_coupling_adopt); nuserdata grows to GS_USERDATA_SIZE.
// Checks every muscle's and contact sphere's parameters. A model with implant-knee numerics
// (gs_knee_*) has them checked and registered once here (gs_knee.h), so the passive callback
// does no name look-ups; inconsistent numerics fail. Call before mj_makeData. Returns 0, or -1
// with the reason (naming the actuator, geom or numeric) in err.
int gs_physics_prepare(mjModel* m, char* err, int errsz);

// Install the callbacks (process-global). Call once, before threads start. Idempotent.
void gs_physics_install(void);

// Tendon tension (N, >= 0 when pulling) of gaitsim muscle actuator i at the current state:
// rigid tendon from activation and actuator length/velocity; elastic tendon Fmax * userdata[i].
// out (may be NULL) receives fibre length, velocity, pennation and force components; for elastic
// tendons the fibre velocity is the one that satisfies the Hill equilibrium (forward model).
// Needs actuator_length/velocity (mj_fwdPosition, mj_fwdVelocity).
double gs_physics_muscle_tension(const mjModel* m, const mjData* d, int i, gsMuscleOut* out);

// Metabolic power (W) of gaitsim muscle actuator i at the current state (Umberger 2010, exact
// model, gs_metabolics.h): excitation ctrl[i], activation, fibre length and velocity from the
// muscle state (gs_physics_muscle_tension). terms (may be NULL) receives every term.
double gs_physics_muscle_metabolics(const mjModel* m, const mjData* d, int i,
                                    gsUmbergerTerms* terms);

// Static equilibrium of the elastic tendons: for every elastic-tendon muscle i whose state is
// not given (given == NULL or given[i] < 0), set d->userdata[i] to the normalised tendon force in
// Hill equilibrium at zero velocity for its activation and actuator length
// (gs_muscle_equilibrium_fT). Needs mj_fwdPosition. given: per actuator (nu), e.g. a state
// file's column map (gsStateMap.fT_col).
void gs_physics_equilibrate_tendons(const mjModel* m, mjData* d, const int* given);

// Normalised tendon-force rate dfT/dt (1/s) of every elastic-tendon muscle at the current state,
// from the Hill equilibrium (forward model), into fT_dot (nu; 0 for other actuators). Needs
// mj_fwdPosition and mj_fwdVelocity. Returns the number of muscles whose equilibrium was clamped.
int gs_physics_tendon_force_rates(const mjModel* m, const mjData* d, mjtNum* fT_dot);

// One forward-simulation step with the fibre states integrated too: mj_step1, tendon-force rates
// at the step's start state, mj_step2 (MuJoCo integrates q, qdot, act), then semi-implicit Euler
// on d->userdata with the same timestep. fT_dot is scratch (nu). Returns 0, or -1 when a state
// became non-finite.
int gs_physics_step(const mjModel* m, mjData* d, mjtNum* fT_dot);

// Hunt-Crossley forces of every contact sphere added to d->qfrc_passive (the mjcb_passive body;
// exposed for tests). Needs positions and velocities (mj_fwdPosition, mj_fwdVelocity's comVel).
void gs_physics_contact_passive(const mjModel* m, mjData* d);

// Hunt-Crossley contact of geom g with the floor at the current state (gs_contact_sphere with the
// sphere's centre velocity and its body's velocity at the contact point): force on the body, where
// it acts, depth and its rate. Returns 1, or 0 (out untouched) when g is not a contact sphere.
int gs_physics_sphere_contact(const mjModel* m, const mjData* d, int g, gsContactOut* out);

// Ground reaction of one foot (side 'r' or 'l') from its contact spheres at the current state:
// force, centre of pressure and free moment (gs_contact_foot_grf; COP defined above fn_min N).
void gs_physics_foot_grf(const mjModel* m, const mjData* d, int side, double fn_min,
                         gsFootGrf* grf);

#endif  // GAITSIM_CALLBACKS_GS_PHYSICS_H_
