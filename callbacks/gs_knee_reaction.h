// gs_knee_reaction.h: knee contact force of a knee without a contact model (the left, 1-DOF
// hinge knee of the jw models) by a joint-reaction computation on the multibody dynamics: the
// force the femur exerts on the tibia through the articular surfaces, and its compressive
// component along the tibia's long axis.
//
// Method (Newton's second law on the subtree S below the knee, as OpenSim's Joint Reaction
// Analysis, which Lin, Walter & Pandy 2018 (Ann Biomed Eng 46:1216, Methods) used for the
// contralateral 1-DOF knee; the muscle and external-load decomposition of Winby et al. 2009,
// J Biomech 42:2294):
//   F_int = dP_S/dt - m_S g                        force S needs from outside, world      (N)
//   F_J   = F_int - F_ground - sum_m F_m u_m       the rest: femur on tibia, articular    (N)
//   C     = -F_J . a                               compressive component, > 0 compressing (N)
// F_int is the force part of MuJoCo's cfrc_int of the subtree root after mj_rnePostConstraint
// (engine_core_smooth.c, MuJoCo 2.2.2: cacc with the world at -g, cfrc_body = cinert cacc +
// cvel x* cinert cvel, minus cfrc_ext, summed over the subtree; layout [torque(3), force(3)];
// the force part of a spatial force does not depend on the com-based reference point). gaitsim
// applies foot contact and muscles as generalised forces (qfrc_passive, actuator moments), not
// in cfrc_ext (MuJoCo's contacts are off, xfrc_applied is zero), so both are subtracted here:
//   F_ground  the contact spheres of every foot inside S (gs_physics_foot_grf), world
//   F_m u_m   every muscle whose path crosses the boundary of S: for each path segment from a
//             point on a body of S to a point on a body outside S, the tension F_m pulls the
//             inside point towards the outside one (u_m, unit, along the segment). Segments with
//             both ends inside S cancel (muscles with both ends in S, e.g. soleus, drop out).
//             Path points: d->wrap_xpos of the tendon (ten_wrapadr, ten_wrapnum); sites belong to
//             m->site_bodyid, wrap-geom tangent points to m->geom_bodyid[wrap_obj]; a pulley
//             (wrap_obj -2) divides the tension of the branches after it by its divisor.
// a: the tibia's long axis, the unit vector from the ankle joint centre to the knee joint centre
// (d->xanchor). It is the anatomical definition and does not depend on how a model orients the
// tibia's body frame; in jw_fullbody.xml the ankle (talus_l at (0, -0.44751, 0) of tibia_l) and the
// knee (knee_flexion_l at (0, -0.00235, 0)) both lie on tibia_l's y axis, so there the two
// definitions agree to 1e-10.
// Approximations (documented, not corrected):
//   - straight path segments between MuJoCo's path points; a wrapped segment's force acts at the
//     tangent points on the wrap geom's body, as MuJoCo's tendon Jacobian has it;
//   - patella_l is fixed to tibia_l (inside S) and the quadriceps insert on it, so F_J is the
//     femur's force on the tibia-patella unit: tibiofemoral plus patellofemoral contact, with the
//     quadriceps pulling along their own line rather than along the patellar ligament;
//   - the hinge carries ligament loads too: the left knee has no ligaments, so F_J is all
//     "articular";
//   - joint-space forces of the knee's own dofs (hinge springs, limits, joint actuators) are
//     torques for a hinge and add nothing to F_J; for slide dofs (the right knee's placeholder
//     knee_tx/ty/tz) they are part of F_J, which is what the comparison in tests/ uses.
// Needs positions, velocities and accelerations (mj_inverse, as go_gait_load_node runs, or
// mj_forward) and the muscle state (actuator_length, actuator_velocity, act, d->userdata).
#ifndef GAITSIM_CALLBACKS_GS_KNEE_REACTION_H_
#define GAITSIM_CALLBACKS_GS_KNEE_REACTION_H_

#include <mujoco/mujoco.h>

// Which knee: resolved model ids (gs_knee_reaction_spec).
typedef struct gsKneeReactionSpec_ {
  int body;          // root of the subtree S below the knee (tibia_l)                (body id)
  int knee_joint;    // joint whose anchor is the knee joint centre (knee_flexion_l)  (joint id)
  int ankle_joint;   // joint whose anchor is the ankle joint centre (ankle_angle_l)  (joint id)
  int ground_r;      // 1: the right foot's contact spheres are inside S              (flag)
  int ground_l;      // 1: the left foot's contact spheres are inside S               (flag)
} gsKneeReactionSpec;

// The reaction and its parts at one state.
typedef struct gsKneeReaction_ {
  double force[3];     // F_J: force of the femur on the subtree through the joint, world   (N)
  double axis[3];      // a: unit tibia long axis, ankle -> knee joint centre, world       (-)
  double compression;  // C = -F_J . a, positive in compression                            (N)
  double inertial[3];  // F_int = dP_S/dt - m_S g: force S needs from outside, world       (N)
  double ground[3];    // F_ground: ground reaction on the feet inside S, world            (N)
  double muscle[3];    // sum_m F_m u_m: net force of the muscles crossing into S, world   (N)
  int ncross;          // muscle actuators whose path crosses the boundary of S            (-)
} gsKneeReaction;

// Resolve a knee by names: subtree root body `tibia`, joints `knee` and `ankle` (the ankle joint
// on a body inside the subtree). A foot's contact spheres must lie all inside or all outside
// the subtree. Returns 0, or -1 with the reason (naming the object) in err.
int gs_knee_reaction_spec(const mjModel* m, const char* tibia, const char* knee,
                          const char* ankle, gsKneeReactionSpec* spec, char* err, int errsz);

// The left (1-DOF) knee of the jw models: tibia_l, knee_flexion_l, ankle_angle_l.
int gs_knee_reaction_spec_left(const mjModel* m, gsKneeReactionSpec* spec, char* err, int errsz);

// Joint reaction of the knee spec at the current state of d (see the top of this file). Runs
// mj_rnePostConstraint (writes d->cacc, d->cfrc_int, d->cfrc_ext). tension: per actuator (nu),
// the tendon tension of each actuator (N, >= 0 pulling), e.g. zeros but one for a test; NULL:
// gs_physics_muscle_tension for gaitsim muscles and 0 for every other actuator (MuJoCo-native
// muscles and joint actuators are not subtracted). Returns 0, or -1 when a tendon path could not
// be matched to its model elements or a result is not finite (out is filled either way).
int gs_knee_reaction(const mjModel* m, mjData* d, const gsKneeReactionSpec* spec,
                     const double* tension, gsKneeReaction* out);

#endif  // GAITSIM_CALLBACKS_GS_KNEE_REACTION_H_
