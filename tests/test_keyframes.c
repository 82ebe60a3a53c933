// test_keyframes.c: a solution exported as MuJoCo keyframes (render/gr_keyframes.h) loads in
// stock MuJoCo (mj_loadXML; no gaitsim callback is installed in this program) and every key holds
// its states.sto row: time to 1e-12 s, qpos to 1e-12 rad or m (degrees converted here, by joint
// type, not by the exporter's code), speeds and activations likewise or 0 where states.sto has
// none. Also: include paths relative to the exported file's folder; a model coordinate missing
// from states.sto fails and leaves no file; --out naming the model itself fails, model intact.
//
//   test_keyframes                        export tests/fixtures/solution_small and check it
//   test_keyframes EXPORT.xml STATES.sto  check an existing export (the CLI test's `gaitsim export`)
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <mujoco/mujoco.h>

#include "io/gs_storage.h"
#include "render/gr_keyframes.h"
#include "tests/gs_test.h"

#define FIXTURE GAITSIM_SOURCE_DIR "/tests/fixtures/solution_small/states.sto"
#define MODEL GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody_knee6.xml"
#define ONE_MUSCLE GAITSIM_SOURCE_DIR "/tests/fixtures/one_muscle.xml"

static const double kTol = 1e-12;  // round trip through 17 significant digits (rad, m, s)

// value of column `label` at row r in SI units, or `missing` when t has no such column
static double column(const gsTable* t, const char* label, int r, int angle, double missing) {
  int c = gs_table_column(t, label);
  if (c < 0) return missing;
  double v = t->data[(size_t)r * (size_t)t->ncol + (size_t)c];
  return angle && t->in_degrees ? v * M_PI / 180.0 : v;
}

// check every gait key of the exported file against states.sto; returns the number of keys seen
static int check_export(const char* exported, const char* states_path) {
  char err[1024];
  gsTable t;
  gs_table_init(&t);
  EXPECT_EQ_INT(0, gs_storage_read(states_path, &t, err, sizeof(err)));
  mjModel* m = mj_loadXML(exported, NULL, err, sizeof(err));
  EXPECT_TRUE(m != NULL);
  if (!m || t.nrow == 0) {
    fprintf(stderr, "%s: %s\n", exported, err);
    if (m) mj_deleteModel(m);
    gs_table_free(&t);
    return 0;
  }
  int nseen = 0, nqpos = 0, nqvel = 0, nact = 0;
  for (int r = 0; r < t.nrow; r++) {
    char name[32];
    snprintf(name, sizeof(name), "gait_%03d", r);
    int k = mj_name2id(m, mjOBJ_KEY, name);
    EXPECT_TRUE(k >= 0);
    if (k < 0) continue;
    nseen++;
    EXPECT_NEAR(t.time[r], m->key_time[k], kTol);
    for (int j = 0; j < m->njnt; j++) {
      int hinge = m->jnt_type[j] == mjJNT_HINGE;
      if (!hinge && m->jnt_type[j] != mjJNT_SLIDE) continue;
      const char* jn = mj_id2name(m, mjOBJ_JOINT, j);
      double q = column(&t, jn, r, hinge, NAN);
      EXPECT_TRUE(!isnan(q));  // every coordinate is in states.sto
      if (!isnan(q)) {
        EXPECT_NEAR(q, m->key_qpos[k * m->nq + m->jnt_qposadr[j]], kTol);
        nqpos++;
      }
      char speed[256];
      snprintf(speed, sizeof(speed), "%s_u", jn);
      EXPECT_NEAR(column(&t, speed, r, hinge, 0), m->key_qvel[k * m->nv + m->jnt_dofadr[j]], kTol);
      nqvel += gs_table_column(&t, speed) >= 0;
    }
    for (int i = m->nu - m->na; i < m->nu; i++) {
      char label[256];
      snprintf(label, sizeof(label), "%s.activation", mj_id2name(m, mjOBJ_ACTUATOR, i));
      EXPECT_NEAR(column(&t, label, r, 0, 0), m->key_act[k * m->na + i - (m->nu - m->na)], kTol);
      nact += gs_table_column(&t, label) >= 0;
    }
  }
  EXPECT_EQ_INT(t.nrow, nseen);
  printf("%s: %d keys, %d coordinate, %d speed and %d activation values checked\n", exported,
         nseen, nqpos, nqvel, nact);
  mj_deleteModel(m);
  gs_table_free(&t);
  return nseen;
}

static void relative_paths_should_start_from_the_output_folder(const char* dir) {
  char rel[4096], err[1024], sub[4096], deep[4096];
  snprintf(sub, sizeof(sub), "%s/sub", dir);
  snprintf(deep, sizeof(deep), "%s/sub/deeper", dir);
  EXPECT_EQ_INT(0, mkdir(sub, 0777));
  EXPECT_EQ_INT(0, mkdir(deep, 0777));
  char file[4096];
  snprintf(file, sizeof(file), "%s/sub/m.xml", dir);
  FILE* f = fopen(file, "w");
  EXPECT_TRUE(f != NULL);
  if (f) fclose(f);
  EXPECT_EQ_INT(0, gr_keyframes_relative_path(file, sub, rel, sizeof(rel), err, sizeof(err)));
  EXPECT_TRUE(strcmp(rel, "m.xml") == 0);
  EXPECT_EQ_INT(0, gr_keyframes_relative_path(file, deep, rel, sizeof(rel), err, sizeof(err)));
  EXPECT_TRUE(strcmp(rel, "../m.xml") == 0);
  EXPECT_EQ_INT(0, gr_keyframes_relative_path(file, dir, rel, sizeof(rel), err, sizeof(err)));
  EXPECT_TRUE(strcmp(rel, "sub/m.xml") == 0);
  EXPECT_EQ_INT(-1, gr_keyframes_relative_path("/nonexistent/m.xml", dir, rel, sizeof(rel), err,
                                               sizeof(err)));
  EXPECT_TRUE(strstr(err, "/nonexistent/m.xml") != NULL);
  printf("relative paths: %s\n", rel);
  unlink(file);
  rmdir(deep);
  rmdir(sub);
}

static void fixture_should_export_and_load_in_stock_mujoco(const char* dir) {
  char out[4096], err[1024];
  snprintf(out, sizeof(out), "%s/new/folder/gait.xml", dir);  // folders are created
  char merr[1024];
  mjModel* m = mj_loadXML(MODEL, NULL, merr, sizeof(merr));
  EXPECT_TRUE(m != NULL);
  if (!m) return;
  grKeyframesInfo info;
  int rc = gr_keyframes_export(m, MODEL, FIXTURE, out, &info, err, sizeof(err));
  EXPECT_EQ_INT(0, rc);
  if (rc != 0) fprintf(stderr, "export: %s\n", err);
  EXPECT_EQ_INT(14, info.nkey);  // the fixture's rows
  EXPECT_EQ_INT(m->nkey, info.first_key);
  EXPECT_EQ_INT(26, info.nq_found);
  EXPECT_EQ_INT(0, info.nv_found);  // the fixture has no speeds: keys hold 0
  EXPECT_EQ_INT(93, info.na_found);
  EXPECT_TRUE(info.include[0] != '/');  // MuJoCo 2.2.2 needs a relative include
  EXPECT_EQ_INT(14, check_export(out, FIXTURE));

  // the key poses are the states: the right knee flexion of row 0 is 1.4398999 degrees
  mjModel* back = mj_loadXML(out, NULL, merr, sizeof(merr));
  EXPECT_TRUE(back != NULL);
  if (back) {
    int k = mj_name2id(back, mjOBJ_KEY, "gait_000");
    int j = mj_name2id(back, mjOBJ_JOINT, "knee_flexion");
    EXPECT_TRUE(k >= 0 && j >= 0);
    if (k >= 0 && j >= 0) {
      EXPECT_NEAR(1.4398999 * M_PI / 180, back->key_qpos[k * back->nq + back->jnt_qposadr[j]],
                  kTol);
    }
    mj_deleteModel(back);
  }
  mj_deleteModel(m);
}

static void missing_coordinate_should_fail_without_a_file(const char* dir) {
  char out[4096], err[1024], merr[1024];
  snprintf(out, sizeof(out), "%s/none.xml", dir);
  mjModel* m = mj_loadXML(ONE_MUSCLE, NULL, merr, sizeof(merr));
  EXPECT_TRUE(m != NULL);
  if (!m) return;
  EXPECT_EQ_INT(-1, gr_keyframes_export(m, ONE_MUSCLE, FIXTURE, out, NULL, err, sizeof(err)));
  EXPECT_TRUE(strstr(err, "no column for coordinate drop") != NULL);
  printf("missing coordinate: %s\n", err);
  EXPECT_TRUE(access(out, F_OK) != 0);
  mj_deleteModel(m);
}

static void model_should_not_be_overwritten(const char* dir) {
  char model[4096], err[1024], merr[1024], cmd[16600];
  snprintf(model, sizeof(model), "%s/copy.xml", dir);
  // the copy finds the model's meshes (meshdir="meshes") through a link beside it
  snprintf(cmd, sizeof(cmd), "cp '%s' '%s' && ln -sfn \"$(dirname '%s')/meshes\" '%s/meshes'",
           MODEL, model, MODEL, dir);
  EXPECT_EQ_INT(0, system(cmd));
  mjModel* m = mj_loadXML(model, NULL, merr, sizeof(merr));
  EXPECT_TRUE(m != NULL);
  if (!m) return;
  EXPECT_EQ_INT(-1, gr_keyframes_export(m, model, FIXTURE, model, NULL, err, sizeof(err)));
  EXPECT_TRUE(strstr(err, "is the model itself") != NULL);
  mj_deleteModel(m);
  m = mj_loadXML(model, NULL, merr, sizeof(merr));  // still the model
  EXPECT_TRUE(m != NULL && m->nq == 26);
  if (m) mj_deleteModel(m);
}

int main(int argc, char** argv) {
  if (argc == 3) {
    EXPECT_TRUE(check_export(argv[1], argv[2]) > 0);
    return GS_TEST_RESULT();
  }
  char dir[1024];
  const char* base = getenv("TMPDIR");
  snprintf(dir, sizeof(dir), "%s/gs_test_keyframes_XXXXXX", base && *base ? base : "/tmp");
  if (!mkdtemp(dir)) {
    fprintf(stderr, "cannot create a temporary directory\n");
    return 1;
  }
  relative_paths_should_start_from_the_output_folder(dir);
  fixture_should_export_and_load_in_stock_mujoco(dir);
  missing_coordinate_should_fail_without_a_file(dir);
  model_should_not_be_overwritten(dir);
  char cmd[4200];
  snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
  if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
  return GS_TEST_RESULT();
}
