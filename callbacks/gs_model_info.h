// gs_model_info.h: what a model holds in gaitsim's terms (callbacks/gs_model_layout.h): degrees
// of freedom, Hill muscle-tendon units and their tendon type, foot contact spheres, mass.
#ifndef GAITSIM_CALLBACKS_GS_MODEL_INFO_H_
#define GAITSIM_CALLBACKS_GS_MODEL_INFO_H_

#include <mujoco/mujoco.h>

typedef struct gsModelInfo_ {
  int ndof;              // degrees of freedom (nv)
  int nmuscle;           // muscle actuators: gaitsim Hill units plus MuJoCo-native muscles
  int nmuscle_gaitsim;   // of which carry gaitsim Hill parameters (user row, GS_ACT_NUSER)
  int nmuscle_rigid;     // of which have a rigid tendon (native muscles count as rigid)
  int ncontact_r;        // contact spheres of the right foot ("contact_r_*")
  int ncontact_l;        // contact spheres of the left foot ("contact_l_*")
  double mass;           // total mass (kg)
} gsModelInfo;

// 1 if actuator i carries gaitsim Hill parameters in its user row, else 0.
int gs_actuator_is_gaitsim_muscle(const mjModel* m, int i);

// 1 if actuator i is a muscle: a gaitsim Hill unit or a MuJoCo-native muscle.
int gs_actuator_is_muscle(const mjModel* m, int i);

// 1 if muscle actuator i has an elastic tendon, 0 if rigid (MuJoCo-native muscles are rigid).
int gs_actuator_has_elastic_tendon(const mjModel* m, int i);

// 'r' or 'l' if geom g is a foot contact sphere of that side ("contact_<side>_<k>"), else 0.
int gs_geom_contact_side(const mjModel* m, int g);

// Fill info for model m.
void gs_model_info(const mjModel* m, gsModelInfo* info);

#endif  // GAITSIM_CALLBACKS_GS_MODEL_INFO_H_
