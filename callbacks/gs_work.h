// gs_work.h: the mechanical power budget of a gait at one instant (issue 20, metabolic cost
// across speeds): where the body's mechanical energy comes from and where it goes. Integrated over
// a stride it gives each source's positive and negative work: the muscles' (muscle-tendon units
// and their contractile elements), the foot contact's (the Hunt-Crossley spheres' dissipation and
// rebound, the model's stand-in for the heel pad and the soft tissues of Zelik & Kuo 2010, J Exp
// Biol 213:4257), the implant knee's contact and ligaments, the joint-limit moments.
//
// Power of a generalised force f on the body: P = f . qdot (W; > 0 when it adds energy). MuJoCo's
// equations of motion M qdd + c = f_passive + f_actuator + f_constraint + f_applied give, since
// qdot' (M' / 2 - C) qdot = 0 for the Coriolis and centrifugal part C qdot of c (the skew
// symmetry of M' - 2C; Siciliano et al. 2009, Robotics: Modelling, Planning and Control, ch. 7):
//   d/dt (KE + PE) = (f_passive + f_actuator + f_constraint + f_applied) . qdot            (W)
// with KE = qdot' M qdot / 2 and PE = -m_total g . c_com, the gravity's power being -dPE/dt =
// m_total g . v_com. Every term below is one piece of the right-hand side; their sum equals the
// left-hand side exactly at a state (tests/test_work.c checks it by central differences along a
// state's own motion; the app integrates each term over a solution's rows).
//
// Muscles (gs_muscle.h's Hill model; gaitsim muscle actuators only):
//   muscle-tendon unit i:  P_i = -F_T,i v_MT,i    (F_T the tendon tension >= 0, v_MT the
//                          actuator's lengthening velocity; = actuator_force . actuator_velocity)
//   contractile element:   P_CE,i = -F_CE,i vM,i  (F_CE = Fmax a fL fV along the fibre, vM the
//                          fibre's lengthening velocity), the work Umberger 2010 prices (positive
//                          only; gs_metabolics.h)
//   passive fibre:         -(F_PE + F_damping) vM,  tendon: P_i - P_CE,i - passive (the rest)
// Foot contact: per foot, sum over its spheres of the sphere force . the contact point's velocity
// (the point on the sphere's body; the floor is still): negative while the sphere is pressed in
// faster than it rebounds (Hunt-Crossley damping, friction slip), so its integral over a stride is
// the energy the contact dissipates. Split per sphere into the normal force's power -Fn d' (the
// body point at the contact moves along the normal as the centre does, d' the depth rate; the
// elastic part returns what it stores, so over a stride its net is the Hunt-Crossley damping's
// loss) and the friction's, the rest (slip: the smoothed friction law needs the sole to creep to
// hold a shear force).
// For a muscle at zero activation with a slack tendon the fibre velocity of the Hill equilibrium
// is ill-conditioned, and the unit's split into fibre and tendon with it (the unit's power is not).
#ifndef GAITSIM_CALLBACKS_GS_WORK_H_
#define GAITSIM_CALLBACKS_GS_WORK_H_

#include <mujoco/mujoco.h>

// Powers at one instant (W; > 0 adds energy to the body). *_pos and *_neg: the sum over the
// source's parts (each muscle, each foot) of their positive and negative parts; net = pos + neg.
typedef struct gsPowers_ {
  double mtu_pos, mtu_neg;    // muscle-tendon units (gaitsim muscles)
  double ce_pos, ce_neg;      // their contractile elements (active fibre force)
  double fibre_passive;       // their passive fibre force and fibre damping (net)
  double tendon;              // their tendons (net): the units less their fibres
  double foot_pos, foot_neg;  // foot contact, per foot
  double foot_normal_pos, foot_normal_neg;  // its normal forces, per sphere: -Fn d' (elastic
                                            // and Hunt-Crossley damping; d' the depth rate)
  double foot_friction;       // its friction: the foot contact less its normal forces (net)
  double knee;                // the implant knee's contact and ligaments (gs_knee.h; 0 without)
  double joint_limits;        // joint-limit moments (gs_joint_limits.h)
  double couplings;           // coordinate couplings (gs_coupling.h)
  double mujoco_passive;      // MuJoCo's own passive forces (joint damping, springs)
  double other_actuators;     // actuators that are not gaitsim muscles
  double constraint;          // MuJoCo's constraint forces (joint limits, equalities)
  double applied;             // qfrc_applied and xfrc_applied
  double gravity;             // -dPE/dt = m_total g . v_com
  double kinetic;             // kinetic energy KE (J)
  double potential;           // gravitational potential energy PE, zero at z = 0 (J)
} gsPowers;

// The budget at the current state of d, after mj_forward (positions, velocities, actuation and
// constraint forces computed). d->qfrc_passive is rebuilt piece by piece and restored; nothing
// else of d changes but subtree_linvel (mj_subtreeVel).
void gs_work_powers(const mjModel* m, mjData* d, gsPowers* p);

// The sum of the non-gravity powers: d/dt (KE + PE) (W).
double gs_work_total(const gsPowers* p);

// The muscles' power at each degree of freedom (W, nv entries): qfrc_actuator[k] qdot[k] of the
// gaitsim muscles alone, i.e. their net moment about coordinate k times its speed; the joint
// power of inverse dynamics less the passive structures' part. Their sum over k is
// mtu_pos + mtu_neg. Needs mj_forward; d->qfrc_actuator is not changed.
void gs_work_dof_muscle_powers(const mjModel* m, const mjData* d, double* power);

// The foot whose contact spheres hang below degree of freedom k: 'r', 'l', or 0 when both feet
// or none do (the pelvis's dofs, the trunk's, the arms').
int gs_work_dof_side(const mjModel* m, int k);

#endif  // GAITSIM_CALLBACKS_GS_WORK_H_
