// cmd_work.c: `gaitsim work MODEL --pose FILE`: the mechanical work over the rows of a gait's
// states (callbacks/gs_work.h): each source's positive, negative and net work by the trapezoidal
// rule over the rows, and the energy balance that checks it; with --joints the muscles' work at
// each coordinate; with --grf the net joint work of inverse dynamics instead (gs_balance.h).
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "app/gs_app_model.h"
#include "app/gs_commands.h"
#include "app/gs_options.h"
#include "callbacks/gs_balance.h"
#include "callbacks/gs_coupling.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_physics.h"
#include "callbacks/gs_state.h"
#include "callbacks/gs_work.h"

#define WORK_STANCE_N 20.0  // a foot is in stance above this vertical force (N)

static const char* kWorkUsage =
    "usage: gaitsim work MODEL --pose FILE [--joints]\n"
    "       gaitsim work MODEL --pose FILE --grf GRF.mot\n\n"
    "The mechanical work of a gait over the rows of FILE (a solution's or a simulation's\n"
    "states.sto: coordinates, speeds, activations and tendon forces; a solution's rows span one\n"
    "stride), by the trapezoidal rule: for each source, the positive, negative and net work (J)\n"
    "and its net mean power per kg of body mass (W/kg). Sources: the muscle-tendon units and\n"
    "their contractile elements (active fibre force; the work Umberger 2010 prices), passive\n"
    "fibre force, tendons, the foot contact spheres (net negative: the energy the contact\n"
    "dissipates; its negative work is the stand-in for the soft tissues' collision work) with\n"
    "their normal forces (elastic and Hunt-Crossley damping) and their friction, the\n"
    "implant knee's contact and ligaments, joint-limit moments, couplings, MuJoCo's passive and\n"
    "constraint forces (callbacks/gs_work.h). The last lines check the budget: the sum of the\n"
    "net works against the change of kinetic plus potential energy from the first row to the\n"
    "last (equal up to the rows' time discretisation), and the distance the centre of mass\n"
    "travelled.\n\n"
    "  --joints     also the muscles' work at each coordinate (their net moment about it times\n"
    "               its speed: the joint work of inverse dynamics less the passive\n"
    "               structures'), positive and negative over all rows and over the rows where\n"
    "               the foot below the coordinate is in stance (its vertical ground force\n"
    "               above 20 N)\n"
    "  --grf GRF.mot  instead, the net joint work of inverse dynamics under these ground\n"
    "               reactions (OpenSim ExternalLoads columns), the same table: each coordinate's\n"
    "               net generalised force (M qdd + c less the ground reactions' J^T [F; T],\n"
    "               gaitsim balance's) times its speed, stance from GRF.mot. FILE needs only the\n"
    "               coordinates (a trial's coordinates.mot: speeds and accelerations by central\n"
    "               differences of its rows), so a measured gait's joint work can be set beside\n"
    "               a solution's\n";

// the file must carry every speed and every muscle state: the work needs the velocities and
// the muscle forces, which an absent column would silently zero
static int require_states(const mjModel* m, const gsStateMap* map, const char* path) {
  for (int j = 0; j < m->njnt; j++) {
    int dof = m->jnt_dofadr[j];
    if (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE) continue;
    if (map->qvel_col[dof] >= 0 || gs_coupling_joint_follows(m, j)) continue;
    fprintf(stderr, "gaitsim: %s: no speed column %s_u (the work needs every speed)\n", path,
            mj_id2name(m, mjOBJ_JOINT, j));
    return -1;
  }
  for (int i = 0; i < m->nu; i++) {
    if (!gs_actuator_is_gaitsim_muscle(m, i)) continue;
    const char* name = mj_id2name(m, mjOBJ_ACTUATOR, i);
    int act = i - (m->nu - m->na);  // MuJoCo 2.2: the stateful actuators come last
    if (act >= 0 && map->act_col[act] < 0) {
      fprintf(stderr, "gaitsim: %s: no column %s.activation (the work needs every muscle's "
              "state)\n", path, name);
      return -1;
    }
    if (gs_actuator_has_elastic_tendon(m, i) && map->fT_col[i] < 0) {
      fprintf(stderr, "gaitsim: %s: no column %s.normalized_tendon_force (the work needs "
              "every muscle's state)\n", path, name);
      return -1;
    }
  }
  return 0;
}

enum { kMtu, kCe, kFibre, kTendon, kFoot, kFootNormal, kFriction, kKnee, kLimits, kCouplings,
       kMujoco, kOther, kConstraint, kApplied, kSources };

static const char* const kSourceName[kSources] = {
    "muscle-tendon units", "  their contractile elements (active fibre force)",
    "  their passive fibre force and damping", "  their tendons", "foot contact spheres",
    "  their normal forces (elastic and Hunt-Crossley damping)", "  their friction",
    "implant knee: contact and ligaments", "joint-limit moments", "coordinate couplings",
    "MuJoCo passive forces (joint damping, springs)", "other actuators",
    "MuJoCo constraint forces", "applied forces"};

// positive and negative power of each source at one row (W)
static void row_powers(const gsPowers* p, double pos[kSources], double neg[kSources]) {
  double net[kSources] = {0};
  memset(pos, 0, sizeof(double) * kSources);
  memset(neg, 0, sizeof(double) * kSources);
  pos[kMtu] = p->mtu_pos, neg[kMtu] = p->mtu_neg;
  pos[kCe] = p->ce_pos, neg[kCe] = p->ce_neg;
  pos[kFoot] = p->foot_pos, neg[kFoot] = p->foot_neg;
  pos[kFootNormal] = p->foot_normal_pos, neg[kFootNormal] = p->foot_normal_neg;
  net[kFriction] = p->foot_friction;
  net[kFibre] = p->fibre_passive, net[kTendon] = p->tendon, net[kKnee] = p->knee;
  net[kLimits] = p->joint_limits, net[kCouplings] = p->couplings;
  net[kMujoco] = p->mujoco_passive, net[kOther] = p->other_actuators;
  net[kConstraint] = p->constraint, net[kApplied] = p->applied;
  for (int k = 0; k < kSources; k++) {
    if (net[k] > 0) pos[k] += net[k];
    else neg[k] += net[k];
  }
}

// per coordinate: its work over all rows and over its foot's stance (J), by the trapezoidal rule,
// each end of an interval counted positive or negative by its own sign
typedef struct dofWork_ {
  int nv;
  double *pos, *neg, *stance_pos, *stance_neg, *prev;
  int stance_prev[2];
  double time_prev;
  int rows;
} dofWork;

static int dof_work_init(dofWork* w, int nv) {
  memset(w, 0, sizeof(*w));
  w->nv = nv;
  w->pos = (double*)calloc((size_t)(5 * nv), sizeof(double));
  if (!w->pos) return -1;
  w->neg = w->pos + nv, w->stance_pos = w->pos + 2 * nv, w->stance_neg = w->pos + 3 * nv;
  w->prev = w->pos + 4 * nv;
  return 0;
}

static void dof_work_add(dofWork* w, const mjModel* m, double time, const double* power,
                         const int stance[2]) {
  for (int k = 0; w->rows > 0 && k < w->nv; k++) {
    double h = 0.5 * (time - w->time_prev);
    int side = gs_work_dof_side(m, k), f = side == 'r' ? 0 : side == 'l' ? 1 : -1;
    const double ends[2] = {w->prev[k], power[k]};
    const int on[2] = {f >= 0 && w->stance_prev[f], f >= 0 && stance[f]};
    for (int e = 0; e < 2; e++) {
      double* all = ends[e] < 0 ? w->neg : w->pos;
      double* in_stance = ends[e] < 0 ? w->stance_neg : w->stance_pos;
      all[k] += h * ends[e];
      if (on[e]) in_stance[k] += h * ends[e];
    }
  }
  memcpy(w->prev, power, sizeof(double) * (size_t)w->nv);
  w->stance_prev[0] = stance[0], w->stance_prev[1] = stance[1];
  w->time_prev = time;
  w->rows++;
}

static void dof_work_print(const dofWork* w, const mjModel* m, const char* what) {
  printf("\n%s at each coordinate (J; stance: its foot's vertical force above %.0f N)\n", what,
         WORK_STANCE_N);
  printf("| coordinate | positive | negative | in stance: positive | negative |\n");
  printf("|---|---|---|---|---|\n");
  for (int k = 0; k < w->nv; k++) {
    if (w->pos[k] < 0.005 && w->neg[k] > -0.005) continue;  // below the printed 0.01 J
    const char* name = mj_id2name(m, mjOBJ_JOINT, m->dof_jntid[k]);
    printf("| %s | %.2f | %.2f | %.2f | %.2f |\n", name ? name : "(unnamed)", w->pos[k],
           w->neg[k], w->stance_pos[k], w->stance_neg[k]);
  }
}

// the sources' work and, with joints, the muscles' work per coordinate, over a states file
static int work_of_states(const mjModel* m, mjData* d, const char* path, const char* pose,
                          const gsTable* t, const gsStateMap* map, int joints) {
  if (require_states(m, map, pose) != 0) return -1;
  if (t->nrow < 2) {
    fprintf(stderr, "gaitsim: %s: %d row; the work needs at least 2\n", pose, t->nrow);
    return -1;
  }
  double pos[kSources] = {0}, neg[kSources] = {0};
  double prev_pos[kSources] = {0}, prev_neg[kSources] = {0};
  double e_first = 0, e_last = 0, x_first = 0, x_last = 0;
  int n = t->nrow;
  dofWork w;
  double* power = (double*)calloc((size_t)m->nv, sizeof(double));
  if (!power || dof_work_init(&w, m->nv) != 0) {
    fprintf(stderr, "gaitsim: work: out of memory\n");
    free(power);
    return -1;
  }
  for (int i = 0; i < n; i++) {
    mj_resetData(m, d);
    gs_state_apply(m, t, map, t->time[i], d);
    mj_forward(m, d);
    gsPowers p;
    gs_work_powers(m, d, &p);
    double rp[kSources], rn[kSources];
    row_powers(&p, rp, rn);
    if (i > 0) {
      double h = t->time[i] - t->time[i - 1];
      for (int k = 0; k < kSources; k++) {
        pos[k] += 0.5 * h * (rp[k] + prev_pos[k]);
        neg[k] += 0.5 * h * (rn[k] + prev_neg[k]);
      }
    }
    memcpy(prev_pos, rp, sizeof(rp));
    memcpy(prev_neg, rn, sizeof(rn));
    gs_work_dof_muscle_powers(m, d, power);
    int stance[2];
    for (int f = 0; f < 2; f++) {
      gsFootGrf grf;
      gs_physics_foot_grf(m, d, f == 0 ? 'r' : 'l', WORK_STANCE_N, &grf);
      stance[f] = grf.loaded;
    }
    dof_work_add(&w, m, t->time[i], power, stance);
    double e = p.kinetic + p.potential;
    if (i == 0) e_first = e, x_first = d->subtree_com[0];
    e_last = e, x_last = d->subtree_com[0];
  }
  double mass = m->body_subtreemass[0], span = t->time[n - 1] - t->time[0];
  printf("mechanical work of %s over %s (%d rows, %.4f-%.4f s, %.4f s; body mass %.2f kg)\n",
         path, pose, n, t->time[0], t->time[n - 1], span, mass);
  printf("| source | positive (J) | negative (J) | net (J) | net mean power (W/kg) |\n");
  printf("|---|---|---|---|---|\n");
  double sum = 0;
  for (int k = 0; k < kSources; k++) {
    double net = pos[k] + neg[k];
    printf("| %s | %.2f | %.2f | %.2f | %.4f |\n", kSourceName[k], pos[k], neg[k], net,
           span > 0 ? net / span / mass : 0.0);
    if (kSourceName[k][0] != ' ') sum += net;  // the indented parts are in the row above
  }
  printf("sum of the net works: %.2f J; change of kinetic plus potential energy: %.2f J "
         "(difference %.2f J)\n", sum, e_last - e_first, sum - (e_last - e_first));
  printf("centre of mass travelled %.4f m forward (x)\n", x_last - x_first);
  if (joints) dof_work_print(&w, m, "the muscles' work");
  free(w.pos);
  free(power);
  return 0;
}

// the net joint work of inverse dynamics under measured or solved ground reactions
static int work_by_inverse_dynamics(const mjModel* m, mjData* d, const char* path,
                                    const char* pose, const gsTable* t, const gsStateMap* map,
                                    const char* grf) {
  gsBalanceSpec spec;
  gsTable g;
  char err[512];
  int col[GS_GRF_NCOL], nq = m->nq, nv = m->nv, n = t->nrow, status = -1;
  gs_table_init(&g);
  double *q = NULL, *v = NULL, *a = NULL, *tau = NULL;
  dofWork w = {0};
  if (gs_balance_spec(m, &spec, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", path, err);
    goto done;
  }
  if (n < 3) {
    fprintf(stderr, "gaitsim: %s: %d rows; the differences need at least 3\n", pose, n);
    goto done;
  }
  if (gs_app_read_table(m, grf, &g) != 0) goto done;
  if (gs_balance_grf_columns(&g, col, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", grf, err);
    goto done;
  }
  q = (double*)malloc(sizeof(double) * (size_t)(n * nq));
  v = (double*)malloc(sizeof(double) * (size_t)(n * nv));
  a = (double*)malloc(sizeof(double) * (size_t)(n * nv));
  tau = (double*)malloc(sizeof(double) * (size_t)nv);
  if (!q || !v || !a || !tau || dof_work_init(&w, nv) != 0) {
    fprintf(stderr, "gaitsim: work: out of memory\n");
    goto done;
  }
  int speeds = gs_app_pose_kinematics(m, d, t, map, q, v, a);
  for (int i = 0; i < n; i++) {
    mj_resetData(m, d);
    mju_copy(d->qpos, q + i * nq, nq);
    mju_copy(d->qvel, v + i * nv, nv);
    gsFootLoad load[2];
    gs_balance_loads_at(&g, col, t->time[i], WORK_STANCE_N, load);
    gsBalance b;
    gs_balance_eval_tau(m, d, &spec, a + i * nv, load, &b, tau);
    for (int k = 0; k < nv; k++) tau[k] *= v[i * nv + k];  // the joint power (W)
    const int stance[2] = {load[0].loaded, load[1].loaded};
    dof_work_add(&w, m, t->time[i], tau, stance);
  }
  printf("net joint work by inverse dynamics of %s over %s with %s (%d rows, %.4f-%.4f s; "
         "speeds %s)\n", path, pose, grf, n, t->time[0], t->time[n - 1],
         speeds ? "from the file" : "by central differences");
  dof_work_print(&w, m, "the net joint work of inverse dynamics");
  status = 0;
done:
  free(q);
  free(v);
  free(a);
  free(tau);
  free(w.pos);
  gs_table_free(&g);
  return status;
}

int gs_cmd_work(int argc, char** argv) {
  static const struct option options[] = {{"pose", required_argument, NULL, 'p'},
                                          {"joints", no_argument, NULL, 'j'},
                                          {"grf", required_argument, NULL, 'g'},
                                          {"help", no_argument, NULL, 'h'},
                                          {NULL, 0, NULL, 0}};
  const char *pose = NULL, *grf = NULL;
  int joints = 0;
  optind = 1;
  opterr = 0;
  int c;
  while ((c = getopt_long(argc, argv, ":p:jg:h", options, NULL)) != -1) {
    switch (c) {
      case 'p': pose = optarg; break;
      case 'j': joints = 1; break;
      case 'g': grf = optarg; break;
      case 'h': fputs(kWorkUsage, stdout); return GS_EXIT_OK;
      default: return gs_opt_getopt_error("work", c, argv);
    }
  }
  if (gs_opt_one_operand("work", "MODEL", argc, argv) != 0) return GS_EXIT_USAGE;
  if (!pose) return gs_opt_usage_error("work", "missing --pose FILE");
  if (grf && joints) return gs_opt_usage_error("work", "--grf prints the joints' table already");
  const char* path = argv[optind];
  mjModel* m = gs_app_load_model(path);
  if (!m) return GS_EXIT_FAILURE;
  int status = GS_EXIT_FAILURE;
  mjData* d = mj_makeData(m);
  gsTable t;
  gs_table_init(&t);
  gsStateMap map = {0};
  char err[512];
  if (gs_app_read_table(m, pose, &t) != 0 || gs_app_require_coordinates(m, &t, pose) != 0)
    goto done;
  if (gs_state_map(m, &t, &map, err, sizeof(err)) != 0) {
    fprintf(stderr, "gaitsim: %s: %s\n", pose, err);
    goto done;
  }
  if ((grf ? work_by_inverse_dynamics(m, d, path, pose, &t, &map, grf)
           : work_of_states(m, d, path, pose, &t, &map, joints)) == 0)
    status = GS_EXIT_OK;
done:
  gs_state_map_free(&map);
  gs_table_free(&t);
  mj_deleteData(d);
  mj_deleteModel(m);
  return status;
}
