// gs_model_info.c: model summary in gaitsim's terms (see gs_model_info.h).
#include "callbacks/gs_model_info.h"

#include <string.h>

#include "callbacks/gs_model_layout.h"

int gs_actuator_is_gaitsim_muscle(const mjModel* m, int i) {
  if (m->nuser_actuator < GS_ACT_NUSER) {
    return 0;
  }
  return m->actuator_user[i * m->nuser_actuator + GS_ACT_FMAX] > 0;
}

int gs_actuator_is_muscle(const mjModel* m, int i) {
  if (gs_actuator_is_gaitsim_muscle(m, i)) {
    return 1;
  }
  return m->actuator_gaintype[i] == mjGAIN_MUSCLE;
}

int gs_actuator_has_elastic_tendon(const mjModel* m, int i) {
  if (!gs_actuator_is_gaitsim_muscle(m, i)) {
    return 0;
  }
  return m->actuator_user[i * m->nuser_actuator + GS_ACT_ELASTIC_TENDON] > 0.5;
}

int gs_geom_contact_side(const mjModel* m, int g) {
  if (m->geom_type[g] != mjGEOM_SPHERE) {
    return 0;
  }
  const char* name = mj_id2name(m, mjOBJ_GEOM, g);
  if (!name || strncmp(name, "contact_", 8) != 0) {
    return 0;
  }
  if ((name[8] == 'r' || name[8] == 'l') && name[9] == '_') {
    return name[8];
  }
  return 0;
}

void gs_model_info(const mjModel* m, gsModelInfo* info) {
  memset(info, 0, sizeof(*info));
  info->ndof = m->nv;
  for (int i = 0; i < m->nu; i++) {
    if (gs_actuator_is_muscle(m, i)) {
      info->nmuscle++;
      info->nmuscle_gaitsim += gs_actuator_is_gaitsim_muscle(m, i);
      info->nmuscle_rigid += !gs_actuator_has_elastic_tendon(m, i);
    }
  }
  for (int g = 0; g < m->ngeom; g++) {
    int side = gs_geom_contact_side(m, g);
    info->ncontact_r += side == 'r';
    info->ncontact_l += side == 'l';
  }
  info->mass = mj_getTotalmass((mjModel*)m);
}
