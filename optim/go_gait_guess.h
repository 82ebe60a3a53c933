// go_gait_guess.h: initial guess of the gait problem (go_gait.h) from a measured trial.
//
// Coordinates: the measured table's samples, their speeds and accelerations by central
// differences on the table's own grid with the stride wrapped periodically (the sample before the
// first is the one before the last, shifted by the stride's net change, so pelvis_tx's progression
// is kept), then linearly resampled at the node times. Coordinates absent from the table: the
// model's qpos0, speed 0. q' = qdot. Activations and excitations constant; adot = 0. Tendon
// forces in static equilibrium (gs_muscle_equilibrium_fT at the node's muscle-tendon length), fT'
// by periodic central differences over the nodes. Ground reaction variables: the model's contact
// forces at the node's q, qdot (so the grf path rows hold exactly).
#ifndef GAITSIM_OPTIM_GO_GAIT_GUESS_H_
#define GAITSIM_OPTIM_GO_GAIT_GUESS_H_

#include "io/gs_table.h"
#include "optim/go_gait.h"

// Fill z (N nz, physical, the NLP's node-major order) for problem g from coords (radians, model
// coordinate names, >= 3 rows spanning the stride); activation in [0.001, 1] for every muscle.
// Returns 0, or -1 with the reason in err.
int go_gait_guess_from_trial(const go_gait* g, const gsTable* coords, double activation,
                             double* z, char* err, int errsz);

// Fill z (N nz, physical) from a solution of a gait problem on the same model, e.g. the same
// problem on fewer nodes (mesh continuation) or a tracking solution as the guess of a prediction:
// states (gs_state.h columns, radians: coordinates, speeds, activations, tendon forces; time
// spanning the stride) and controls (excitations), both linearly interpolated at the node times
// t_k = t_0 + T' k / (N - 1) with T' = the states' time span times time_scale (> 0; 1 keeps the
// stride, 0.8 makes it 20 % shorter, with speeds and derivatives scaled by 1/time_scale and the
// forward translation kept). Missing quantities as in go_gait_guess_from_trial (activation
// `activation`, tendon forces in equilibrium). q' = qdot; qddot, adot and fT' by periodic
// central differences over the nodes; ground reaction variables from the model's contact. Returns
// 0, or -1 with the reason in err.
int go_gait_guess_from_solution(const go_gait* g, const gsTable* states, const gsTable* controls,
                                double time_scale, double activation, double* z, char* err,
                                int errsz);

#endif  // GAITSIM_OPTIM_GO_GAIT_GUESS_H_
