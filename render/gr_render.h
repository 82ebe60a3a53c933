// gr_render.h: off-screen rendering of a gait through MuJoCo's renderer on OSMesa (software
// rasterizer: no display, no GPU, no EGL or GLX), scene decoration, and the three jobs of
// `gaitsim render`: a video (mp4 and/or numbered PNG frames), one picture, a filmstrip.
//
// Scene: the model's own geoms (floor, its material, bone and implant meshes; contact spheres
// only when the model has no meshes), skybox, lights and tendons, plus
//  - bones of bodies without a mesh: a capsule from the body's origin to each child body's
//    origin, bodies welded to the world excluded;
//  - muscles: each tendon driven by an actuator coloured by its activation (or excitation)
//    from blue (0) to red (1);
//  - ground reaction force arrows from the centre of pressure, grf_scale m per body weight;
//  - knee contact force arrows along the tibia onto the tibial plateau (body tibial_tray or
//    tibia, and tibia_l), knee_scale m per body weight;
//  - floor lines every 0.5 m when the floor has no material (the models' checker shows the
//    forward progression against the followed camera itself);
//  - shadows: in fast quality each mesh flattened onto the floor along the model's first
//    directional light (planar shadows; no self-shadowing); in high quality MuJoCo's shadow
//    maps, with directional lights moved to follow the camera target;
//  - a text overlay: time (s) and % of the cycle with the cycle number.
// The camera follows the pelvis (body "pelvis", else body 1): side (from the right), front, or
// follow (three-quarter view from behind on the right).
//
// Set-up order for OSMesa (STACK.md): context -> make current -> offscreen size in the model ->
// mjr_makeContext -> mjr_setBuffer(mjFB_OFFSCREEN). Speed: default (fast) quality has planar
// shadows, no reflections or multisampling, tessellates round geoms 12 x 6 (MuJoCo's default
// 28 x 16) and draws planes in 1 m cells; high quality turns on MuJoCo's shadow maps,
// reflections and 4x MSAA and keeps the model's tessellation.
//
// Errors: 0 on success, -1 with one line in err (errsz bytes). Nothing is printed or exits.
#ifndef GAITSIM_RENDER_GR_RENDER_H_
#define GAITSIM_RENDER_GR_RENDER_H_

#include <mujoco/mujoco.h>

#include "render/gr_motion.h"

typedef enum grCameraKind_ {
  GR_CAMERA_SIDE = 0,  // from the model's right (world -y), looking at +y
  GR_CAMERA_FRONT,     // from ahead (world +x), looking back
  GR_CAMERA_FOLLOW     // three-quarter view from behind and to the right
} grCameraKind;

typedef struct grOptions_ {
  int width, height;    // frame size (pixels)
  int high_quality;     // 1: shadow maps, reflections, 4x multisampling; 0: planar shadows (fast)
  grCameraKind camera;  // viewpoint
  int overlay;          // 1: time and % cycle text in the top left corner
  double grf_scale;     // ground reaction arrow length per body weight (m/BW)
  double knee_scale;    // knee contact arrow length per body weight (m/BW)
  double distance;      // camera distance from the pelvis (m); <= 0: fit 2.1 m of height
} grOptions;

// Defaults: 1280 x 720, fast quality, side camera, overlay on, 1 m/BW GRF, 0.25 m/BW knee.
void gr_options_default(grOptions* o);

typedef struct grRenderer_ {
  mjModel* m;              // the model (borrowed; its vis.global.offwidth/offheight, quality,
                           // map.shadowclip, tendon_width and (fast) the plane geoms' drawing
                           // grid size[2] are set by gr_renderer_create)
  mjData* d;               // pose being drawn (owned)
  void* osmesa;            // OSMesa context (OSMesaContext)
  unsigned char* osbuf;    // OSMesa's default framebuffer (width x height x 4 bytes)
  unsigned char* rows;     // mjr_readPixels output, rows bottom-up (width x height x 3 bytes)
  mjrContext con;          // MuJoCo GPU-side (here: llvmpipe) resources
  mjvScene scn;            // abstract scene
  mjvOption opt;           // what MuJoCo draws of the model
  mjvCamera cam;           // free camera
  grOptions o;             // options the renderer was made with
  int* tendon_actuator;    // actuator driving each tendon, -1 for none (ntendon)
  unsigned char* body_mesh;  // 1 where the body carries a visible mesh geom (nbody)
  int floor_textured;      // 1 when a visible plane geom has a material (no floor lines)
  int has_floor;           // 1 when the world has a plane geom (planar shadows fall on it)
  double floor_height;     // height of the world's first plane geom (m)
  int has_sky;             // 1 when the model has a skybox texture
  float sky_rgb[3];        // its mean colour, 0..1 (fast quality's backdrop)
  int pelvis_body;         // body the camera follows
  int knee_body[2];        // tibial plateau body per knee (right, left), -1 when none
  int knee_distal[2];      // the body below it (talus), giving the tibia's axis; -1 when none
} grRenderer;

// Create a renderer for model m with options o (m is modified as stated above).
int gr_renderer_create(mjModel* m, const grOptions* o, grRenderer* r, char* err, int errsz);

// Draw motion mo at time t (s from the start of the first cycle) into rgb (width x height x 3
// bytes, rows top-down).
void gr_renderer_frame(grRenderer* r, const grMotion* mo, double t, unsigned char* rgb);

// Release everything the renderer owns (not the model). Safe on a zeroed struct.
void gr_renderer_free(grRenderer* r);

// Number of video frames for `cycles` strides of stride time T (s) at fps frames/s:
// round(fps * cycles * T), at least 1.
long gr_frame_count(int fps, int cycles, double T);

// A video job: frames k = 0 .. gr_frame_count - 1 at t = k / fps.
typedef struct grVideoJob_ {
  int fps;                 // frames per second
  int cycles;              // strides shown (>= 1)
  const char* mp4;         // mp4 path, NULL for none
  const char* ffmpeg;      // ffmpeg executable (needed when mp4 is set)
  const char* frames_dir;  // folder for numbered PNG frames frame_00000.png ..., NULL for none
} grVideoJob;

// Render the video job; *nframes gets the frames written. On failure no mp4 is left.
int gr_render_video(grRenderer* r, const grMotion* mo, const grVideoJob* job, long* nframes,
                    char* err, int errsz);

// Render one frame at fraction `at` (0..1) of the cycle into the PNG `path`.
int gr_render_png(grRenderer* r, const grMotion* mo, double at, const char* path, char* err,
                  int errsz);

// Render `count` frames at fractions 0, 1/count, ... of the cycle side by side into one PNG
// (count * width x height) at `path`.
int gr_render_strip(grRenderer* r, const grMotion* mo, int count, const char* path, char* err,
                    int errsz);

#endif  // GAITSIM_RENDER_GR_RENDER_H_
