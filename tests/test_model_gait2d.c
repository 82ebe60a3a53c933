// test_model_gait2d.c: the planar model mjmodels/gait2d.xml (scripts/make_gait2d.py) has the
// documented structure: 9 hinge/slide degrees of freedom (pelvis_tx, pelvis_ty, pelvis_rz and
// hip, knee, ankle flexion per leg), 18 gaitsim muscles (9 per leg), 6 + 6 contact spheres, a
// `standing` keyframe, the full-body model's mass (removed joints are welds), and every muscle
// has a moment arm about at least one kept leg coordinate at the standing pose.
#include <mujoco/mujoco.h>
#include <string.h>

#include "callbacks/gs_model_layout.h"
#include "callbacks/gs_mujoco.h"
#include "tests/gs_test.h"

#define GAIT2D_PATH GAITSIM_SOURCE_DIR "/mjmodels/gait2d.xml"
#define FULL_PATH GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody.xml"
#define MIN_ARM 0.005  // smallest |moment arm| that counts as "crosses the joint" (m)

static const char* const COORDS[9] = {
    "pelvis_tx",   "pelvis_ty",     "pelvis_rz",      "hip_flexion",   "knee_flexion",
    "ankle_angle", "hip_flexion_l", "knee_flexion_l", "ankle_angle_l",
};

// the kept units: right leg JW names, left leg gait2392 names (mjmodels/README.md)
static const char* const MUSCLES[18] = {
    "glmax2",      "iliacus",    "recfem",    "vasint",      "bflh",      "bfsh",
    "gasmed",      "soleus",     "tibant",    "glut_max2_l", "iliacus_l", "rect_fem_l",
    "vas_int_l",   "bifemlh_l",  "bifemsh_l", "med_gas_l",   "soleus_l",  "tib_ant_l",
};

// gaitsim contact spheres of one side ("contact_<side>_<k>" with stiffness > 0)
static int count_spheres(const mjModel* m, char side) {
  int n = 0;
  for (int g = 0; g < m->ngeom; g++) {
    const char* name = mj_id2name(m, mjOBJ_GEOM, g);
    if (name && !strncmp(name, "contact_", 8) && name[8] == side && name[9] == '_' &&
        m->geom_type[g] == mjGEOM_SPHERE && m->nuser_geom >= GS_GEOM_NUSER &&
        m->geom_user[g * m->nuser_geom + GS_GEOM_STIFFNESS] > 0) {
      n++;
    }
  }
  return n;
}

int main(void) {
  gs_mujoco_install_handlers();
  char err[1000];
  mjModel* m = gs_model_load(GAIT2D_PATH, err, sizeof(err));
  mjModel* full = gs_model_load(FULL_PATH, err, sizeof(err));
  EXPECT_TRUE(m != NULL && full != NULL);
  if (!m || !full) {
    fprintf(stderr, "%s\n", err);
    return GS_TEST_RESULT();
  }

  // structure
  EXPECT_EQ_INT(9, m->nq);
  EXPECT_EQ_INT(9, m->nv);
  EXPECT_EQ_INT(9, m->njnt);
  for (int k = 0; k < 9 && k < m->njnt; k++) {
    int j = mj_name2id(m, mjOBJ_JOINT, COORDS[k]);
    EXPECT_EQ_INT(k, j);
    if (j >= 0) {
      EXPECT_EQ_INT(k, m->jnt_qposadr[j]);
    }
  }
  EXPECT_EQ_INT(18, m->nu);
  EXPECT_EQ_INT(GS_ACT_NUSER, m->nuser_actuator);
  for (int k = 0; k < 18; k++) {
    int a = mj_name2id(m, mjOBJ_ACTUATOR, MUSCLES[k]);
    EXPECT_TRUE(a >= 0);
    if (a < 0) {
      fprintf(stderr, "muscle %s missing\n", MUSCLES[k]);
    } else if (m->nuser_actuator >= GS_ACT_NUSER) {
      EXPECT_TRUE(m->actuator_user[a * m->nuser_actuator + GS_ACT_FMAX] > 0);
      EXPECT_EQ_INT(mjTRN_TENDON, m->actuator_trntype[a]);
    }
  }
  EXPECT_EQ_INT(6, count_spheres(m, 'r'));
  EXPECT_EQ_INT(6, count_spheres(m, 'l'));
  EXPECT_TRUE(mj_name2id(m, mjOBJ_GEOM, "floor") >= 0);
  EXPECT_NEAR(mj_getTotalmass(full), mj_getTotalmass(m), 1e-9);

  // standing keyframe: every muscle crosses a kept leg joint (|r| > MIN_ARM about one of them)
  int key = mj_name2id(m, mjOBJ_KEY, "standing");
  EXPECT_TRUE(key >= 0);
  mjData* d = mj_makeData(m);
  if (key >= 0) {
    mj_resetDataKeyframe(m, d, key);
    // pelvis_ty as at jw_fullbody.xml's standing keyframe
    int full_key = mj_name2id(full, mjOBJ_KEY, "standing");
    int full_ty = mj_name2id(full, mjOBJ_JOINT, "pelvis_ty");
    EXPECT_TRUE(full_key >= 0 && full_ty >= 0);
    if (full_key >= 0 && full_ty >= 0) {
      double ty = full->key_qpos[full_key * full->nq + full->jnt_qposadr[full_ty]];
      EXPECT_NEAR(ty, d->qpos[1], 1e-3);
      EXPECT_TRUE(ty > 0.95 && ty < 1.05);  // JW's standing pelvis height (m)
    }
    mj_fwdPosition(m, d);
    for (int a = 0; a < m->nu; a++) {
      double best = 0;
      for (int v = 3; v < m->nv; v++) {  // leg dofs (after the three pelvis dofs)
        double r = fabs(d->actuator_moment[a * m->nv + v]);
        best = r > best ? r : best;
      }
      EXPECT_TRUE(best > MIN_ARM);
      if (best <= MIN_ARM) {
        fprintf(stderr, "muscle %s: largest leg moment arm %.4f m\n",
                mj_id2name(m, mjOBJ_ACTUATOR, a), best);
      }
    }
    // the calcaneus spheres (1-4) touch the floor (z = 0) within 1 mm: level feet; the toes
    // spheres (5, 6), lifted by the converter's GRF fit, clear it by 0-20 mm (mjmodels/README.md)
    double low = 1e9, high = -1e9, toes_low = 1e9, toes_high = -1e9;
    for (int g = 0; g < m->ngeom; g++) {
      const char* name = mj_id2name(m, mjOBJ_GEOM, g);
      if (name && !strncmp(name, "contact_", 8)) {
        double z = d->geom_xpos[3 * g + 2] - m->geom_size[3 * g];
        int toes = name[strlen(name) - 1] == '5' || name[strlen(name) - 1] == '6';
        double *lo = toes ? &toes_low : &low, *hi = toes ? &toes_high : &high;
        *lo = z < *lo ? z : *lo;
        *hi = z > *hi ? z : *hi;
      }
    }
    EXPECT_NEAR(0.0, low, 1e-3);
    EXPECT_NEAR(0.0, high, 1e-3);
    EXPECT_TRUE(toes_low > -1e-3 && toes_high < 0.02);
  }

  mj_deleteData(d);
  mj_deleteModel(full);
  mj_deleteModel(m);
  return GS_TEST_RESULT();
}
