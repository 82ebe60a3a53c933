// cmd_inspect.c: `gaitsim inspect MODEL --pose FILE --time t`: one row per muscle at one
// instant: muscle-tendon length, fibre length, tendon tension, metabolic rate and moment arms;
// then where the feet are: each contact sphere's bottom height and position, each foot's GRF.
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <mujoco/mujoco.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "app/gs_options.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_muscle.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_state.h"
#include "callbacks/gs_tendon_paths.h"

static const char* kInspectUsage =
    "usage: gaitsim inspect MODEL --pose FILE [--time T] [--activation A]\n\n"
    "One row per muscle at time T (s, default the file's first row) of FILE (a states.sto,\n"
    "or coordinates .mot; missing speeds are 0, missing activations A (default 0.05), missing\n"
    "excitations equal the activation, missing tendon forces in static equilibrium):\n"
    "muscle-tendon length lMT (m), fibre length lM (m) and lM/lopt, tendon tension F (N),\n"
    "metabolic rate (W, Umberger 2010) and the moment arms (m or m/m) above 0.1 mm; then one\n"
    "row per contact sphere: its bottom's height (mm; below 0: pressed into the floor) and\n"
    "world x, y (m), and each foot's ground reaction and centre of pressure.\n";

int gs_cmd_inspect(int argc, char** argv) {
  static const struct option options[] = {{"pose", required_argument, NULL, 'p'},
                                          {"time", required_argument, NULL, 't'},
                                          {"activation", required_argument, NULL, 'a'},
                                          {"help", no_argument, NULL, 'h'},
                                          {NULL, 0, NULL, 0}};
  const char* pose = NULL;
  double time = NAN, activation = 0.05;
  optind = 1;
  opterr = 0;
  int c, bad = 0;
  while (!bad && (c = getopt_long(argc, argv, ":p:t:a:h", options, NULL)) != -1) {
    switch (c) {
      case 'p': pose = optarg; break;
      case 't': bad = gs_opt_real("--time", optarg, -HUGE_VAL, HUGE_VAL, 0, &time); break;
      case 'a': bad = gs_opt_real("--activation", optarg, 0, 1, 0, &activation); break;
      case 'h': fputs(kInspectUsage, stdout); return GS_EXIT_OK;
      default: return gs_opt_getopt_error("inspect", c, argv);
    }
  }
  if (bad) return GS_EXIT_USAGE;
  if (gs_opt_one_operand("inspect", "MODEL", argc, argv) != 0) return GS_EXIT_USAGE;
  if (!pose) return gs_opt_usage_error("inspect", "missing --pose FILE");
  const char* path = argv[optind];
  mjModel* m = gs_app_load_model(path);
  if (!m) {
    return GS_EXIT_FAILURE;
  }
  int status = GS_EXIT_FAILURE;
  mjData* d = mj_makeData(m);
  gsTable t;
  gsStateMap map = {0};
  char err[512];
  if (gs_app_read_table(m, pose, &t) != 0) {
    goto done;
  }
  if (gs_app_require_coordinates(m, &t, pose) != 0) goto done;
  if (gs_state_map(m, &t, &map, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", pose, err);
    goto done;
  }
  if (isnan(time)) {
    time = t.time[0];
  }
  if (time < t.time[0] || time > t.time[t.nrow - 1]) {
    fprintf(stderr, "gaitsim: %s: time %g s outside the file's %g..%g s\n", pose, time,
            t.time[0], t.time[t.nrow - 1]);
    goto done;
  }
  for (int i = 0; i < m->na; i++) d->act[i] = activation;
  for (int i = 0; i < m->nu; i++) d->ctrl[i] = activation;
  gs_state_apply(m, &t, &map, time, d);
  if (map.nctrl_found == 0) {  // excitations default to the activation
    for (int i = m->nu - m->na; i < m->nu; i++) d->ctrl[i] = d->act[i - (m->nu - m->na)];
  }
  gs_forward(m, d);
  gs_physics_equilibrate_tendons(m, d, map.fT_col);  // tendon forces not given
  gs_forward(m, d);
  printf("%s at t = %.4f s of %s\n", path, time, pose);
  printf("%-16s %-7s %9s %8s %7s %9s %9s  %s\n", "muscle", "tendon", "lMT (m)", "lM (m)",
         "lM/lopt", "F (N)", "Edot (W)", "moment arms (m)");
  for (int i = 0; i < m->nu; i++) {
    if (!gs_actuator_is_gaitsim_muscle(m, i)) {
      continue;
    }
    gsMuscleOut out;
    double force = gs_physics_muscle_tension(m, d, i, &out);
    double power = gs_physics_muscle_metabolics(m, d, i, NULL);
    printf("%-16s %-7s %9.6f %8.4f %7.3f %9.1f %9.2f ", mj_id2name(m, mjOBJ_ACTUATOR, i),
           gs_actuator_has_elastic_tendon(m, i) ? "elastic" : "rigid", d->actuator_length[i],
           out.lM, out.lM_norm, force, power);
    for (int j = 0; j < m->njnt; j++) {
      // MuJoCo's actuator_moment is dL/dq; the moment arm is -dL/dq (OpenSim's convention)
      double r = -d->actuator_moment[i * m->nv + m->jnt_dofadr[j]];
      if (fabs(r) > 1e-4) {
        printf(" %s=%.4f", mj_id2name(m, mjOBJ_JOINT, j), r);
      }
    }
    printf("\n");
  }
  // where the feet are: every contact sphere's bottom (centre height - radius; < 0 is the depth
  // pressed into the floor) and position, then each foot's ground reaction
  printf("%-16s %-4s %12s %9s %9s\n", "contact sphere", "foot", "bottom (mm)", "x (m)", "y (m)");
  for (int g = 0; g < m->ngeom; g++) {
    int side = gs_geom_contact_side(m, g);
    if (side == 'r' || side == 'l') {
      const double* p = d->geom_xpos + 3 * g;
      printf("%-16s %-4c %12.1f %9.4f %9.4f\n", mj_id2name(m, mjOBJ_GEOM, g), side,
             1e3 * (p[2] - m->geom_size[3 * g]), p[0], p[1]);
    }
  }
  for (int s = 0; s < 2; s++) {
    gsFootGrf fg;
    gs_physics_foot_grf(m, d, s == 0 ? 'r' : 'l', 5.0, &fg);
    printf("foot %c: ground reaction %.1f %.1f %.1f N (world x y z), centre of pressure %.4f "
           "%.4f m%s\n", s == 0 ? 'r' : 'l', fg.force[0], fg.force[1], fg.force[2], fg.cop[0],
           fg.cop[1], fg.loaded ? "" : " (unloaded)");
  }
  status = GS_EXIT_OK;
done:
  gs_state_map_free(&map);
  gs_table_free(&t);
  mj_deleteData(d);
  mj_deleteModel(m);
  return status;
}
