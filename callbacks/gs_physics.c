// gs_physics.c: gaitsim's physics installed in MuJoCo's callbacks (see gs_physics.h).
#include "callbacks/gs_physics.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "callbacks/gs_activation.h"
#include "callbacks/gs_coupling.h"
#include "callbacks/gs_joint_limits.h"
#include "callbacks/gs_knee.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_model_layout.h"
#include "callbacks/gs_muscle.h"
#include "callbacks/gs_tendon_paths.h"

// the user row of actuator i as doubles (mjtNum is double; the copy keeps the types explicit)
static const double* actuator_user(const mjModel* m, int i) {
  return m->actuator_user + i * m->nuser_actuator;
}

// activation of actuator i (actuators with activation come last: act index = i - (nu - na))
static double actuator_activation(const mjModel* m, const mjData* d, int i) {
  return d->act[i - (m->nu - m->na)];
}

// --- Hill muscle-tendon units (gs_muscle.h, gs_activation.h) ---------------------------------

double gs_physics_muscle_tension(const mjModel* m, const mjData* d, int i, gsMuscleOut* out) {
  gsMuscleParams prm;
  if (gs_muscle_params_from_user(actuator_user(m, i), &prm, NULL, 0) != 0) {
    return 0;  // rejected in gs_physics_prepare
  }
  double a = actuator_activation(m, d, i);
  if (prm.elastic) {
    double fT = d->userdata[i];
    if (out) {
      // fibre state consistent with the tendon force; fT_dot from equilibrium (forward model)
      double fT_dot = 0;
      gs_muscle_elastic_fT_dot(&prm, a, d->actuator_length[i], d->actuator_velocity[i], fT,
                               &fT_dot, out);
    }
    return prm.fmax * fT;
  }
  return gs_muscle_rigid_force(&prm, a, d->actuator_length[i], d->actuator_velocity[i], NULL, out);
}

double gs_physics_muscle_metabolics(const mjModel* m, const mjData* d, int i,
                                    gsUmbergerTerms* terms) {
  gsUmbergerMuscle mus;
  if (gs_umberger_muscle_from_user(actuator_user(m, i), &mus, NULL, 0) != 0) {
    return 0;
  }
  gsMuscleOut out;
  gs_physics_muscle_tension(m, d, i, &out);
  gsUmbergerInput in = {d->ctrl[i], actuator_activation(m, d, i), out.lM_norm, out.vM,
                        out.f_active, out.fL};
  return gs_umberger2010(&mus, &in, terms);
}

// mjcb_act_dyn: da/dt from excitation ctrl[i] and activation (De Groote 2016, gs_activation.h)
static mjtNum gs_act_dyn_callback(const mjModel* m, const mjData* d, int i) {
  gsActivationParams prm;
  if (gs_activation_params_from_user(actuator_user(m, i), &prm, NULL, 0) != 0) {
    return 0;
  }
  return gs_activation_dot(&prm, d->ctrl[i], actuator_activation(m, d, i), NULL, NULL);
}

// mjcb_act_gain: the whole force is in the bias term, so gain is 0
static mjtNum gs_act_gain_callback(const mjModel* m, const mjData* d, int i) {
  return 0;
}

// mjcb_act_bias: actuator force = -tendon tension (a pulling muscle shortens its tendon)
static mjtNum gs_act_bias_callback(const mjModel* m, const mjData* d, int i) {
  return -gs_physics_muscle_tension(m, d, i, NULL);
}

void gs_physics_equilibrate_tendons(const mjModel* m, mjData* d, const int* given) {
  for (int i = 0; i < m->nu; i++) {
    gsMuscleParams prm;
    if ((given && given[i] >= 0) || !gs_actuator_has_elastic_tendon(m, i) ||
        gs_muscle_params_from_user(actuator_user(m, i), &prm, NULL, 0) != 0) {
      continue;
    }
    double a = i >= m->nu - m->na ? actuator_activation(m, d, i) : 0;
    double fT = 0;
    gs_muscle_equilibrium_fT(&prm, a, d->actuator_length[i], &fT, NULL);
    d->userdata[i] = fT;
  }
}

int gs_physics_tendon_force_rates(const mjModel* m, const mjData* d, mjtNum* fT_dot) {
  int clamped = 0;
  for (int i = 0; i < m->nu; i++) {
    fT_dot[i] = 0;
    gsMuscleParams prm;
    if (!gs_actuator_has_elastic_tendon(m, i) ||
        gs_muscle_params_from_user(actuator_user(m, i), &prm, NULL, 0) != 0) {
      continue;
    }
    double rate = 0;
    clamped += gs_muscle_elastic_fT_dot(&prm, actuator_activation(m, d, i), d->actuator_length[i],
                                        d->actuator_velocity[i], d->userdata[i], &rate,
                                        NULL) != 0;
    fT_dot[i] = rate;
  }
  return clamped;
}

int gs_physics_step(const mjModel* m, mjData* d, mjtNum* fT_dot) {
  // MuJoCo resets the state (time included) when it finds a bad acceleration: count those
  int bad_before = d->warning[mjWARN_BADQACC].number;
  mj_step1(m, d);
  // a grazing wrap (gs_tendon_paths.h): the velocity stage again, from the recomputed tendons
  if (gs_tendon_repair(m, d) != 0) mj_fwdVelocity(m, d);
  gs_physics_tendon_force_rates(m, d, fT_dot);
  mj_step2(m, d);
  if (d->warning[mjWARN_BADQACC].number != bad_before) {
    return -1;
  }
  int finite = 1;
  for (int i = 0; i < m->nu; i++) {
    d->userdata[i] += m->opt.timestep * fT_dot[i];
    finite = finite && isfinite(d->userdata[i]);
  }
  for (int i = 0; i < m->nv; i++) {
    finite = finite && isfinite(d->qacc[i]) && isfinite(d->qvel[i]);
  }
  return finite ? 0 : -1;
}

// --- foot-ground contact (gs_contact.h) ------------------------------------------------------

// contact parameters of geom g; 0 on success
static int contact_params(const mjModel* m, int g, gsContactParams* prm, char* err, int errsz) {
  const mjtNum* user = m->geom_user + g * m->nuser_geom;
  double row[GS_GEOM_NUSER];
  for (int k = 0; k < GS_GEOM_NUSER; k++) {
    row[k] = user[k];
  }
  return gs_contact_params_from_user(row, m->geom_size[3 * g], prm, err, errsz);
}

int gs_physics_sphere_contact(const mjModel* m, const mjData* d, int g, gsContactOut* out) {
  if (!gs_geom_contact_side(m, g) || m->nuser_geom < GS_GEOM_NUSER) {
    return 0;
  }
  gsContactParams prm;
  if (contact_params(m, g, &prm, NULL, 0) != 0) {
    return 0;  // rejected in gs_physics_prepare
  }
  // velocity of the sphere centre and of the body point at the contact (world frame)
  mjtNum twist[6];
  mj_objectVelocity(m, d, mjOBJ_GEOM, g, twist, 0);
  const mjtNum* center = d->geom_xpos + 3 * g;
  double pos[3] = {center[0], center[1], center[2]};
  double vel[3] = {twist[3], twist[4], twist[5]};
  // contact point: the centre projected on the plane z = 0; v_point = v + w x (point - centre)
  double r[3] = {0, 0, -center[2]};
  double vel_point[3] = {vel[0] + twist[1] * r[2] - twist[2] * r[1],
                         vel[1] + twist[2] * r[0] - twist[0] * r[2],
                         vel[2] + twist[0] * r[1] - twist[1] * r[0]};
  gs_contact_sphere(&prm, NULL, NULL, NULL, pos, vel, vel_point, out);
  return 1;
}

void gs_physics_contact_passive(const mjModel* m, mjData* d) {
  const mjtNum zero[3] = {0, 0, 0};
  for (int g = 0; g < m->ngeom; g++) {
    gsContactOut out;
    if (!gs_physics_sphere_contact(m, d, g, &out)) {
      continue;
    }
    mjtNum force[3] = {out.force[0], out.force[1], out.force[2]};
    mjtNum point[3] = {out.point[0], out.point[1], out.point[2]};
    mj_applyFT(m, d, force, zero, point, m->geom_bodyid[g], d->qfrc_passive);
  }
}

void gs_physics_foot_grf(const mjModel* m, const mjData* d, int side, double fn_min,
                         gsFootGrf* grf) {
  enum { kMaxSpheres = 64 };
  double forces[3 * kMaxSpheres], points[3 * kMaxSpheres];
  int n = 0;
  for (int g = 0; g < m->ngeom && n < kMaxSpheres; g++) {
    gsContactOut out;
    if (gs_geom_contact_side(m, g) != side || !gs_physics_sphere_contact(m, d, g, &out)) {
      continue;
    }
    memcpy(forces + 3 * n, out.force, sizeof(out.force));
    memcpy(points + 3 * n, out.point, sizeof(out.point));
    n++;
  }
  gs_contact_foot_grf(n, forces, points, NULL, NULL, fn_min, grf);
}

// mjcb_passive: foot-ground contact, the implant knee's surrogate contact and ligaments when
// the model carries the gs_knee numerics (callbacks/gs_knee.h; a no-op otherwise; the knee's
// parameters were cached by gs_physics_prepare, gs_knee_register), the coordinate couplings and
// the joint-limit moments (callbacks/gs_joint_limits.h)
static void gs_passive_callback(const mjModel* m, mjData* d) {
  gs_physics_contact_passive(m, d);
  gs_knee_passive(m, d, NULL);
  gs_coupling_passive(m, d);
  gs_joint_limits_passive(m, d);
}

int gs_physics_prepare(mjModel* m, char* err, int errsz) {
  // Hill muscles: parameters valid; gain, bias and dynamics become ours
  for (int i = 0; i < m->nu; i++) {
    if (!gs_actuator_is_gaitsim_muscle(m, i)) {
      continue;
    }
    const char* name = mj_id2name(m, mjOBJ_ACTUATOR, i);
    char why[256];
    gsMuscleParams mprm;
    gsActivationParams aprm;
    if (gs_muscle_params_from_user(actuator_user(m, i), &mprm, why, sizeof(why)) != 0 ||
        gs_activation_params_from_user(actuator_user(m, i), &aprm, why, sizeof(why)) != 0) {
      snprintf(err, errsz, "muscle %s: %s", name, why);
      return -1;
    }
    if (m->actuator_dyntype[i] == mjDYN_NONE) {
      snprintf(err, errsz, "muscle %s: actuator has no activation state (dyntype none)", name);
      return -1;
    }
    m->actuator_gaintype[i] = mjGAIN_USER;
    m->actuator_biastype[i] = mjBIAS_USER;
    m->actuator_dyntype[i] = mjDYN_USER;
    m->actuator_forcelimited[i] = 0;
  }
  // contact spheres: parameters present and valid
  for (int g = 0; g < m->ngeom; g++) {
    if (!gs_geom_contact_side(m, g)) {
      continue;
    }
    const char* name = mj_id2name(m, mjOBJ_GEOM, g);
    if (m->nuser_geom < GS_GEOM_NUSER) {
      snprintf(err, errsz, "contact sphere %s: geom user has %d entries, need %d", name,
               m->nuser_geom, GS_GEOM_NUSER);
      return -1;
    }
    gsContactParams prm;
    char why[256];
    if (contact_params(m, g, &prm, why, sizeof(why)) != 0) {
      snprintf(err, errsz, "contact sphere %s: %s", name, why);
      return -1;
    }
  }
  m->opt.disableflags |= mjDSBL_CONTACT;
  if (m->nuserdata < GS_USERDATA_SIZE(m)) {
    m->nuserdata = GS_USERDATA_SIZE(m);
  }
  // coordinate couplings (the right patella's): held by mjcb_passive, not by MuJoCo's solver
  if (gs_coupling_adopt(m, err, errsz) < 0) return -1;
  // joint-limit moments: their numerics checked once here
  if (gs_joint_limits_check(m, err, errsz) < 0) return -1;
  // implant knee: numerics checked and cached once here, so that mjcb_passive finds them by the
  // model pointer instead of by name on every call (gs_knee_register; no-op for other models)
  char why[256];
  if (gs_knee_register(m, why, sizeof(why)) < 0) {
    snprintf(err, errsz, "%s", why);
    return -1;
  }
  return 0;
}

void gs_physics_install(void) {
  mjcb_act_dyn = gs_act_dyn_callback;
  mjcb_act_gain = gs_act_gain_callback;
  mjcb_act_bias = gs_act_bias_callback;
  mjcb_passive = gs_passive_callback;
}
