// cmd_export.c: `gaitsim export SOLUTION_DIR --out F.xml [--model M]`: a solved gait as MuJoCo
// keyframes (render/gr_keyframes.h).
#include <getopt.h>
#include <stdio.h>

#include <mujoco/mujoco.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "callbacks/gs_mujoco.h"
#include "render/gr_keyframes.h"

static const char* kExportUsage =
    "usage: gaitsim export SOLUTION_DIR --out F.xml [--model MODEL]\n\n"
    "Write an MJCF that includes MODEL and holds one keyframe per row of SOLUTION_DIR/states.sto\n"
    "(keys gait_000, gait_001, ... after the model's own keys: time, qpos, qvel, act), for stock\n"
    "MuJoCo and its viewer:\n"
    "  mujoco-simulate F.xml      (Simulation > Key: pick a frame, Load key)\n"
    "The include path is relative to F's folder (MuJoCo 2.2.2 resolves includes from there), so\n"
    "keep F and the model where they are. qvel and act are 0 where states.sto has no speed or\n"
    "activation column. Stock MuJoCo's muscles and contacts are not gaitsim's (mjmodels/README.md):\n"
    "the keys show the solved poses; simulating from them is MuJoCo's physics, not the solve's.\n\n"
    "  --out F.xml     exported file (written atomically, checked to load in stock MuJoCo)\n"
    "  --model MODEL   model to include (default: the model SOLUTION_DIR/summary.json names, else\n"
    "                  the bundled model); its joints must match states.sto's coordinates\n";

int gs_cmd_export(int argc, char** argv) {
  static const struct option options[] = {{"out", required_argument, NULL, 'o'},
                                          {"model", required_argument, NULL, 'm'},
                                          {"help", no_argument, NULL, 'h'},
                                          {NULL, 0, NULL, 0}};
  const char *out = NULL, *model_path = NULL;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, "h", options, NULL)) != -1) {
    switch (c) {
      case 'o': out = optarg; break;
      case 'm': model_path = optarg; break;
      case 'h': fputs(kExportUsage, stdout); return GS_EXIT_OK;
      default: fputs(kExportUsage, stderr); return GS_EXIT_USAGE;
    }
  }
  if (optind != argc - 1 || !out) {
    fputs(kExportUsage, stderr);
    return GS_EXIT_USAGE;
  }
  const char* dir = argv[optind];

  // the model the solution was solved with, unless told otherwise
  char solved_with[4096];
  const char* mpath =
      gs_app_model_for_solution(dir, model_path, solved_with, (int)sizeof(solved_with));
  char err[1024];
  mjModel* m = gs_model_load(mpath, err, sizeof(err));
  if (!m) {
    fprintf(stderr, "gaitsim: %s: %s\n", mpath, err);
    return GS_EXIT_FAILURE;
  }
  char states[4096];
  snprintf(states, sizeof(states), "%s/states.sto", dir);
  grKeyframesInfo info;
  int rc = gr_keyframes_export(m, mpath, states, out, &info, err, sizeof(err));
  mj_deleteModel(m);
  if (rc != 0) {
    fprintf(stderr, "gaitsim: export: %s\n", err);
    return GS_EXIT_FAILURE;
  }
  printf("export: wrote %s: %d keyframes (gait_000.., key index %d on), include \"%s\"; "
         "coordinates %d, speeds %d, activations %d from states.sto\n",
         out, info.nkey, info.first_key, info.include, info.nq_found, info.nv_found,
         info.na_found);
  return GS_EXIT_OK;
}
