// gr_render.c: OSMesa context, scene decoration and the render jobs.
#include "render/gr_render.h"

#include <GL/osmesa.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "callbacks/gs_tendon_paths.h"
#include "io/gs_atomic.h"
#include "render/gr_image.h"

#define SET_ERR(...)                                                 \
  do {                                                               \
    if (err && errsz > 0) snprintf(err, (size_t)errsz, __VA_ARGS__); \
  } while (0)

static const float kBoneRgba[4] = {0.92f, 0.89f, 0.82f, 1.0f};    // bones
static const float kGrfRgba[4] = {0.10f, 0.75f, 0.20f, 1.0f};     // ground reaction arrows
static const float kKneeRgba[4] = {1.00f, 0.70f, 0.05f, 1.0f};    // knee contact arrows
static const float kLineRgba[4] = {0.55f, 0.55f, 0.58f, 1.0f};    // floor lines
static const float kShadowRgba[4] = {0.30f, 0.30f, 0.31f, 1.0f};  // planar shadows (fast)
static const double kBoneRadius = 0.018;                          // bone capsules (m)
static const double kArrowWidth = 0.012;                          // GRF arrows (m)
static const double kKneeArrowWidth = 0.026;                      // knee arrows, wider than
                                                                  // the bone they run along (m)
static const double kTendonMinWidth = 0.004;                      // drawn tendon radius (m)
static const double kLookatHeight = 0.95;                         // camera target height (m)
static const double kViewHeight = 2.1;                            // height in view (m)
static const int kFastSlices = 12;                                // fast quality: slices
static const int kFastStacks = 6;                                 // fast quality: stacks
static const double kFastPlaneGrid = 1.0;                         // fast quality: plane drawn in
                                                                  // cells of this size (m)
static const double kShadowHalfWidth = 1.6;                       // directional shadow map
                                                                  // covers +-this (m)
static const double kLightDistance = 3.0;                         // directional lights sit this
                                                                  // far up-beam of the target (m)
static const double kShadowFlatten = 1e-3;                        // planar shadow: height scale
static const double kShadowLift = 0.001;                          // planar shadow above floor (m)
static const double kBackdropDistance = 30.0;                     // fast sky: backdrop distance
                                                                  // beyond the target (m)
static const double kBackdropEmission = 100.0;                    // its emission (rgba / this:
                                                                  // lights add ~1 %)

void gr_options_default(grOptions* o) {
  memset(o, 0, sizeof(*o));
  o->width = 1280;
  o->height = 720;
  o->high_quality = 0;
  o->camera = GR_CAMERA_SIDE;
  o->overlay = 1;
  o->grf_scale = 1.0;
  o->knee_scale = 0.25;
  o->distance = 0;
}

long gr_frame_count(int fps, int cycles, double T) {
  long n = lround((double)fps * cycles * T);
  return n < 1 ? 1 : n;
}

// first of the named bodies that exists, or -1
static int find_body(const mjModel* m, const char* const* names) {
  for (; *names; names++) {
    int b = mj_name2id(m, mjOBJ_BODY, *names);
    if (b >= 0) return b;
  }
  return -1;
}

int gr_renderer_create(mjModel* m, const grOptions* o, grRenderer* r, char* err, int errsz) {
  memset(r, 0, sizeof(*r));
  r->o = *o;
  r->m = m;
  int w = o->width, h = o->height;
  if (w < 16 || h < 16 || w > 8192 || h > 8192) {
    SET_ERR("frame size %dx%d outside 16..8192", w, h);
    return -1;
  }
  r->osbuf = (unsigned char*)malloc((size_t)w * h * 4);
  r->rows = (unsigned char*)malloc((size_t)w * h * 3);
  r->tendon_actuator = (int*)malloc(sizeof(int) * (size_t)(m->ntendon > 0 ? m->ntendon : 1));
  r->body_mesh = (unsigned char*)calloc((size_t)m->nbody, 1);
  r->d = mj_makeData(m);
  if (!r->osbuf || !r->rows || !r->tendon_actuator || !r->body_mesh || !r->d) {
    SET_ERR("out of memory for a %dx%d renderer", w, h);
    gr_renderer_free(r);
    return -1;
  }
  // software OpenGL context: RGBA, 24-bit depth, 8-bit stencil
  OSMesaContext ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
  if (!ctx) {
    SET_ERR("OSMesaCreateContextExt failed");
    gr_renderer_free(r);
    return -1;
  }
  r->osmesa = ctx;
  if (!OSMesaMakeCurrent(ctx, r->osbuf, GL_UNSIGNED_BYTE, w, h)) {
    SET_ERR("OSMesaMakeCurrent failed for %dx%d", w, h);
    gr_renderer_free(r);
    return -1;
  }
  // offscreen buffer and quality live in the model and are read by mjr_makeContext
  m->vis.global.offwidth = w;
  m->vis.global.offheight = h;
  m->vis.quality.offsamples = o->high_quality ? 4 : 0;
  m->vis.quality.shadowsize = o->high_quality ? 4096 : 1024;
  // directional shadow map: +-kShadowHalfWidth around the light's axis, which place_lights
  // aims at the camera target (MuJoCo sizes it as shadowclip x stat.extent)
  if (m->stat.extent > 0) m->vis.map.shadowclip = (float)(kShadowHalfWidth / m->stat.extent);
  // tessellation of spheres, capsules, cylinders: llvmpipe's cost is in the triangles (fast:
  // 12 x 6 instead of MuJoCo's 28 x 16 gave about 4x the frame rate at 1280x720)
  if (!o->high_quality) {
    if (m->vis.quality.numslices > kFastSlices) m->vis.quality.numslices = kFastSlices;
    if (m->vis.quality.numstacks > kFastStacks) m->vis.quality.numstacks = kFastStacks;
  }
  // planes: MuJoCo draws up to 200 x 200 cells of geom size[2] (the models' 0.1 m: 20,000
  // textured quads for the 10 x 5 m floor); size[2] is drawing-only for a plane
  for (int g = 0; g < m->ngeom && !o->high_quality; g++) {
    if (m->geom_type[g] == mjGEOM_PLANE && m->geom_size[3 * g + 2] < kFastPlaneGrid) {
      m->geom_size[3 * g + 2] = kFastPlaneGrid;
    }
  }
  for (int i = 0; i < m->ntendon; i++) {
    if (m->tendon_width[i] < kTendonMinWidth) m->tendon_width[i] = kTendonMinWidth;
  }
  int fontscale = h < 400 ? mjFONTSCALE_50 : (h < 1000 ? mjFONTSCALE_100 : mjFONTSCALE_150);
  mjr_defaultContext(&r->con);
  mjr_makeContext(m, &r->con, fontscale);
  mjr_setBuffer(mjFB_OFFSCREEN, &r->con);
  if (r->con.currentBuffer != mjFB_OFFSCREEN || r->con.offWidth < w || r->con.offHeight < h) {
    SET_ERR("no %dx%d offscreen framebuffer in the OSMesa context", w, h);
    gr_renderer_free(r);
    return -1;
  }
  mjv_defaultScene(&r->scn);
  mjv_makeScene(m, &r->scn, 4000);
  mjv_defaultOption(&r->opt);
  // shadows: MuJoCo's shadow maps in high quality; in fast quality they tripled the cost of
  // the bone meshes on llvmpipe, so add_planar_shadows draws flattened ellipsoids on the floor
  r->scn.flags[mjRND_SHADOW] = (mjtByte)(o->high_quality != 0);
  r->scn.flags[mjRND_REFLECTION] = (mjtByte)(o->high_quality != 0);
  // sky: the model's skybox texture (else black); in fast quality a backdrop of its mean
  // colour instead (MuJoCo's cube-mapped skybox cost 5-8 ms of CPU per 1280x720 frame on
  // llvmpipe, as much as the bone meshes)
  for (int t = 0; t < m->ntex && !r->has_sky; t++) {
    if (m->tex_type[t] != mjTEXTURE_SKYBOX) continue;
    long n = (long)m->tex_width[t] * m->tex_height[t];
    double sum[3] = {0, 0, 0};
    for (long i = 0; i < n; i++) {
      for (int k = 0; k < 3; k++) sum[k] += m->tex_rgb[m->tex_adr[t] + 3 * i + k];
    }
    for (int k = 0; k < 3; k++) r->sky_rgb[k] = n > 0 ? (float)(sum[k] / n / 255.0) : 0.0f;
    r->has_sky = 1;
  }
  r->scn.flags[mjRND_SKYBOX] = (mjtByte)(o->high_quality != 0);
  // bodies drawn by a mesh of a visible group get no stick-figure capsule; a floor with a
  // material (the models' checker texture) needs no drawn lines
  for (int g = 0; g < m->ngeom; g++) {
    int group = m->geom_group[g];
    if (group < 0 || group >= mjNGROUP || !r->opt.geomgroup[group]) continue;
    if (m->geom_type[g] == mjGEOM_MESH) r->body_mesh[m->geom_bodyid[g]] = 1;
    if (m->geom_type[g] == mjGEOM_PLANE && m->geom_matid[g] >= 0) r->floor_textured = 1;
    if (m->geom_type[g] == mjGEOM_PLANE && m->geom_bodyid[g] == 0 && !r->has_floor) {
      r->has_floor = 1;
      r->floor_height = m->geom_pos[3 * g + 2];
    }
  }
  // with bone meshes the contact spheres (group 2) would hide the feet: not drawn
  for (int b = 0; b < m->nbody; b++) {
    if (r->body_mesh[b]) r->opt.geomgroup[2] = 0;
  }
  mjv_defaultCamera(&r->cam);
  r->cam.type = mjCAMERA_FREE;
  // which actuator drives each tendon (colours)
  for (int i = 0; i < m->ntendon; i++) r->tendon_actuator[i] = -1;
  for (int a = 0; a < m->nu; a++) {
    if (m->actuator_trntype[a] == mjTRN_TENDON) {
      int t = m->actuator_trnid[2 * a];
      if (t >= 0 && t < m->ntendon) r->tendon_actuator[t] = a;
    }
  }
  static const char* const pelvis[] = {"pelvis", NULL};
  static const char* const knee_r[] = {"tibial_tray", "tibia", "tibia_r", NULL};
  static const char* const knee_l[] = {"tibia_l", NULL};
  static const char* const talus_r[] = {"talus", "talus_r", NULL};
  static const char* const talus_l[] = {"talus_l", NULL};
  r->pelvis_body = find_body(m, pelvis);
  if (r->pelvis_body < 0) r->pelvis_body = m->nbody > 1 ? 1 : 0;
  r->knee_body[0] = find_body(m, knee_r);
  r->knee_body[1] = find_body(m, knee_l);
  r->knee_distal[0] = find_body(m, talus_r);
  r->knee_distal[1] = find_body(m, talus_l);
  return 0;
}

void gr_renderer_free(grRenderer* r) {
  if (r->osmesa) {
    OSMesaMakeCurrent((OSMesaContext)r->osmesa, r->osbuf, GL_UNSIGNED_BYTE, r->o.width,
                      r->o.height);
    mjr_freeContext(&r->con);
    mjv_freeScene(&r->scn);
    OSMesaMakeCurrent(NULL, NULL, GL_UNSIGNED_BYTE, 0, 0);  // unbind, so Mesa frees the buffer
    OSMesaDestroyContext((OSMesaContext)r->osmesa);
  }
  if (r->d) mj_deleteData(r->d);
  free(r->osbuf);
  free(r->rows);
  free(r->tendon_actuator);
  free(r->body_mesh);
  memset(r, 0, sizeof(*r));
}

// ---------------------------------------------------------------------------------------------
// decoration

// next free geom of the scene, initialised as a decoration, or NULL when full. The slot is
// cleared first: MuJoCo 2.2's mjv_initGeom leaves objtype/objid as the previous frame left
// them, and a stale mjOBJ_TENDON would have decorate() recolour the decoration
static mjvGeom* add_geom(mjvScene* scn, int type, const float rgba[4]) {
  if (scn->ngeom >= scn->maxgeom) return NULL;
  mjvGeom* g = scn->geoms + scn->ngeom++;
  memset(g, 0, sizeof(*g));
  mjv_initGeom(g, type, NULL, NULL, NULL, rgba);
  g->objtype = mjOBJ_UNKNOWN;
  g->objid = -1;
  g->dataid = -1;
  g->texid = -1;
  g->segid = -1;
  g->category = mjCAT_DECOR;
  return g;
}

static void add_connector(mjvScene* scn, int type, double width, const double a[3],
                          const double b[3], const float rgba[4]) {
  mjvGeom* g = add_geom(scn, type, rgba);
  if (!g) return;
  mjv_makeConnector(g, type, width, a[0], a[1], a[2], b[0], b[1], b[2]);
  // MuJoCo 2.2's renderer draws an arrow of size[2] as size[2]/2 long (shaft 1/3, head 1/6):
  // double it so the arrow ends at b (checked on a rendered frame)
  if (type == mjGEOM_ARROW) g->size[2] *= 2;
}

// blue (0) -> red (1), through purple
static void activation_rgba(double a, float rgba[4]) {
  if (!(a >= 0)) a = 0;
  if (a > 1) a = 1;
  rgba[0] = (float)(0.15 + 0.80 * a);
  rgba[1] = (float)(0.20 - 0.10 * a);
  rgba[2] = (float)(0.90 - 0.80 * a);
  rgba[3] = 1.0f;
}

static void decorate(grRenderer* r, const grMotion* mo, const grFrameForces* ff) {
  const mjModel* m = r->m;
  const mjData* d = r->d;
  mjvScene* scn = &r->scn;
  // muscles: colour the tendon segments MuJoCo drew
  if (ff->colour_source) {
    for (int i = 0; i < scn->ngeom; i++) {
      mjvGeom* g = scn->geoms + i;
      if (g->objtype != mjOBJ_TENDON || g->objid < 0 || g->objid >= m->ntendon) continue;
      int a = r->tendon_actuator[g->objid];
      if (a < 0) continue;
      int ia = a - (m->nu - m->na);
      double v = (ff->colour_source == 1 && ia >= 0) ? d->act[ia] : d->ctrl[a];
      activation_rgba(v, g->rgba);
    }
  }
  // bones without a mesh: parent origin -> child origin, for bodies that move
  for (int b = 1; b < m->nbody; b++) {
    int p = m->body_parentid[b];
    if (p <= 0 || m->body_weldid[p] == 0 || r->body_mesh[p]) continue;
    const double* a = d->xpos + 3 * p;
    const double* c = d->xpos + 3 * b;
    double dx[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    if (mju_norm3(dx) < 0.02) continue;
    add_connector(scn, mjGEOM_CAPSULE, kBoneRadius, a, c, kBoneRgba);
  }
  // ground reaction arrows at the centre of pressure
  for (int f = 0; f < 2; f++) {
    if (!ff->grf_on[f] || r->o.grf_scale <= 0) continue;
    double tip[3], s = r->o.grf_scale / mo->body_weight;
    for (int k = 0; k < 3; k++) tip[k] = ff->cop[f][k] + s * ff->grf[f][k];
    add_connector(scn, mjGEOM_ARROW, kArrowWidth, ff->cop[f], tip, kGrfRgba);
  }
  // knee contact: along the tibia's axis, pointing onto the plateau
  for (int f = 0; f < 2; f++) {
    int b = r->knee_body[f], bd = r->knee_distal[f];
    if (!ff->knee_on[f] || b < 0 || bd < 0 || ff->knee[f] <= 0 || r->o.knee_scale <= 0) continue;
    const double* p = d->xpos + 3 * b;
    double u[3] = {d->xpos[3 * bd] - p[0], d->xpos[3 * bd + 1] - p[1], d->xpos[3 * bd + 2] - p[2]};
    if (mju_normalize3(u) < 1e-6) continue;
    double len = ff->knee[f] / mo->body_weight * r->o.knee_scale, tail[3];
    for (int k = 0; k < 3; k++) tail[k] = p[k] - len * u[k];
    add_connector(scn, mjGEOM_ARROW, kKneeArrowWidth, tail, p, kKneeRgba);
  }
  // floor lines every 0.5 m across the walking direction, around the camera target (a
  // textured floor shows the progression itself)
  if (r->floor_textured) return;
  double x0 = floor((r->cam.lookat[0] - 4.0) / 0.5) * 0.5;
  for (int i = 0; i <= 16; i++) {
    double x = x0 + 0.5 * i;
    mjvGeom* g = add_geom(scn, mjGEOM_BOX, kLineRgba);
    if (!g) break;
    mjtNum size[3] = {0.004, 0.6, 0.0005}, pos[3] = {x, r->cam.lookat[1], 0.0005};
    mjtNum mat[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    mjv_initGeom(g, mjGEOM_BOX, size, pos, mat, kLineRgba);
    g->category = mjCAT_DECOR;
  }
}

// free camera on the pelvis for the chosen viewpoint
static void place_camera(grRenderer* r) {
  const double* p = r->d->xpos + 3 * r->pelvis_body;
  double fovy = r->m->vis.global.fovy > 1 ? r->m->vis.global.fovy : 45;
  double fit = kViewHeight / (2 * tan(fovy * mjPI / 360));
  r->cam.lookat[0] = p[0];
  r->cam.lookat[1] = p[1];
  r->cam.lookat[2] = kLookatHeight;
  r->cam.distance = r->o.distance > 0 ? r->o.distance : fit;
  switch (r->o.camera) {
    case GR_CAMERA_FRONT: r->cam.azimuth = 180; r->cam.elevation = -8; break;
    case GR_CAMERA_FOLLOW:
      r->cam.azimuth = 45;
      r->cam.elevation = -15;
      r->cam.distance *= 1.15;
      break;
    case GR_CAMERA_SIDE:
    default: r->cam.azimuth = 90; r->cam.elevation = -8; break;
  }
}

// directional lights (not the headlight) follow the camera target, so the shadow map, which
// MuJoCo centres on the light's axis, covers the body wherever it walks
static void place_lights(grRenderer* r) {
  for (int i = 0; i < r->scn.nlight; i++) {
    mjvLight* l = r->scn.lights + i;
    if (!l->directional || l->headlight) continue;
    double dir[3] = {l->dir[0], l->dir[1], l->dir[2]};
    if (mju_normalize3(dir) < 1e-6) continue;
    for (int k = 0; k < 3; k++) l->pos[k] = (float)(r->cam.lookat[k] - kLightDistance * dir[k]);
  }
}

// fast-quality shadows: for every mesh geom of the model, the ellipsoid of its bounding box
// (MuJoCo's geom size of a mesh: half-sizes in the mesh's principal frame) projected along the
// first directional light (else straight down) onto the floor plane z = floor_height,
// flattened to kShadowFlatten of its height (non-singular, so its normals point up and it is
// lit like the floor) and kShadowLift above it, in one dark colour. Ellipsoids, not the
// meshes: projecting the meshes themselves (62,000 triangles) halved the frame rate on
// llvmpipe, 83 ellipsoids of 12 x 6 cost little; the shadow is a soft body outline
static void add_planar_shadows(grRenderer* r) {
  mjvScene* scn = &r->scn;
  double dir[3] = {0, 0, -1};
  for (int i = 0; i < scn->nlight; i++) {
    const mjvLight* l = scn->lights + i;
    double u[3] = {l->dir[0], l->dir[1], l->dir[2]};
    if (l->directional && !l->headlight && mju_normalize3(u) > 1e-6 && u[2] < -0.2) {
      mju_copy3(dir, u);
      break;
    }
  }
  double ax = -dir[0] / dir[2], ay = -dir[1] / dir[2], h = r->floor_height;
  int n = scn->ngeom;
  for (int i = 0; i < n; i++) {
    const mjvGeom* g = scn->geoms + i;
    if (g->type != mjGEOM_MESH || g->category == mjCAT_DECOR) continue;
    mjvGeom* s = add_geom(scn, mjGEOM_ELLIPSOID, kShadowRgba);
    if (!s) return;
    for (int k = 0; k < 3; k++) s->size[k] = g->size[k];
    // world x = pos + mat x_local; projected x' = x + a (z - h), y' = y + b (z - h),
    // z' = h + lift + flatten (z - h)
    for (int c = 0; c < 3; c++) {
      s->mat[c] = (float)(g->mat[c] + ax * g->mat[6 + c]);
      s->mat[3 + c] = (float)(g->mat[3 + c] + ay * g->mat[6 + c]);
      s->mat[6 + c] = (float)(kShadowFlatten * g->mat[6 + c]);
    }
    double dz = g->pos[2] - h;
    s->pos[0] = (float)(g->pos[0] + ax * dz);
    s->pos[1] = (float)(g->pos[1] + ay * dz);
    s->pos[2] = (float)(h + kShadowLift + kShadowFlatten * dz);
    s->specular = 0;
  }
}

// fast-quality sky: a large box of the sky colour kBackdropDistance beyond the camera target,
// vertical, facing the camera; emissive, so its colour does not depend on the viewpoint
static void add_backdrop(grRenderer* r) {
  double az = r->cam.azimuth * mjPI / 180, f[2] = {cos(az), sin(az)};
  float rgba[4] = {1, 1, 1, 1};
  for (int k = 0; k < 3; k++) rgba[k] = (float)(r->sky_rgb[k] / kBackdropEmission);
  mjvGeom* g = add_geom(&r->scn, mjGEOM_BOX, rgba);
  if (!g) return;
  // box axes (columns): right = forward x up, forward (horizontal), up
  float mat[9] = {(float)f[1], (float)f[0], 0, (float)-f[0], (float)f[1], 0, 0, 0, 1};
  memcpy(g->mat, mat, sizeof(mat));
  g->size[0] = 80;
  g->size[1] = 0.1f;
  g->size[2] = 50;
  for (int k = 0; k < 2; k++) g->pos[k] = (float)(r->cam.lookat[k] + kBackdropDistance * f[k]);
  g->pos[2] = (float)r->cam.lookat[2];
  g->emission = (float)kBackdropEmission;
  g->specular = 0;
}

void gr_renderer_frame(grRenderer* r, const grMotion* mo, double t, unsigned char* rgb) {
  mjModel* m = r->m;
  mjData* d = r->d;
  grFrameForces ff;
  gr_motion_apply(m, mo, t, d, &ff);
  // positions only: bodies, geoms, lights, tendon paths
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_camlight(m, d);
  mj_tendon(m, d);
  gs_tendon_repair(m, d);  // a path grazing a wrap geom drawn straight, not NaN or the far side
  place_camera(r);
  mjv_updateScene(m, d, &r->opt, NULL, &r->cam, mjCAT_ALL, &r->scn);
  place_lights(r);
  if (!r->o.high_quality && r->has_floor) add_planar_shadows(r);
  if (!r->o.high_quality && r->has_sky) add_backdrop(r);
  decorate(r, mo, &ff);
  mjrRect vp = {0, 0, r->o.width, r->o.height};
  mjr_render(vp, &r->scn, &r->con);
  if (r->o.overlay) {
    char left[64], right[96];
    double T = gr_motion_stride_time(mo);
    snprintf(left, sizeof(left), "time\ncycle");
    snprintf(right, sizeof(right), "%.3f s\n%.0f %% (%d)", ff.cycle * T + ff.time,
             100 * ff.phase, ff.cycle + 1);
    mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, vp, left, right, &r->con);
  }
  mjr_readPixels(r->rows, NULL, vp, &r->con);
  size_t stride = (size_t)r->o.width * 3;
  for (int y = 0; y < r->o.height; y++) {
    memcpy(rgb + (size_t)y * stride, r->rows + (size_t)(r->o.height - 1 - y) * stride, stride);
  }
}

// ---------------------------------------------------------------------------------------------
// jobs

int gr_render_video(grRenderer* r, const grMotion* mo, const grVideoJob* job, long* nframes,
                    char* err, int errsz) {
  *nframes = 0;
  if (job->fps < 1 || job->cycles < 1 || (!job->mp4 && !job->frames_dir) ||
      (job->mp4 && !job->ffmpeg)) {
    SET_ERR("bad video job (fps %d, cycles %d)", job->fps, job->cycles);
    return -1;
  }
  long n = gr_frame_count(job->fps, job->cycles, gr_motion_stride_time(mo));
  if (job->frames_dir && gs_mkdir_p(job->frames_dir, err, errsz) != 0) return -1;
  unsigned char* rgb = (unsigned char*)malloc((size_t)r->o.width * r->o.height * 3);
  if (!rgb) {
    SET_ERR("out of memory");
    return -1;
  }
  grVideo v;
  memset(&v, 0, sizeof(v));
  if (job->mp4 && gr_video_open(&v, job->ffmpeg, job->mp4, r->o.width, r->o.height, job->fps,
                                err, errsz) != 0) {
    free(rgb);
    return -1;
  }
  char path[4096];
  for (long k = 0; k < n; k++) {
    gr_renderer_frame(r, mo, (double)k / job->fps, rgb);
    if (job->mp4 && gr_video_write(&v, rgb, err, errsz) != 0) goto fail;
    if (job->frames_dir) {
      snprintf(path, sizeof(path), "%s/frame_%05ld.png", job->frames_dir, k);
      if (gr_png_write(path, rgb, r->o.width, r->o.height, err, errsz) != 0) goto fail;
    }
  }
  free(rgb);
  if (job->mp4 && gr_video_commit(&v, err, errsz) != 0) return -1;
  *nframes = n;
  return 0;
fail:
  free(rgb);
  gr_video_abort(&v);
  return -1;
}

int gr_render_png(grRenderer* r, const grMotion* mo, double at, const char* path, char* err,
                  int errsz) {
  unsigned char* rgb = (unsigned char*)malloc((size_t)r->o.width * r->o.height * 3);
  if (!rgb) {
    SET_ERR("out of memory");
    return -1;
  }
  gr_renderer_frame(r, mo, at * gr_motion_stride_time(mo), rgb);
  int status = gr_png_write(path, rgb, r->o.width, r->o.height, err, errsz);
  free(rgb);
  return status;
}

int gr_render_strip(grRenderer* r, const grMotion* mo, int count, const char* path, char* err,
                    int errsz) {
  int w = r->o.width, h = r->o.height;
  if (count < 1 || (long)count * w > 32768) {
    SET_ERR("strip of %d frames of width %d: count must be 1..%d", count, w, 32768 / w);
    return -1;
  }
  unsigned char* tile = (unsigned char*)malloc((size_t)w * h * 3);
  unsigned char* strip = (unsigned char*)malloc((size_t)count * w * h * 3);
  if (!tile || !strip) {
    free(tile);
    free(strip);
    SET_ERR("out of memory");
    return -1;
  }
  double T = gr_motion_stride_time(mo);
  for (int i = 0; i < count; i++) {
    gr_renderer_frame(r, mo, T * i / count, tile);
    for (int y = 0; y < h; y++) {
      memcpy(strip + ((size_t)y * count * w + (size_t)i * w) * 3, tile + (size_t)y * w * 3,
             (size_t)w * 3);
    }
  }
  int status = gr_png_write(path, strip, count * w, h, err, errsz);
  free(tile);
  free(strip);
  return status;
}
