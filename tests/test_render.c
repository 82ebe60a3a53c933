// test_render.c: the render module: a fixed pose against a stored golden image, solution
// loading and its errors, cycles with forward translation, frame counts, PNG round trip; and,
// independent of the golden image, the joints of the drawn pose projected through the camera
// (joint_positions_should_project_onto_the_body).
//
// Golden image: tests/fixtures/render_golden_160x120.png is the fixture solution
// (tests/fixtures/solution_small) at 35 % of the cycle, 160x120, default (fast) quality, side
// camera, overlay on, written by
//   build/gaitsim render tests/fixtures/solution_small --at 0.35 --size 160x120
//       --png tests/fixtures/render_golden_160x120.png     (one command line)
// (or by this test with GAITSIM_UPDATE_GOLDEN=1). Tolerance: mean absolute difference per
// channel <= 1.5 (of 255). The same call sequence renders bit-identically here (difference 0);
// STACK.md measured up to 10/255 on single pixels for the same state after a different history,
// and llvmpipe's rasterisation may differ in edge pixels across CPUs (SIMD width) and Mesa
// versions: edge pixels are a few percent of this picture, so a mean of 1.5 admits such
// differences while a changed pose (checked below: 35 % vs 45 % of the cycle) or a missing
// decoration (GRF arrows off) exceeds it.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <mujoco/mujoco.h>

#include "callbacks/gs_mujoco.h"
#include "callbacks/gs_physics.h"
#include "render/gr_image.h"
#include "render/gr_motion.h"
#include "render/gr_render.h"
#include "tests/gs_test.h"

#define FIXTURE GAITSIM_SOURCE_DIR "/tests/fixtures/solution_small"
#define GOLDEN GAITSIM_SOURCE_DIR "/tests/fixtures/render_golden_160x120.png"
#define MODEL GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody.xml"

// LeakSanitizer (scripts/test.sh runs the unit tests with detect_leaks=1): Mesa's OSMesa keeps
// 480 bytes in 5 blocks per process after OSMesaDestroyContext (inside libOSMesa.so.8, Mesa
// 22.3.6; not gaitsim's): suppressed by library name, nothing else.
const char* __lsan_default_suppressions(void);
const char* __lsan_default_suppressions(void) { return "leak:libOSMesa.so\n"; }

static const double kGoldenTolerance = 1.5;  // mean |difference| per channel (of 255)

// copy the fixture's files into dir, leaving out `skip` (NULL: none)
static void copy_fixture(const char* dir, const char* skip) {
  static const char* const files[] = {"states.sto", "controls.sto", "grf.mot",
                                      "knee_contact.sto", NULL};
  for (int i = 0; files[i]; i++) {
    char src[1024], dst[1024];
    if (skip && strcmp(files[i], skip) == 0) {
      snprintf(dst, sizeof(dst), "%s/%s", dir, files[i]);
      unlink(dst);
      continue;
    }
    snprintf(src, sizeof(src), "%s/%s", FIXTURE, files[i]);
    snprintf(dst, sizeof(dst), "%s/%s", dir, files[i]);
    FILE* in = fopen(src, "rb");
    FILE* out = fopen(dst, "wb");
    char buf[8192];
    size_t n;
    while (in && out && (n = fread(buf, 1, sizeof(buf), in)) > 0) fwrite(buf, 1, n, out);
    if (in) fclose(in);
    if (out) fclose(out);
  }
}

static void write_text(const char* path, const char* text) {
  FILE* f = fopen(path, "w");
  if (f) {
    fputs(text, f);
    fclose(f);
  }
}

// load the fixture solution for model m; 0 on success
static int load_fixture(const mjModel* m, grMotion* mo) {
  char err[1024];
  int rc = gr_motion_load_solution(m, FIXTURE, mo, err, sizeof(err));
  if (rc != 0) fprintf(stderr, "fixture: %s\n", err);
  return rc;
}

// render the fixture at fraction `at` into a new w x h x 3 buffer
static unsigned char* render_at(grRenderer* r, const grMotion* mo, double at) {
  unsigned char* rgb = (unsigned char*)malloc((size_t)r->o.width * r->o.height * 3);
  if (rgb) gr_renderer_frame(r, mo, at * gr_motion_stride_time(mo), rgb);
  return rgb;
}

// the model, the fixture motion and a renderer of w x h with o's other fields; 0 on success
// (then free all three), else nothing is left to free
static int open_fixture(int w, int h, grOptions* o, mjModel** m, grMotion* mo, grRenderer* r) {
  char err[1024];
  *m = gs_model_load(MODEL, err, sizeof(err));
  EXPECT_TRUE(*m != NULL);
  if (!*m) return -1;
  EXPECT_EQ_INT(0, load_fixture(*m, mo));
  o->width = w;
  o->height = h;
  if (gr_renderer_create(*m, o, r, err, sizeof(err)) != 0) {
    fprintf(stderr, "renderer: %s\n", err);
    EXPECT_TRUE(0);
    gr_motion_free(mo);
    mj_deleteModel(*m);
    return -1;
  }
  return 0;
}

// the fixed pose against the golden image; a different pose and a missing arrow must fail it
static void golden_image_should_match_within_tolerance(void) {
  char err[1024];
  mjModel* m;
  grMotion mo;
  grOptions o;
  grRenderer r;
  gr_options_default(&o);
  if (open_fixture(160, 120, &o, &m, &mo, &r) != 0) return;
  unsigned char* img = render_at(&r, &mo, 0.35);  // first frame: the command's call sequence
  EXPECT_TRUE(img != NULL);
  if (getenv("GAITSIM_UPDATE_GOLDEN")) {
    EXPECT_EQ_INT(0, gr_png_write(GOLDEN, img, 160, 120, err, sizeof(err)));
    printf("wrote %s\n", GOLDEN);
  }
  unsigned char* golden = NULL;
  int gw = 0, gh = 0;
  EXPECT_EQ_INT(0, gr_png_read(GOLDEN, &golden, &gw, &gh, err, sizeof(err)));
  EXPECT_EQ_INT(160, gw);
  EXPECT_EQ_INT(120, gh);
  if (img && golden && gw == 160 && gh == 120) {
    int maxdiff;
    double mad = gr_image_mean_abs_diff(img, golden, 160, 120, &maxdiff);
    printf("golden: mean |diff| %.4f per channel, max %d (tolerance %.1f)\n", mad, maxdiff,
           kGoldenTolerance);
    EXPECT_NEAR(0, mad, kGoldenTolerance);
    // the scene: a sky (top right pixel light blue, not the black of no skybox) over a
    // checker floor (the bottom row spans two grey levels, > 30 apart)
    const unsigned char* sky = img + (5 * 160 + 155) * 3;
    printf("sky pixel %d %d %d\n", sky[0], sky[1], sky[2]);
    EXPECT_TRUE(sky[2] > 150 && sky[2] > sky[0] + 20);
    int lo = 255, hi = 0;
    for (int x = 0; x < 160; x++) {
      int v = img[(119 * 160 + x) * 3 + 1];
      lo = v < lo ? v : lo;
      hi = v > hi ? v : hi;
    }
    printf("floor row green %d..%d\n", lo, hi);
    EXPECT_TRUE(hi - lo > 30);
    // a test that cannot fail is a defect: another pose, and no GRF arrows, are detected
    unsigned char* other = render_at(&r, &mo, 0.45);
    double mad_pose = other ? gr_image_mean_abs_diff(other, golden, 160, 120, NULL) : 0;
    printf("golden vs 45 %% of the cycle: %.4f\n", mad_pose);
    EXPECT_TRUE(mad_pose > kGoldenTolerance);
    free(other);
    r.o.grf_scale = 0;
    r.o.knee_scale = 0;
    r.o.overlay = 0;
    unsigned char* bare = render_at(&r, &mo, 0.35);
    double mad_bare = bare ? gr_image_mean_abs_diff(bare, golden, 160, 120, NULL) : 0;
    printf("golden vs no arrows and no overlay: %.4f\n", mad_bare);
    EXPECT_TRUE(mad_bare > kGoldenTolerance);
    // and the bones: that frame without the bone meshes (group 1) differs from it as much
    r.opt.geomgroup[1] = 0;
    unsigned char* boneless = render_at(&r, &mo, 0.35);
    double mad_boneless =
        boneless && bare ? gr_image_mean_abs_diff(boneless, bare, 160, 120, NULL) : 0;
    printf("no arrows and no overlay vs also no bone meshes: %.4f\n", mad_boneless);
    EXPECT_TRUE(mad_boneless > kGoldenTolerance);
    free(boneless);
    free(bare);
  }
  free(img);
  free(golden);
  gr_renderer_free(&r);
  gr_motion_free(&mo);
  mj_deleteModel(m);
}

// copy of the model file at `src` without its display meshes (the <mesh> assets and the geoms
// of class bone / implant, one per line as scripts/osim2mjcf.py writes them) into `dst`;
// returns the number of lines left out
static int write_without_meshes(const char* src, const char* dst) {
  FILE* in = fopen(src, "r");
  FILE* out = fopen(dst, "w");
  int dropped = 0;
  char line[8192];
  while (in && out && fgets(line, sizeof(line), in)) {
    if (strstr(line, "<mesh ") || strstr(line, "class=\"bone\" mesh=") ||
        strstr(line, "class=\"implant\" mesh=")) {
      dropped++;
      continue;
    }
    fputs(line, out);
  }
  if (in) fclose(in);
  if (out) fclose(out);
  return dropped;
}

// bitwise equality of n values, printing the first difference
static int same_bits(const char* what, const mjtNum* a, const mjtNum* b, int n) {
  for (int i = 0; i < n; i++) {
    if (memcmp(a + i, b + i, sizeof(mjtNum)) != 0) {
      fprintf(stderr, "%s[%d]: %.17g with meshes, %.17g without\n", what, i, a[i], b[i]);
      return 0;
    }
  }
  return 1;
}

// step both models from the standing keyframe, all controls at 0.3, and compare the state
static void expect_same_motion(const mjModel* a, const mjModel* b, int steps) {
  mjData* da = mj_makeData(a);
  mjData* db = mj_makeData(b);
  mj_resetDataKeyframe(a, da, 0);
  mj_resetDataKeyframe(b, db, 0);
  for (int k = 0; k < a->nu; k++) da->ctrl[k] = db->ctrl[k] = 0.3;
  for (int s = 0; s < steps; s++) {
    mj_step(a, da);
    mj_step(b, db);
  }
  EXPECT_TRUE(mju_norm(da->qvel, a->nv) > 1e-3);  // it moved
  EXPECT_TRUE(same_bits("qpos", da->qpos, db->qpos, a->nq));
  EXPECT_TRUE(same_bits("qvel", da->qvel, db->qvel, a->nv));
  EXPECT_TRUE(same_bits("qacc", da->qacc, db->qacc, a->nv));
  EXPECT_TRUE(same_bits("act", da->act, db->act, a->na));
  EXPECT_TRUE(same_bits("qfrc_passive", da->qfrc_passive, db->qfrc_passive, a->nv));
  EXPECT_EQ_INT(db->ncon, da->ncon);
  mj_deleteData(da);
  mj_deleteData(db);
}

// The bone and implant meshes are display only: each model file against its own copy without
// them has the same masses and inertias, bit for bit, and moves the same, bit for bit, for
// 200 steps in stock MuJoCo (its contact solver, no gaitsim callback) and with gaitsim's
// physics (muscles, foot contact and, in the knee6 model, the implant knee's surrogate).
static void display_meshes_should_change_no_physics(void) {
  static const char* const models[] = {"/mjmodels/jw_fullbody.xml",
                                       "/mjmodels/jw_fullbody_knee6.xml",
                                       "/mjmodels/gait2d.xml"};
  enum { kModels = 3 };
  mjModel* with[kModels] = {NULL};
  mjModel* without[kModels] = {NULL};
  char err[1024], path[1024], bare[] = "/tmp/gaitsim_test_render_XXXXXX";
  int fd = mkstemp(bare);
  EXPECT_TRUE(fd >= 0);
  if (fd < 0) return;
  close(fd);
  for (int i = 0; i < kModels; i++) {
    snprintf(path, sizeof(path), "%s%s", GAITSIM_SOURCE_DIR, models[i]);
    with[i] = gs_model_load(path, err, sizeof(err));
    EXPECT_TRUE(with[i] != NULL);
    EXPECT_TRUE(write_without_meshes(path, bare) >= 2 * 83);  // 83 assets + 83 geoms
    without[i] = gs_model_load(bare, err, sizeof(err));
    EXPECT_TRUE(without[i] != NULL);
    if (!with[i] || !without[i]) {
      fprintf(stderr, "%s: %s\n", models[i], err);
      continue;
    }
    const mjModel* a = with[i];
    const mjModel* b = without[i];
    // 83 meshes (81 bones, 2 implant parts), every mesh geom visual only
    EXPECT_EQ_INT(83, a->nmesh);
    EXPECT_EQ_INT(0, b->nmesh);
    EXPECT_EQ_INT(b->ngeom + 83, a->ngeom);
    for (int g = 0; g < a->ngeom; g++) {
      if (a->geom_type[g] != mjGEOM_MESH) continue;
      EXPECT_EQ_INT(0, a->geom_contype[g]);
      EXPECT_EQ_INT(0, a->geom_conaffinity[g]);
      EXPECT_EQ_INT(1, a->geom_group[g]);
    }
    EXPECT_EQ_INT(b->nbody, a->nbody);
    if (a->nbody != b->nbody) continue;
    EXPECT_TRUE(same_bits("body_mass", a->body_mass, b->body_mass, a->nbody));
    EXPECT_TRUE(same_bits("body_subtreemass", a->body_subtreemass, b->body_subtreemass,
                          a->nbody));
    EXPECT_TRUE(same_bits("body_inertia", a->body_inertia, b->body_inertia, 3 * a->nbody));
    EXPECT_TRUE(same_bits("body_ipos", a->body_ipos, b->body_ipos, 3 * a->nbody));
    EXPECT_TRUE(same_bits("body_iquat", a->body_iquat, b->body_iquat, 4 * a->nbody));
    EXPECT_TRUE(same_bits("dof_invweight0", a->dof_invweight0, b->dof_invweight0, a->nv));
    EXPECT_TRUE(same_bits("meaninertia", &a->stat.meaninertia, &b->stat.meaninertia, 1));
    expect_same_motion(a, b, 200);  // stock MuJoCo
  }
  unlink(bare);
  // gaitsim's physics (process-global callbacks: installed after the stock runs)
  gs_physics_install();
  for (int i = 0; i < kModels; i++) {
    if (!with[i] || !without[i]) continue;
    EXPECT_EQ_INT(0, gs_physics_prepare(with[i], err, sizeof(err)));
    EXPECT_EQ_INT(0, gs_physics_prepare(without[i], err, sizeof(err)));
    expect_same_motion(with[i], without[i], 200);
  }
  for (int i = 0; i < kModels; i++) {
    if (with[i]) mj_deleteModel(with[i]);
    if (without[i]) mj_deleteModel(without[i]);
  }
}

// the fixture maps onto the model: stride, activations, forces, cycles
static void fixture_should_load_and_repeat_with_forward_translation(void) {
  char err[1024];
  mjModel* m = gs_model_load(MODEL, err, sizeof(err));
  if (!m) return;
  grMotion mo;
  EXPECT_EQ_INT(0, load_fixture(m, &mo));
  double T = gr_motion_stride_time(&mo);
  EXPECT_NEAR(1.1055, T, 1e-3);                 // trial.json stride_time_s
  EXPECT_NEAR(1.404, mo.advance, 0.01);         // trial.json stride_length_m
  EXPECT_NEAR(62.64 * 9.80665, mo.body_weight, 1.0);
  EXPECT_EQ_INT(m->nu, mo.smap.na_found);       // activations from states.sto
  EXPECT_TRUE(mo.knee_col[0] >= 0);
  mjData* d = mj_makeData(m);
  grFrameForces f0, f1;
  gr_motion_apply(m, &mo, 0.3 * T, d, &f0);
  int knee = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "knee_flexion")];
  double tx0 = d->qpos[mo.advance_qpos], knee0 = d->qpos[knee];
  gr_motion_apply(m, &mo, 2.3 * T, d, &f1);
  double tx1 = d->qpos[mo.advance_qpos], knee1 = d->qpos[knee];
  EXPECT_EQ_INT(0, f0.cycle);
  EXPECT_EQ_INT(2, f1.cycle);
  EXPECT_NEAR(0.3, f1.phase, 1e-9);
  EXPECT_NEAR(tx0 + 2 * mo.advance, tx1, 1e-9);  // two strides further
  EXPECT_NEAR(knee0, knee1, 1e-12);              // same joint angles
  EXPECT_NEAR(f0.cop[0][0] + 2 * mo.advance, f1.cop[0][0], 1e-9);
  EXPECT_EQ_INT(1, f0.colour_source);
  // at 30 % of the cycle the right foot is in stance: upward force of about body weight
  EXPECT_TRUE(f0.grf_on[0]);
  EXPECT_TRUE(f0.grf[0][2] > 0.5 * mo.body_weight && f0.grf[0][2] < 1.5 * mo.body_weight);
  // frame count = fps x duration
  EXPECT_EQ_INT(199, gr_frame_count(60, 3, T));  // 60 x 3 x 1.1055 = 198.99
  EXPECT_EQ_INT(11, gr_frame_count(10, 1, T));
  EXPECT_EQ_INT(1, gr_frame_count(10, 1, 0));
  mj_deleteData(d);
  gr_motion_free(&mo);
  // a bare pose file: the trial's coordinates (degrees)
  EXPECT_EQ_INT(0, gr_motion_load_pose(m, GAITSIM_SOURCE_DIR
                                       "/mjmodels/trials/jw_ngait_og5/coordinates.mot",
                                       &mo, err, sizeof(err)));
  EXPECT_EQ_INT(26, mo.smap.nq_found);
  gr_motion_free(&mo);
  mj_deleteModel(m);
}

// expect loading dir to fail with a message naming `name`
static void expect_load_error(const mjModel* m, const char* dir, const char* name) {
  grMotion mo;
  char err[1024] = "";
  int rc = gr_motion_load_solution(m, dir, &mo, err, sizeof(err));
  EXPECT_EQ_INT(-1, rc);
  if (!strstr(err, name)) {
    fprintf(stderr, "error '%s' does not name %s\n", err, name);
  }
  EXPECT_TRUE(strstr(err, name) != NULL);
  if (rc == 0) gr_motion_free(&mo);
}

// missing or malformed files give an error naming the file
static void bad_solution_folders_should_name_the_file(void) {
  char err[1024];
  mjModel* m = gs_model_load(MODEL, err, sizeof(err));
  if (!m) return;
  char dir[] = "/tmp/gaitsim_test_render.XXXXXX";
  if (!mkdtemp(dir)) {
    EXPECT_TRUE(0);
    mj_deleteModel(m);
    return;
  }
  char path[1200];
  expect_load_error(m, "/nonexistent/solution", "/nonexistent/solution");
  static const char* const required[] = {"states.sto", "controls.sto", "grf.mot"};
  for (int i = 0; i < 3; i++) {
    copy_fixture(dir, required[i]);
    expect_load_error(m, dir, required[i]);
    snprintf(path, sizeof(path), "%s/%s", dir, required[i]);
    write_text(path, "x\nversion=1\nnRows=1\nnColumns=2\nendheader\ntime\tdrop\n0\tnan\n");
    expect_load_error(m, dir, required[i]);  // malformed
  }
  // knee_contact.sto is optional, but when present it must be well formed
  copy_fixture(dir, NULL);
  snprintf(path, sizeof(path), "%s/knee_contact.sto", dir);
  write_text(path, "x\nversion=1\nnRows=2\nnColumns=2\nendheader\ntime\tother\n0\t1\n1\t2\n");
  expect_load_error(m, dir, "knee_contact.sto");
  unlink(path);
  grMotion mo;
  EXPECT_EQ_INT(0, gr_motion_load_solution(m, dir, &mo, err, sizeof(err)));
  EXPECT_TRUE(mo.knee_col[0] < 0 && mo.knee_col[1] < 0);  // no knee arrows
  gr_motion_free(&mo);
  // grf.mot without the left foot, and one that stops before the stride ends
  snprintf(path, sizeof(path), "%s/grf.mot", dir);
  write_text(path,
             "grf\nversion=1\nnRows=2\nnColumns=7\nendheader\ntime\tground_force_r_vx\t"
             "ground_force_r_vy\tground_force_r_vz\tground_force_r_px\tground_force_r_py\t"
             "ground_force_r_pz\n0\t0\t0\t0\t0\t0\t0\n1.2\t0\t0\t0\t0\t0\t0\n");
  expect_load_error(m, dir, "ground_force_l_vx");
  copy_fixture(dir, NULL);
  snprintf(path, sizeof(path), "%s/controls.sto", dir);
  write_text(path, "controls\nversion=1\nnRows=2\nnColumns=2\nendheader\ntime\tsoleus\n0\t0.1\n"
                   "0.5\t0.2\n");
  expect_load_error(m, dir, "does not cover");
  // states naming no joint of the model
  copy_fixture(dir, NULL);
  snprintf(path, sizeof(path), "%s/states.sto", dir);
  write_text(path, "states\nversion=1\nnRows=2\nnColumns=2\nendheader\ntime\tnot_a_joint\n0\t1\n"
                   "1\t2\n");
  expect_load_error(m, dir, "no column names a joint");
  static const char* const all[] = {"states.sto", "controls.sto", "grf.mot", "knee_contact.sto"};
  for (int i = 0; i < 4; i++) {
    snprintf(path, sizeof(path), "%s/%s", dir, all[i]);
    unlink(path);
  }
  rmdir(dir);
  mj_deleteModel(m);
}

// PNG write then read gives the same pixels; a file that is not a PNG is refused
static void png_should_round_trip(void) {
  unsigned char img[7 * 5 * 3];
  for (int i = 0; i < (int)sizeof(img); i++) img[i] = (unsigned char)(i * 37 % 256);
  char path[] = "/tmp/gaitsim_test_png.XXXXXX";
  int fd = mkstemp(path);
  if (fd >= 0) close(fd);
  char err[1024];
  EXPECT_EQ_INT(0, gr_png_write(path, img, 7, 5, err, sizeof(err)));
  unsigned char* back = NULL;
  int w = 0, h = 0;
  EXPECT_EQ_INT(0, gr_png_read(path, &back, &w, &h, err, sizeof(err)));
  EXPECT_EQ_INT(7, w);
  EXPECT_EQ_INT(5, h);
  if (back && w == 7 && h == 5) EXPECT_TRUE(memcmp(img, back, sizeof(img)) == 0);
  free(back);
  write_text(path, "not a png\n");
  EXPECT_EQ_INT(-1, gr_png_read(path, &back, &w, &h, err, sizeof(err)));
  unlink(path);
  EXPECT_EQ_INT(-1, gr_png_write("/nonexistent/dir/x.png", img, 7, 5, err, sizeof(err)));
}

// pixel (u right, v down) of world point p through the renderer's free camera, MuJoCo's
// convention (mjv_updateCamera): forward f = (cos e cos a, cos e sin a, sin e), up
// (-sin e cos a, -sin e sin a, cos e), eye at lookat - distance f, vertical field of view fovy
// (deg), square pixels; 0 when p is behind the camera
static int project(const grRenderer* r, const double* p, double* u, double* v) {
  double a = r->cam.azimuth * mjPI / 180, e = r->cam.elevation * mjPI / 180;
  double f[3] = {cos(e) * cos(a), cos(e) * sin(a), sin(e)};
  double up[3] = {-sin(e) * cos(a), -sin(e) * sin(a), cos(e)};
  double right[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2],
                     f[0] * up[1] - f[1] * up[0]};
  double rel[3];
  for (int i = 0; i < 3; i++) rel[i] = p[i] - (r->cam.lookat[i] - r->cam.distance * f[i]);
  double z = rel[0] * f[0] + rel[1] * f[1] + rel[2] * f[2];
  if (z <= 0) return 0;
  double x = rel[0] * right[0] + rel[1] * right[1] + rel[2] * right[2];
  double y = rel[0] * up[0] + rel[1] * up[1] + rel[2] * up[2];
  double t = tan(r->m->vis.global.fovy * mjPI / 360), w = r->o.width, h = r->o.height;
  *u = 0.5 * w * (1 + x / (z * t * w / h));
  *v = 0.5 * h * (1 - y / (z * t));
  return 1;
}

// 1 when a body pixel (mask) lies within `radius` pixels of (u, v)
static int near_mask(const unsigned char* mask, int w, int h, double u, double v, int radius) {
  for (int dv = -radius; dv <= radius; dv++)
    for (int du = -radius; du <= radius; du++) {
      int x = (int)floor(u) + du, y = (int)floor(v) + dv;
      if (x >= 0 && y >= 0 && x < w && y < h && mask[y * w + x]) return 1;
    }
  return 0;
}

// An independent check of the picture (the golden image is the program's own output): every
// hinge joint's anchor in the drawn pose (d->xanchor after mj_kinematics), projected through the
// camera by project() above, lies within 2 pixels of a pixel the body covers: one that differs
// (by more than 24 of 255 in a channel) from the same frame drawn with the body's geoms and
// tendons hidden. Moved 0.4 m forward (world +x) the anchors land on the body at most a third
// of the time, so a wrong camera, pose or projection fails it.
static void joint_positions_should_project_onto_the_body(void) {
  mjModel* m;
  grMotion mo;
  grOptions o;
  grRenderer r;
  gr_options_default(&o);
  o.overlay = 0;
  o.grf_scale = 0;
  o.knee_scale = 0;
  if (open_fixture(320, 240, &o, &m, &mo, &r) != 0) return;
  unsigned char* img = render_at(&r, &mo, 0.35);
  mj_kinematics(m, r.d);
  int nj = 0, on = 0, on_moved = 0, inside = 0;
  double* uv = (double*)calloc(4 * (size_t)m->njnt, sizeof(double));
  for (int j = 0; j < m->njnt; j++) {
    if (m->jnt_type[j] != mjJNT_HINGE) continue;
    const double* p = r.d->xanchor + 3 * j;
    double moved[3] = {p[0] + 0.4, p[1], p[2]};
    int ok = project(&r, p, &uv[4 * nj], &uv[4 * nj + 1]) &&
             project(&r, moved, &uv[4 * nj + 2], &uv[4 * nj + 3]);
    inside += ok && uv[4 * nj] >= 0 && uv[4 * nj] < o.width && uv[4 * nj + 1] >= 0 &&
              uv[4 * nj + 1] < o.height;
    nj++;
  }
  // the same frame without the body: its geoms to group 5 (hidden), no tendons
  for (int g = 0; g < m->ngeom; g++)
    if (m->geom_bodyid[g] > 0) m->geom_group[g] = 5;
  r.opt.geomgroup[5] = 0;
  for (int k = 0; k < mjNGROUP; k++) r.opt.tendongroup[k] = 0;
  unsigned char* bare = render_at(&r, &mo, 0.35);
  unsigned char* mask = (unsigned char*)calloc((size_t)o.width * o.height, 1);
  long body_pixels = 0;
  for (int i = 0; img && bare && mask && i < o.width * o.height; i++) {
    for (int c = 0; c < 3; c++) mask[i] |= abs(img[3 * i + c] - bare[3 * i + c]) > 24;
    body_pixels += mask[i];
  }
  for (int j = 0; mask && j < nj; j++) {
    on += near_mask(mask, o.width, o.height, uv[4 * j], uv[4 * j + 1], 2);
    on_moved += near_mask(mask, o.width, o.height, uv[4 * j + 2], uv[4 * j + 3], 2);
  }
  printf("projected joints: %d hinges, %d in the frame, %d on the body (%ld body pixels); moved "
         "0.4 m forward: %d on the body\n", nj, inside, on, body_pixels, on_moved);
  EXPECT_TRUE(nj >= 15);
  EXPECT_EQ_INT(nj, inside);
  EXPECT_EQ_INT(nj, on);
  EXPECT_TRUE(3 * on_moved <= nj);
  EXPECT_TRUE(body_pixels > 500);
  free(uv), free(img), free(bare), free(mask);
  gr_renderer_free(&r);
  gr_motion_free(&mo);
  mj_deleteModel(m);
}

int main(void) {
  gs_mujoco_install_handlers();
  golden_image_should_match_within_tolerance();  // first: the command's call sequence
  joint_positions_should_project_onto_the_body();
  fixture_should_load_and_repeat_with_forward_translation();
  bad_solution_folders_should_name_the_file();
  png_should_round_trip();
  display_meshes_should_change_no_physics();  // last: installs gaitsim's callbacks
  return GS_TEST_RESULT();
}
