// gs_tendon_paths.h: MuJoCo's position stage with tendon paths that are finite and continuous
// where a site segment grazes a wrap geom.
//
// MuJoCo 2.2.2 (engine_util_misc.c, mju_wrap and wrap_circle) wraps a site-to-site segment
// around a cylinder or sphere when the segment passes inside the geom's circle. Where it passes
// less than about 2e-10 m inside (a graze: the two tangent points nearly coincide), MuJoCo
// - penalises the short wrap as self-intersecting (is_intersect() of two nearly collinear
//   segments that touch at the tangent point) and takes the far side of the geom: adductor
//   longus 31 mm longer than a pose 1e-12 rad away, or
// - takes acos() of the tangent points' dot product rounded above 1: a NaN length, Jacobian and
//   wrap points.
// Both were measured on adductor longus and its femoral-shaft cylinder (20.9 mm): the pose where
// eq. 3's band x 1.5 stopped the 1.0 m/s prediction (docs/BENCHMARKS.md, "A grazing wrap").
// At a graze the wrapped path and the straight one have the same length and the same derivative
// (the wrap's extra length grows as depth^1.5 / radius^0.5), so the straight path is the answer.
//
// gs_tendon_repair recomputes, after mj_tendon, every tendon whose segment passes inside a wrap
// geom by less than GS_TENDON_GRAZE_REL of its radius (where MuJoCo would wrap it; with a side
// site, on the side site's side of the geom only, the others wrap the long way on purpose) with
// that geom moved in mjData (the model is shared by threads) 2 x GS_TENDON_GRAZE_REL x radius
// away from the segment: the straight path, to within 2e-11 m of the wrapped one at 20 mm. A tendon
// still non-finite (no graze found) is recomputed with its wrap geoms moved by the same distance
// across the geom's axis, in four directions in turn. The other tendons keep their lengths and
// Jacobian rows bitwise (dense Jacobians, as MuJoCo uses below 60 DOF).
#ifndef GAITSIM_CALLBACKS_GS_TENDON_PATHS_H_
#define GAITSIM_CALLBACKS_GS_TENDON_PATHS_H_

#include <mujoco/mujoco.h>

// the graze band: depth inside a wrap geom, as a fraction of its radius (-); MuJoCo 2.2.2 fails
// up to 1e-8 of the radius (2e-10 m at 20.9 mm); fifty times that
#define GS_TENDON_GRAZE_REL 5e-7

// After mj_tendon and mj_transmission (kinematics computed): the repair above, geom positions
// restored, and mj_transmission again when a tendon was recomputed. Returns the number of tendons
// recomputed (0: d untouched), or -1 when one stays non-finite.
int gs_tendon_repair(const mjModel* m, mjData* d);

// mj_fwdPosition, then gs_tendon_repair; its return.
int gs_fwd_position(const mjModel* m, mjData* d);

// mj_inverse with gs_fwd_position's position stage (then mj_inverse's position-stage sensors and
// energy, and mj_inverseSkip(mjSTAGE_POS)): bitwise mj_inverse when no tendon is recomputed.
// gs_fwd_position's return.
int gs_inverse(const mjModel* m, mjData* d);

// mj_forward with gs_fwd_position's position stage (then mj_forward's position-stage sensors and
// energy, and mj_forwardSkip(mjSTAGE_POS)): bitwise mj_forward when no tendon is recomputed.
// gs_fwd_position's return.
int gs_forward(const mjModel* m, mjData* d);

#endif  // GAITSIM_CALLBACKS_GS_TENDON_PATHS_H_
