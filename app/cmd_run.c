// cmd_run.c: `gaitsim run`: the default job on the bundled model and trial. It grows with the
// project (tracking -> prediction -> report -> video); today it summarises the model and runs a
// short forward check in stock MuJoCo: 0.5 s from the standing keyframe with zero controls must
// stay finite; it reports how far the whole-body centre of mass fell.
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "app/gs_commands.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_mujoco.h"

static const char* kRunUsage =
    "usage: gaitsim run [--model FILE]\n\n"
    "Run the default job on the bundled model (default: mjmodels/jw_fullbody.xml in the source\n"
    "tree): model summary and a 0.5 s forward check from the standing keyframe.\n";

int gs_cmd_run(int argc, char** argv) {
  static const struct option options[] = {
      {"model", required_argument, NULL, 'm'}, {"help", no_argument, NULL, 'h'}, {NULL, 0, NULL, 0}};
  const char* path = GAITSIM_SOURCE_DIR "/mjmodels/jw_fullbody.xml";
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, "m:h", options, NULL)) != -1) {
    switch (c) {
      case 'm':
        path = optarg;
        break;
      case 'h':
        fputs(kRunUsage, stdout);
        return GS_EXIT_OK;
      default:
        fputs(kRunUsage, stderr);
        return GS_EXIT_USAGE;
    }
  }
  if (optind != argc) {
    fputs(kRunUsage, stderr);
    return GS_EXIT_USAGE;
  }

  char err[1024];
  mjModel* m = gs_model_load(path, err, sizeof(err));
  if (!m) {
    fprintf(stderr, "gaitsim: %s: %s\n", path, err);
    return GS_EXIT_FAILURE;
  }
  gsModelInfo info;
  gs_model_info(m, &info);
  printf("[1/2] model %s: %d dof, %d muscles (%d rigid tendon), %d+%d contact spheres, %.2f kg\n",
         path, info.ndof, info.nmuscle, info.nmuscle_rigid, info.ncontact_r, info.ncontact_l,
         info.mass);

  // forward check: from the standing keyframe, zero excitation, 0.5 s
  mjData* d = mj_makeData(m);
  int key = mj_name2id(m, mjOBJ_KEY, "standing");
  if (key >= 0) {
    mj_resetDataKeyframe(m, d, key);
  }
  mj_forward(m, d);
  double z0 = d->subtree_com[2];  // body 0's subtree: the whole model's centre of mass
  int steps = (int)lround(0.5 / m->opt.timestep);
  int finite = 1;
  for (int s = 0; s < steps && finite; s++) {
    mj_step(m, d);
    for (int i = 0; i < m->nv; i++) {
      finite = finite && isfinite(d->qacc[i]);
    }
  }
  mj_forward(m, d);
  double z1 = d->subtree_com[2];
  printf("[2/2] forward check: %d steps of %.4f s, centre of mass height %.3f -> %.3f m, %d contacts, %s\n",
         steps, m->opt.timestep, z0, z1, d->ncon, finite ? "finite" : "NOT FINITE");
  mj_deleteData(d);
  mj_deleteModel(m);
  return finite ? GS_EXIT_OK : GS_EXIT_FAILURE;
}
