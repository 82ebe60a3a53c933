// gs_app_model.h: what every subcommand does to get a model ready: load, switch to gaitsim's
// physics, install the callbacks; and small helpers shared by the subcommands.
#ifndef GAITSIM_APP_GS_APP_MODEL_H_
#define GAITSIM_APP_GS_APP_MODEL_H_

#include <mujoco/mujoco.h>

#include "callbacks/gs_state.h"
#include "io/gs_table.h"

// Load MODEL and prepare it for gaitsim's physics (gs_physics_prepare, gs_physics_install).
// Prints "gaitsim: MODEL: reason" and returns NULL on failure.
mjModel* gs_app_load_model(const char* path);

// Read a storage file (.sto/.mot/.csv) for model m, angles converted to radians. Prints
// "gaitsim: FILE: reason" and returns -1 on failure.
int gs_app_read_table(const mjModel* m, const char* path, gsTable* t);

// Write table t to DIR/NAME atomically with gaitsim's header lines. Prints the reason and
// returns -1 on failure.
int gs_app_write_table(const char* dir, const char* name, const gsTable* t);

// Parse the JSON file at path (e.g. a solution's summary.json). Returns the document (caller
// frees with cJSON_Delete), or NULL when the file is missing, unreadable or not JSON.
struct cJSON* gs_app_read_json(const char* path);

// Default bundled model: JW's full body with the six-DOF implant knee (surrogate contact and
// ligaments, mjmodels/README.md "jw_fullbody_knee6.xml"). mjmodels/jw_fullbody.xml is the same
// model with the placeholder knee (a spring-damper on knee_ty).
#define GS_DEFAULT_MODEL GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody_knee6.xml"

// The model a solution folder was solved with: the "model" of DIR/summary.json when that file
// exists, copied into buf (size n). Returns buf, or NULL (no summary, no model entry, or the
// file is gone).
const char* gs_app_solution_model(const char* dir, char* buf, int n);

// The node count a solution folder was solved on: the "nodes" of DIR/summary.json, or -1 (no
// summary, no such entry, not a positive integer).
int gs_app_solution_nodes(const char* dir);

// Check a solution folder before it is read (predict --guess, track --init, render, report,
// sweep --guess): DIR is a folder with states.sto; summary.json, when present (required with
// require_summary), is valid JSON; every storage file of the folder reads without error; and
// states.sto, controls.sto and variables.sto have one row count, equal to summary.json's
// "nodes" when it says. Prints one line "gaitsim: FILE: reason" and returns -1 otherwise.
int gs_app_check_solution(const char* dir, int require_summary);

// Check that table t (read from path) has a column for every coordinate (hinge or slide joint)
// of m. Prints "gaitsim: PATH: no column for N of the model's M coordinates: a, b, ..." and
// returns -1 otherwise.
int gs_app_require_coordinates(const mjModel* m, const gsTable* t, const char* path);

// Read the pose or states file at path and check it with gs_app_require_coordinates. Prints one
// line and returns -1 otherwise.
int gs_app_check_pose_file(const mjModel* m, const char* path);
// The inputs of an inverse dynamics under measured or solved ground reactions (gaitsim balance,
// moments): the pose file (a states.sto or coordinates.mot with every coordinate, at least 3 rows
// for the differences) into t and its column map into map, and the ground reactions (OpenSim
// ExternalLoads columns, gs_balance_grf_columns) into g with their columns in col. Prints one line
// "gaitsim: FILE: reason" and returns -1 otherwise (the tables and map stay the caller's to free).
int gs_app_read_pose_and_loads(const mjModel* m, const char* pose, const char* grf, gsTable* t,
                               gsStateMap* map, gsTable* g, int col[GS_GRF_NCOL]);

// Every row's qpos, qvel and qacc (n x nq, n x nv, n x nv; n = t->nrow >= 3) from table t
// (mapped by map, in radians) for inverse dynamics: the speeds from the file when it has every
// one, else by central differences of the rows (one-sided at the ends), the accelerations always
// by central differences of the speeds. Returns 1 when the speeds came from the file, 0 when
// differenced. d is scratch.
int gs_app_pose_kinematics(const mjModel* m, mjData* d, const gsTable* t,
                           const gsStateMap* map, double* q, double* v, double* a);

// The model to use on solution folder dir: `given` (a --model option) when not NULL, else the
// model dir/summary.json names (copied into buf, size n), else GS_DEFAULT_MODEL.
const char* gs_app_model_for_solution(const char* dir, const char* given, char* buf, int n);

#endif  // GAITSIM_APP_GS_APP_MODEL_H_
