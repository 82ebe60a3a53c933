// cmd_simulate.c: `gaitsim simulate`: forward simulation with gaitsim's physics (Hill muscles
// with their fibre states, activation dynamics, smooth foot contact), states and ground
// reactions written as OpenSim storage files.
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "app/gs_options.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_state.h"
#include "callbacks/gs_tendon_paths.h"
#include "io/gs_atomic.h"
#include "optim/go_ipopt.h"

static const char* kSimulateUsage =
    "usage: gaitsim simulate MODEL --out DIR [options]\n\n"
    "Forward simulation with gaitsim's physics: Hill muscles (elastic tendons integrated too),\n"
    "activation dynamics, smooth Hunt-Crossley foot contact. Writes DIR/states.sto (OpenSim 3\n"
    "state names), DIR/grf.mot (per foot, OpenSim ExternalLoads names) and\n"
    "DIR/muscle_forces.sto (tendon tension, N).\n\n"
    "  --init FILE         initial state (states.sto or coordinates .mot/.sto, first row);\n"
    "                      default: the model's 'standing' keyframe\n"
    "  --excitations FILE  excitations over time (columns named by muscle); default: hold\n"
    "  --excitation E      constant excitation of every muscle (default 0.05)\n"
    "  --duration T        simulated time, s (default 1)\n"
    "  --drop H            start H metres higher (default 0)\n"
    "  --hold              lock every joint but the pelvis at its initial value (soft joint\n"
    "                      limits at that value) with the actuators off, to test the foot\n"
    "                      contact model alone\n"
    "  --rate HZ           output rows per second (default 100)\n";

typedef struct gsSimulateOptions_ {
  const char* model;        // MJCF path
  const char* out;          // output folder
  const char* init;         // initial state file or NULL
  const char* excitations;  // excitation file or NULL
  double excitation;        // constant excitation when no file                     (-)
  double duration;          // simulated time                                       (s)
  double drop;              // initial lift of the root body                         (m)
  double rate;              // output rate                                          (Hz)
  int hold;                 // 1: lock non-pelvis joints
} gsSimulateOptions;

// at most this many output rows (duration x rate): a table of 10^6 rows of the full-body model's
// states is about 1 GB
#define GS_SIMULATE_MAX_ROWS 1e6

// the options into o; 0, -1 after --help (usage on stdout), else GS_EXIT_USAGE after one line
static int parse(int argc, char** argv, gsSimulateOptions* o) {
  static const struct option options[] = {
      {"out", required_argument, NULL, 'o'},        {"init", required_argument, NULL, 'i'},
      {"excitations", required_argument, NULL, 'x'}, {"excitation", required_argument, NULL, 'e'},
      {"duration", required_argument, NULL, 'd'},    {"drop", required_argument, NULL, 'z'},
      {"rate", required_argument, NULL, 'r'},        {"hold", no_argument, NULL, 'H'},
      {"help", no_argument, NULL, 'h'},              {NULL, 0, NULL, 0}};
  *o = (gsSimulateOptions){NULL, NULL, NULL, NULL, 0.05, 1.0, 0.0, 100.0, 0};
  optind = 1;
  opterr = 0;
  int c, bad = 0;
  while (!bad && (c = getopt_long(argc, argv, ":o:i:x:e:d:z:r:Hh", options, NULL)) != -1) {
    switch (c) {
      case 'o': o->out = optarg; break;
      case 'i': o->init = optarg; break;
      case 'x': o->excitations = optarg; break;
      case 'e': bad = gs_opt_real("--excitation", optarg, 0, 1, 0, &o->excitation); break;
      case 'd':
        bad = gs_opt_real("--duration", optarg, 0, 3600, GS_OPT_LO_OPEN, &o->duration);
        break;
      case 'z': bad = gs_opt_real("--drop", optarg, -10, 10, 0, &o->drop); break;
      case 'r': bad = gs_opt_real("--rate", optarg, 0, 1e5, GS_OPT_LO_OPEN, &o->rate); break;
      case 'H': o->hold = 1; break;
      case 'h': fputs(kSimulateUsage, stdout); return -1;
      default: return gs_opt_getopt_error("simulate", c, argv);
    }
  }
  if (bad) return GS_EXIT_USAGE;
  if (gs_opt_one_operand("simulate", "MODEL", argc, argv) != 0) return GS_EXIT_USAGE;
  if (!o->out) return gs_opt_usage_error("simulate", "missing --out DIR");
  if (o->duration * o->rate > GS_SIMULATE_MAX_ROWS) {
    fprintf(stderr, "gaitsim: --duration, --rate: at most %.0g output rows (got %g s x %g Hz)\n",
            GS_SIMULATE_MAX_ROWS, o->duration, o->rate);
    return GS_EXIT_USAGE;
  }
  o->model = argv[optind];
  return 0;
}

// joints of the root body (the pelvis): those whose body hangs from the world body
static int is_root_joint(const mjModel* m, int j) {
  int b = m->jnt_bodyid[j];
  while (b > 0 && m->body_jntnum[b] == 0) {  // jointless bodies are welded to their parent
    b = m->body_parentid[b];
  }
  int parent = m->body_parentid[b];
  while (parent > 0 && m->body_jntnum[parent] == 0) {
    parent = m->body_parentid[parent];
  }
  return parent == 0;
}

// the root's slide joint most aligned with world z, or -1
static int vertical_root_slide(const mjModel* m, const mjData* d) {
  int best = -1;
  double best_dot = 0.5;
  for (int j = 0; j < m->njnt; j++) {
    if (m->jnt_type[j] == mjJNT_SLIDE && is_root_joint(m, j) && fabs(d->xaxis[3 * j + 2]) > best_dot) {
      best = j;
      best_dot = fabs(d->xaxis[3 * j + 2]);
    }
  }
  return best;
}

// initial state: keyframe or file; activations at the excitation; tendon forces in equilibrium
static int initial_state(const mjModel* m, mjData* d, const gsSimulateOptions* o) {
  int key = mj_name2id(m, mjOBJ_KEY, "standing");
  if (key >= 0) {
    mj_resetDataKeyframe(m, d, key);
  } else {
    mj_resetData(m, d);
  }
  for (int i = 0; i < m->nu; i++) {
    d->ctrl[i] = o->excitation;
  }
  for (int i = 0; i < m->na; i++) {
    d->act[i] = o->excitation;
  }
  gsStateMap map = {0};
  gsTable init;
  gs_table_init(&init);
  if (o->init) {
    char err[512];
    if (gs_app_read_table(m, o->init, &init) != 0) {
      return -1;
    }
    if (gs_state_map(m, &init, &map, err, sizeof(err)) != 0) {
      fprintf(stderr, "gaitsim: %s: %s\n", o->init, err);
      gs_table_free(&init);
      return -1;
    }
    if (gs_app_require_coordinates(m, &init, o->init) != 0) {
      gs_state_map_free(&map);
      gs_table_free(&init);
      return -1;
    }
    gs_state_apply(m, &init, &map, init.time[0], d);
  }
  mj_kinematics(m, d);
  int slide = vertical_root_slide(m, d);
  if (o->drop != 0 && slide < 0) {
    fprintf(stderr, "gaitsim: %s: --drop needs a vertical slide joint on the root body\n", o->model);
    return -1;
  }
  if (slide >= 0) {
    d->qpos[m->jnt_qposadr[slide]] += o->drop * (d->xaxis[3 * slide + 2] > 0 ? 1 : -1);
  }
  gs_fwd_position(m, d);  // tendons finite where a path grazes a wrap geom
  // elastic tendons without a given state: static equilibrium
  gs_physics_equilibrate_tendons(m, d, o->init ? map.fT_col : NULL);
  gs_state_map_free(&map);
  gs_table_free(&init);
  return 0;
}

// lock every non-root joint at its current value with a zero-width soft limit, and switch the
// actuators off: what remains is the body as one rigid block on its contact spheres
static void hold_joints(mjModel* m, const mjData* d) {
  m->opt.disableflags |= mjDSBL_ACTUATION;
  for (int j = 0; j < m->njnt; j++) {
    if (is_root_joint(m, j) || (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE)) {
      continue;
    }
    double q = d->qpos[m->jnt_qposadr[j]];
    m->jnt_limited[j] = 1;
    m->jnt_range[2 * j] = q;
    m->jnt_range[2 * j + 1] = q;
    m->jnt_margin[j] = 0;
  }
}

int gs_cmd_simulate(int argc, char** argv) {
  gsSimulateOptions o;
  int prc = parse(argc, argv, &o);
  if (prc != 0) return prc < 0 ? GS_EXIT_OK : prc;
  char err[1024];
  // an existing --out is replaced only when it holds an earlier result (its states.sto)
  if (gs_folder_replaceable(o.out, "states.sto", err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    return GS_EXIT_FAILURE;
  }
  mjModel* m = gs_app_load_model(o.model);
  if (!m) {
    return GS_EXIT_FAILURE;
  }
  int status = GS_EXIT_FAILURE;
  gsFolderTx tx = {NULL, NULL, NULL};
  mjData* d = mj_makeData(m);
  gsTable excitations, states, grf, forces;
  gs_table_init(&excitations);
  gs_table_init(&states);
  gs_table_init(&grf);
  gs_table_init(&forces);
  gsStateMap xmap = {0};
  mjtNum* fT_dot = (mjtNum*)calloc((size_t)m->nu + 1, sizeof(mjtNum));
  if (initial_state(m, d, &o) != 0) {
    goto done;
  }
  if (o.excitations) {
    if (gs_app_read_table(m, o.excitations, &excitations) != 0) {
      goto done;
    }
    if (gs_state_map(m, &excitations, &xmap, err, sizeof(err)) != 0 || xmap.nctrl_found == 0) {
      fprintf(stderr, "gaitsim: %s: %s\n", o.excitations,
              xmap.ctrl_col ? "no column names a muscle of the model" : err);
      goto done;
    }
  }
  if (o.hold) {
    hold_joints(m, d);
  }
  // written into a temporary folder beside --out that replaces it at the end; a stop signal
  // (SIGINT, SIGTERM, SIGHUP) ends the simulation at the next step and writes the rows so far
  // (exit 3), a second one removes the temporary folder and ends the process at once
  go_ipopt_install_stop_signals(gs_folder_abort_from_signal);
  if (gs_folder_begin(&tx, o.out, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    goto done;
  }

  int steps = (int)lround(o.duration / m->opt.timestep);
  int every = (int)lround(1.0 / (o.rate * m->opt.timestep));
  every = every < 1 ? 1 : every;
  int nrow = steps / every + 1;
  const char** names = (const char**)calloc((size_t)m->nu + 1, sizeof(char*));
  for (int i = 0; i < m->nu; i++) {
    names[i] = mj_id2name(m, mjOBJ_ACTUATOR, i);
  }
  int made = gs_state_table_create(m, nrow, &states, err, sizeof(err)) == 0 &&
             gs_grf_table_create(nrow, &grf, err, sizeof(err)) == 0 &&
             gs_table_create(&forces, nrow, m->nu, names, err, sizeof(err)) == 0;
  free(names);
  if (!made) {
    fprintf(stderr, "gaitsim: simulate: %s\n", err);
    goto done;
  }

  int row = 0, finite = 1, stopped = 0;
  double t0 = d->time;
  for (int s = 0; s <= steps; s++) {
    if (go_ipopt_stop_signals() > 0) {
      stopped = 1;
      fprintf(stderr, "gaitsim: simulate: stopped by a signal at t = %.4f s; writing the %d rows "
              "before it\n", d->time - t0, row);
      break;
    }
    if (o.excitations) {
      gs_state_apply(m, &excitations, &xmap, excitations.time[0] + d->time - t0, d);
    }
    if (s % every == 0 && row < nrow) {
      gs_forward(m, d);  // the recorded row: tendons repaired as in the step
      gs_state_table_set_row(m, d, d->time - t0, &states, row);
      gs_grf_table_set_row(m, d, d->time - t0, &grf, row);
      forces.time[row] = d->time - t0;
      for (int i = 0; i < m->nu; i++) {
        forces.data[row * m->nu + i] = gs_actuator_is_gaitsim_muscle(m, i)
                                           ? gs_physics_muscle_tension(m, d, i, NULL)
                                           : -d->actuator_force[i];
      }
      row++;
    }
    // the step's start time, taken before stepping: MuJoCo's reset on a bad acceleration
    // rewinds d->time
    double t_start = d->time - t0;
    if (s < steps && gs_physics_step(m, d, fT_dot) != 0) {
      finite = 0;
      fprintf(stderr, "gaitsim: simulate: state became non-finite in the step from t = %.4f s; writing the %d rows before it\n",
              t_start, row);
      break;
    }
  }
  states.nrow = grf.nrow = forces.nrow = row;  // rows actually filled
  if (gs_app_write_table(tx.staging, "states.sto", &states) != 0 ||
      gs_app_write_table(tx.staging, "grf.mot", &grf) != 0 ||
      gs_app_write_table(tx.staging, "muscle_forces.sto", &forces) != 0) {
    goto done;
  }
  if (gs_folder_commit(&tx, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s\n", err);
    goto done;
  }
  if (row > 0) {
    const double* last = grf.data + (size_t)(row - 1) * grf.ncol;
    double weight = mj_getTotalmass(m) * fabs(m->opt.gravity[2]);
    printf("simulate: %.3f s in %d steps; final vertical GRF right %.1f N, left %.1f N, total %.3f BW\n",
           d->time - t0, steps, last[1], last[10], (last[1] + last[10]) / weight);
  }
  printf("simulate: wrote %s/states.sto, grf.mot, muscle_forces.sto\n", o.out);
  status = !finite ? GS_EXIT_FAILURE : stopped ? GS_EXIT_STOPPED_SHORT : GS_EXIT_OK;

done:
  gs_folder_abort(&tx);  // nothing when committed
  free(fT_dot);
  gs_state_map_free(&xmap);
  gs_table_free(&excitations);
  gs_table_free(&states);
  gs_table_free(&grf);
  gs_table_free(&forces);
  mj_deleteData(d);
  mj_deleteModel(m);
  return status;
}
