// gs_state.h: model state <-> OpenSim storage tables, by name.
//
// Column names follow OpenSim 3.3 state storage (the JW model is an OpenSim 3 model):
//   "<coordinate>"                       coordinate value          (rad or m; deg in .mot files)
//   "<coordinate>_u"                     coordinate speed          (rad/s or m/s)
//   "<muscle>.activation"                activation                (-)
//   "<muscle>.normalized_tendon_force"   elastic-tendon state f~T  (-)
// Controls (excitations) files use "<muscle>" or "<muscle>.excitation". Ground reactions use
// OpenSim ExternalLoads names (ground_force_r_vx ... ground_torque_l_z), in the OpenSim ground
// frame (Y up); the model world is Z up (mjmodels/README.md): x_os = x, y_os = z, z_os = -y.
#ifndef GAITSIM_CALLBACKS_GS_STATE_H_
#define GAITSIM_CALLBACKS_GS_STATE_H_

#include <mujoco/mujoco.h>

#include "io/gs_table.h"

// Where each model quantity sits in a table: column index or -1 when absent.
typedef struct gsStateMap_ {
  int* qpos_col;   // coordinate value columns                  (nq)
  int* qvel_col;   // coordinate speed columns                  (nv)
  int* act_col;    // activation columns                        (na)
  int* fT_col;     // normalised tendon force columns           (nu)
  int* ctrl_col;   // excitation columns                        (nu)
  int nq_found;    // coordinates found
  int nv_found;    // speeds found
  int na_found;    // activations found
  int nfT_found;   // tendon forces found
  int nctrl_found; // excitations found
} gsStateMap;

// Predicate for gs_table_to_radians: 1 when label is a hinge coordinate of model `user`
// (const mjModel*) or its speed ("<hinge>_u").
int gs_state_is_angle(const char* label, void* user);

// Map table t's columns onto model m. Fails (err names the column) when two columns map to the
// same quantity. Free with gs_state_map_free.
int gs_state_map(const mjModel* m, const gsTable* t, gsStateMap* map, char* err, int errsz);
void gs_state_map_free(gsStateMap* map);

// Write the mapped quantities of table t at `time` (s; linear interpolation, clamped to the
// table's time range) into d: qpos, qvel, act, userdata (f~T), ctrl. Others stay as they are.
// t must be in radians (gs_table_to_radians with gs_state_is_angle).
void gs_state_apply(const mjModel* m, const gsTable* t, const gsStateMap* map, double time,
                    mjData* d);

// A states table of nrow rows: every coordinate, speed, activation and elastic tendon force, in
// radians (inDegrees=no). Fill rows with gs_state_table_set_row.
int gs_state_table_create(const mjModel* m, int nrow, gsTable* t, char* err, int errsz);
void gs_state_table_set_row(const mjModel* m, const mjData* d, double time, gsTable* t, int row);

// A ground reaction table (OpenSim ExternalLoads columns, both feet, 18 columns) of nrow rows;
// gs_grf_table_set_row fills one row from the model's contact spheres (COP defined above 5 N).
int gs_grf_table_create(int nrow, gsTable* t, char* err, int errsz);
// the 18 column names of a ground reaction table, in that order (right then left foot: force
// vx vy vz, centre of pressure px py pz, free moment x y z)
#define GS_GRF_NCOL 18
extern const char* const gs_grf_labels[GS_GRF_NCOL];
void gs_grf_table_set_row(const mjModel* m, const mjData* d, double time, gsTable* t, int row);

#endif  // GAITSIM_CALLBACKS_GS_STATE_H_
