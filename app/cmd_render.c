// cmd_render.c: `gaitsim render SOLUTION_DIR|MODEL.xml ...`: headless videos, pictures and
// filmstrips of a gait (render/gr_render.h).
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include <mujoco/mujoco.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "app/gs_options.h"
#include "callbacks/gs_mujoco.h"
#include "io/gs_atomic.h"
#include "render/gr_image.h"
#include "render/gr_render.h"

static const char* kRenderUsage =
    "usage: gaitsim render SOLUTION_DIR [--model MODEL] OUTPUT [options]\n"
    "       gaitsim render MODEL.xml --pose FILE OUTPUT [options]\n\n"
    "Off-screen rendering (OSMesa, no display or GPU) of a solution folder (states.sto,\n"
    "controls.sto, grf.mot, optional knee_contact.sto) on MODEL (default the model its\n"
    "summary.json names, else the bundled model; any\n"
    "MuJoCo model with the same joint names), or of a pose file (states.sto, coordinates.mot).\n"
    "Muscles coloured by activation (blue 0 .. red 1), ground reaction arrows at the centre of\n"
    "pressure (1 m per body weight), knee contact arrows (0.25 m per body weight).\n\n"
    "OUTPUT (one of):\n"
    "  --out FILE.mp4     H.264 video through ffmpeg; without ffmpeg on PATH, PNG frames are\n"
    "                     written instead (to --frames DIR, else FILE_frames/)\n"
    "  --frames DIR       numbered PNG frames DIR/frame_00000.png ... (also with --out); DIR is\n"
    "                     replaced whole, and only when it holds earlier frames (frame_00000.png)\n"
    "  --png FILE         one frame at --at A (fraction of the cycle, default 0)\n"
    "  --strip FILE       --count N frames (default 8) across the cycle, side by side\n"
    "options:\n"
    "  --size WxH         frame (tile for --strip) size, default 1280x720 (strip 320x480)\n"
    "  --fps N            frames per second of a video, default 60\n"
    "  --cycles N         strides shown in a video, repeated with forward translation, default 1\n"
    "  --camera VIEW      side (default), front or follow; the camera follows the pelvis\n"
    "  --quality Q        fast (default) or high (shadows, reflections, 4x multisampling)\n"
    "  --no-overlay       no time / % cycle text\n"
    "Every output is written beside its name first and put in place when complete: SIGINT,\n"
    "SIGTERM or SIGHUP ends render at once, removing what it had written.\n";

// --size "WxH" -> w, h (16..8192 each); prints the reason
static int parse_size(const char* s, int* w, int* h) {
  char* end;
  long a = strtol(s, &end, 10);
  long b = -1;
  if (end != s && (*end == 'x' || *end == 'X')) {
    const char* s2 = end + 1;
    b = strtol(s2, &end, 10);
    if (end == s2 || *end) b = -1;
  }
  if (b < 16 || a < 16 || a > 8192 || b > 8192) {
    fprintf(stderr, "gaitsim: --size: must be WxH, each an integer in 16..8192 (got %s)\n", s);
    return -1;
  }
  *w = (int)a;
  *h = (int)b;
  return 0;
}

// a model file is a regular file ending in .xml or .mjb
static int is_model_path(const char* path) {
  size_t n = strlen(path);
  struct stat st;
  return n > 4 && (strcmp(path + n - 4, ".xml") == 0 || strcmp(path + n - 4, ".mjb") == 0) &&
         stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int gs_cmd_render(int argc, char** argv) {
  static const struct option options[] = {{"out", required_argument, NULL, 'o'},
                                          {"frames", required_argument, NULL, 'F'},
                                          {"png", required_argument, NULL, 'p'},
                                          {"at", required_argument, NULL, 'a'},
                                          {"strip", required_argument, NULL, 's'},
                                          {"count", required_argument, NULL, 'n'},
                                          {"size", required_argument, NULL, 'S'},
                                          {"fps", required_argument, NULL, 'f'},
                                          {"cycles", required_argument, NULL, 'c'},
                                          {"camera", required_argument, NULL, 'C'},
                                          {"quality", required_argument, NULL, 'q'},
                                          {"model", required_argument, NULL, 'm'},
                                          {"pose", required_argument, NULL, 'P'},
                                          {"no-overlay", no_argument, NULL, 'O'},
                                          {"help", no_argument, NULL, 'h'},
                                          {NULL, 0, NULL, 0}};
  const char *out = NULL, *frames = NULL, *png = NULL, *strip = NULL, *model_path = NULL,
             *pose = NULL;
  double at = 0;
  int count = 8, fps = 60, cycles = 1, have_size = 0, bad = 0;
  grOptions ro;
  gr_options_default(&ro);
  static const char* const cameras[] = {"side", "front", "follow", NULL};
  static const char* const qualities[] = {"fast", "high", NULL};
  optind = 1;
  opterr = 0;
  int c, k = 0;
  while (!bad && (c = getopt_long(argc, argv, ":h", options, NULL)) != -1) {
    switch (c) {
      case 'o': out = optarg; break;
      case 'F': frames = optarg; break;
      case 'p': png = optarg; break;
      case 's': strip = optarg; break;
      case 'm': model_path = optarg; break;
      case 'P': pose = optarg; break;
      case 'O': ro.overlay = 0; break;
      case 'a': bad = gs_opt_real("--at", optarg, 0, 1, 0, &at); break;
      case 'n': bad = gs_opt_int("--count", optarg, 1, 100, &count); break;
      case 'f': bad = gs_opt_int("--fps", optarg, 1, 240, &fps); break;
      case 'c': bad = gs_opt_int("--cycles", optarg, 1, 100, &cycles); break;
      case 'S':
        bad = parse_size(optarg, &ro.width, &ro.height) != 0;
        have_size = 1;
        break;
      case 'C':
        bad = gs_opt_choice("--camera", optarg, cameras, &k);
        ro.camera = k == 2 ? GR_CAMERA_FOLLOW : k == 1 ? GR_CAMERA_FRONT : GR_CAMERA_SIDE;
        break;
      case 'q':
        bad = gs_opt_choice("--quality", optarg, qualities, &k);
        ro.high_quality = !bad && k == 1;
        break;
      case 'h': fputs(kRenderUsage, stdout); return GS_EXIT_OK;
      default: return gs_opt_getopt_error("render", c, argv);
    }
  }
  if (bad) return GS_EXIT_USAGE;
  if (gs_opt_one_operand("render", "SOLUTION_DIR or MODEL.xml", argc, argv) != 0)
    return GS_EXIT_USAGE;
  int nmodes = (out || frames) + (png != NULL) + (strip != NULL);
  if (nmodes != 1)
    return gs_opt_usage_error("render", "give exactly one of --out/--frames, --png, --strip");
  const char* input = argv[optind];
  int bare_model = is_model_path(input);
  if (bare_model ? (pose == NULL || model_path != NULL) : pose != NULL) {
    fprintf(stderr, "gaitsim: render: %s\n",
            bare_model ? "a model needs --pose FILE (and no --model)"
                       : "--pose goes with a MODEL.xml, not a solution folder");
    return GS_EXIT_USAGE;
  }
  if (strip && !have_size) {
    ro.width = 320;
    ro.height = 480;
  }
  if ((out || frames) && ((ro.width % 2) || (ro.height % 2))) {
    fprintf(stderr, "gaitsim: render: video size %dx%d must be even (H.264, yuv420p)\n",
            ro.width, ro.height);
    return GS_EXIT_USAGE;
  }

  // ffmpeg, or PNG frames instead
  char ffmpeg[4096], fallback[4096];
  if (out && gr_find_program("ffmpeg", ffmpeg, sizeof(ffmpeg)) != 0) {
    if (!frames) {
      size_t n = strlen(out);
      int cut = n > 4 && strcmp(out + n - 4, ".mp4") == 0 ? (int)(n - 4) : (int)n;
      snprintf(fallback, sizeof(fallback), "%.*s_frames", cut, out);
      frames = fallback;
    }
    fprintf(stderr,
            "gaitsim: render: ffmpeg not found on PATH, so no %s: writing PNG frames to %s/ "
            "instead (install ffmpeg for mp4: scripts/setup.sh)\n",
            out, frames);
    out = NULL;
  }

  // model and motion: everything is read and checked before any output is opened
  // a solution folder is drawn with the model it was solved with (its summary.json)
  char solved_with[4096];
  const char* mpath = bare_model ? input
                                  : gs_app_model_for_solution(input, model_path, solved_with,
                                                              (int)sizeof(solved_with));
  char err[1024], states[4200];
  if (!bare_model && gs_app_check_solution(input, 0) != 0) return GS_EXIT_FAILURE;
  mjModel* m = gs_model_load(mpath, err, sizeof(err));
  if (!m) {
    fprintf(stderr, "gaitsim: %s: %s\n", mpath, err);
    return GS_EXIT_FAILURE;
  }
  // the motion names every coordinate of the model (a planar solution is not drawn on a 3D one)
  snprintf(states, sizeof(states), "%s/states.sto", input);
  if (gs_app_check_pose_file(m, bare_model ? pose : states) != 0) {
    mj_deleteModel(m);
    return GS_EXIT_FAILURE;
  }
  grMotion mo;
  int rc = bare_model ? gr_motion_load_pose(m, pose, &mo, err, sizeof(err))
                      : gr_motion_load_solution(m, input, &mo, err, sizeof(err));
  if (rc != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    mj_deleteModel(m);
    return GS_EXIT_FAILURE;
  }
  int status = GS_EXIT_FAILURE;
  grRenderer r;
  // every output is written whole: into a temporary folder beside it, then put in place (the
  // frames' folder replaces DIR; a file is renamed out of it), so that a failure or a stop signal
  // leaves nothing partial and no stale frame of an earlier render stays in DIR
  gsFolderTx tx_file = {NULL, NULL, NULL}, tx_frames = {NULL, NULL, NULL};
  const char* file = png ? png : strip ? strip : out;
  char staged_file[8300], staged_frames[4200];
  if (frames && gs_folder_replaceable(frames, "frame_00000.png", err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    mj_deleteModel(m);
    gr_motion_free(&mo);
    return GS_EXIT_FAILURE;
  }
  gs_folder_abort_on_signals("gaitsim: render: stopped by a signal; nothing written");
  if (gr_renderer_create(m, &ro, &r, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: render: %s\n", err);
    goto done;
  }
  if (file) {
    if (gs_folder_begin(&tx_file, file, err, sizeof(err)) != 0) goto fail;
    const char* base = strrchr(tx_file.path, '/') ? strrchr(tx_file.path, '/') + 1 : tx_file.path;
    snprintf(staged_file, sizeof(staged_file), "%s/%s", tx_file.staging, base);
  }
  if (frames) {
    if (gs_folder_begin(&tx_frames, frames, err, sizeof(err)) != 0) goto fail;
    snprintf(staged_frames, sizeof(staged_frames), "%s", tx_frames.staging);
  }
  double t_start = now_s();
  if (png) {
    if (gr_render_png(&r, &mo, at, staged_file, err, sizeof(err)) != 0) goto fail;
    if (gs_folder_commit_file(&tx_file, err, sizeof(err)) != 0) goto fail;
    printf("render: wrote %s (%dx%d, %.0f %% of the cycle)\n", png, ro.width, ro.height,
           100 * at);
  } else if (strip) {
    if (gr_render_strip(&r, &mo, count, staged_file, err, sizeof(err)) != 0) goto fail;
    if (gs_folder_commit_file(&tx_file, err, sizeof(err)) != 0) goto fail;
    printf("render: wrote %s (%d frames of %dx%d)\n", strip, count, ro.width, ro.height);
  } else {
    grVideoJob job = {fps, cycles, out ? staged_file : NULL, out ? ffmpeg : NULL,
                      frames ? staged_frames : NULL};
    long n = 0;
    if (gr_render_video(&r, &mo, &job, &n, err, sizeof(err)) != 0) goto fail;
    if (out && gs_folder_commit_file(&tx_file, err, sizeof(err)) != 0) goto fail;
    if (frames && gs_folder_commit(&tx_frames, err, sizeof(err)) != 0) goto fail;
    double wall = now_s() - t_start;
    printf("render: wrote %s%s%s: %ld frames, %dx%d, %d fps, %d cycle%s of %.3f s\n",
           out ? out : "", out && frames ? " and " : "", frames ? frames : "", n, ro.width,
           ro.height, fps, cycles, cycles == 1 ? "" : "s", gr_motion_stride_time(&mo));
    printf("render: %.2f s, %.1f frames/s\n", wall, wall > 0 ? (double)n / wall : 0.0);
  }
  status = GS_EXIT_OK;
  goto done;
fail:
  fprintf(stderr, "gaitsim: %s\n", err);
done:
  gs_folder_abort(&tx_file);  // nothing when committed
  gs_folder_abort(&tx_frames);
  gr_renderer_free(&r);
  gr_motion_free(&mo);
  mj_deleteModel(m);
  return status;
}
