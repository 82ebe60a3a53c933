// gr_motion.h: what the renderer shows, read from a solution folder or a pose file and mapped
// onto a MuJoCo model by name.
//
// A solution folder (written by `gaitsim track`, DESIGN.md "Data flow") must hold
//   states.sto    time + coordinates by joint name (deg when inDegrees=yes), optionally speeds
//                 "<joint>_u" and activations "<actuator>.activation";
//   controls.sto  excitations per muscle ("<actuator>" or "<actuator>.excitation");
//   grf.mot       ground reactions, OpenSim ExternalLoads columns ground_force_{r,l}_v{x,y,z} (N)
//                 and centre of pressure ground_force_{r,l}_p{x,y,z} (m), OpenSim ground frame
//                 (Y up): world = (x, -z, y) (mjmodels/README.md "Frames");
// and may hold
//   knee_contact.sto  knee contact force, column contact_total_r (and contact_total_l) (N).
// Every file present is read and checked; any missing required file, unreadable or malformed
// file, a table without a single model coordinate, or time ranges that do not cover the stride
// is an error naming the file. Muscles are coloured by the activations of states.sto when it has
// them, else by the excitations of controls.sto.
//
// The stride is states.sto's time range [t0, t1]; repeated cycles add the stride's forward
// displacement (pelvis_tx(t1) - pelvis_tx(t0), m, or the root slide joint's) per cycle to that
// coordinate and to the centres of pressure.
//
// Errors: 0 on success, -1 with one line "FILE: reason" in err. Nothing is printed.
#ifndef GAITSIM_RENDER_GR_MOTION_H_
#define GAITSIM_RENDER_GR_MOTION_H_

#include <mujoco/mujoco.h>

#include "callbacks/gs_state.h"
#include "io/gs_table.h"

// One foot's ground reaction columns in grf.mot (-1 when absent).
typedef struct grFootColumns_ {
  int force[3];  // ground_force_?_v{x,y,z} columns (OpenSim ground frame)
  int cop[3];    // ground_force_?_p{x,y,z} columns (OpenSim ground frame)
} grFootColumns;

typedef struct grMotion_ {
  gsTable states;          // coordinates (radians, m), maybe speeds and activations (rows x cols)
  gsStateMap smap;         // states columns -> model quantities
  gsTable controls;        // excitations (rows x muscles); empty when not given
  gsStateMap cmap;         // controls columns -> model quantities
  int has_controls;        // 1 when controls were read
  gsTable grf;             // ground reactions (N, m; OpenSim ground frame); empty when absent
  int has_grf;             // 1 when grf.mot was read
  grFootColumns foot[2];   // right (0) and left (1) foot columns of grf
  gsTable knee;            // knee contact force (N); empty when absent
  int knee_col[2];         // right/left contact_total columns of knee, -1 when absent
  double t0, t1;           // stride start and end: states' time range (s)
  int advance_qpos;        // qpos index of the forward coordinate (pelvis_tx), -1 when none
  double advance;          // forward displacement per stride (m, world x)
  double body_weight;      // model's total mass times |gravity| (N)
} grMotion;

// What one frame shows besides the model pose.
typedef struct grFrameForces_ {
  int grf_on[2];       // 1 when the foot carries more than 5 N (right, left)
  double grf[2][3];    // ground reaction force on each foot, world frame (N)
  double cop[2][3];    // centre of pressure, world frame (m)
  int knee_on[2];      // 1 when a knee contact force is known (right, left)
  double knee[2];      // knee contact force magnitude (N)
  int colour_source;   // muscle colours from: 0 none (model colours), 1 d->act, 2 d->ctrl
  double time;         // time within the stride, from its start (s)
  double phase;        // fraction of the cycle, 0..1
  int cycle;           // cycle index, 0-based
} grFrameForces;

// Read the solution folder dir for model m.
int gr_motion_load_solution(const mjModel* m, const char* dir, grMotion* mo, char* err,
                            int errsz);

// Read one pose file (states.sto or coordinates .mot) for model m: no forces, no colours
// unless it carries activations.
int gr_motion_load_pose(const mjModel* m, const char* path, grMotion* mo, char* err, int errsz);

// Stride time t1 - t0 (s).
double gr_motion_stride_time(const grMotion* mo);

// Pose the model at time t (s, from the start of the first cycle; cycles repeat every stride
// time with forward translation), writing qpos, act and ctrl of d (others untouched), and fill
// out with the forces and the clock. Does not run any mj_ computation.
void gr_motion_apply(const mjModel* m, const grMotion* mo, double t, mjData* d,
                     grFrameForces* out);

void gr_motion_free(grMotion* mo);

#endif  // GAITSIM_RENDER_GR_MOTION_H_
