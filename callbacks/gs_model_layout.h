// gs_model_layout.h: the contract between an MJCF model and gaitsim's physics.
//
// Every physical parameter the callbacks use is read from the compiled mjModel, never from a
// side file, so one MJCF file carries the whole model. This header names where each parameter
// sits. scripts/osim2mjcf.py writes models that follow it; mjmodels/README.md documents it for
// people who edit models by hand.
#ifndef GAITSIM_CALLBACKS_GS_MODEL_LAYOUT_H_
#define GAITSIM_CALLBACKS_GS_MODEL_LAYOUT_H_

// ---------------------------------------------------------------------------------------------
// Muscle-tendon actuators: <muscle ... tendon="NAME" user="p0 p1 ... "/> with
// <size nuser_actuator="GS_ACT_NUSER"/>. An actuator is a gaitsim muscle when its `user` row has
// GS_ACT_NUSER entries and GS_ACT_FMAX > 0. Stock MuJoCo uses the <muscle> fallback parameters;
// gaitsim's runtime switches gain, bias and dynamics to its own callbacks (user types).
// ---------------------------------------------------------------------------------------------
typedef enum gsActUser_ {
  GS_ACT_FMAX = 0,          // maximum isometric force                          (N)
  GS_ACT_LOPT,              // optimal fibre length                             (m)
  GS_ACT_LTS,               // tendon slack length                              (m)
  GS_ACT_PENNATION,         // pennation angle at optimal fibre length          (rad)
  GS_ACT_VMAX,              // maximum contraction velocity                     (lopt/s)
  GS_ACT_SLOW_TWITCH,       // slow-twitch fibre fraction                       (0..1)
  GS_ACT_SPECIFIC_TENSION,  // specific tension                                 (Pa)
  GS_ACT_MASS,              // muscle mass = Fmax / sigma * lopt * 1059.7 kg/m3 (kg)
  GS_ACT_ELASTIC_TENDON,    // 1: elastic tendon (lts >= lopt), 0: rigid tendon  (flag)
  GS_ACT_TAU_ACT,           // activation time constant                         (s)
  GS_ACT_TAU_DEACT,         // deactivation time constant                       (s)
  GS_ACT_TENDON_KT,         // tendon stiffness shape factor, De Groote 2016 kT (-), 35
  GS_ACT_NUSER              // number of user entries per actuator
} gsActUser;

// ---------------------------------------------------------------------------------------------
// Foot-ground contact spheres: sphere geoms named "contact_<side>_<k>" (side r|l, k = 1..6:
// 1-4 under the calcaneus, 5-6 under the toes) with <size nuser_geom="GS_GEOM_NUSER"/>. A geom is
// a gaitsim contact sphere when its `user` row has GS_GEOM_STIFFNESS > 0. The plane is the geom
// named "floor" (z up). Hunt-Crossley parameters as in OpenSim's HuntCrossleyForce.
// ---------------------------------------------------------------------------------------------
typedef enum gsGeomUser_ {
  GS_GEOM_STIFFNESS = 0,    // plane-strain modulus E, F = 4/3 E sqrt(R) d^1.5   (N/m^2)
  GS_GEOM_DISSIPATION,      // Hunt-Crossley dissipation c                      (s/m)
  GS_GEOM_STATIC_FRICTION,  // static friction coefficient                      (-)
  GS_GEOM_DYNAMIC_FRICTION, // dynamic friction coefficient                     (-)
  GS_GEOM_VISCOUS_FRICTION, // viscous friction coefficient                     (s/m)
  GS_GEOM_TRANSITION_VEL,   // transition velocity of the smoothed friction     (m/s)
  GS_GEOM_NUSER             // number of user entries per geom
} gsGeomUser;

#endif  // GAITSIM_CALLBACKS_GS_MODEL_LAYOUT_H_
