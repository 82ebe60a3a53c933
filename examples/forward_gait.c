// forward_gait.c: a MuJoCo program using gaitsim's physics from the installed library.
//
// Loads a gaitsim model, switches it to gaitsim's muscles and foot contact, starts from its
// "standing" keyframe with every muscle excited and activated at E, and steps it for T seconds,
// printing one line per 10 ms: time (s), pelvis height (pelvis_ty, m) and the vertical ground
// reaction on each foot (N). The same run as `gaitsim simulate MODEL --excitation E
// --duration T`.
//
// Build against the installed library (see examples/README.md):
//   cc -std=c11 forward_gait.c $(pkg-config --cflags --libs gaitsim) -o forward_gait
//   ./forward_gait mjmodels/gait2d.xml 0.1 0.05
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <gaitsim/gaitsim.h>
#include <mujoco/mujoco.h>

int main(int argc, char** argv) {
  if (argc < 2 || argc > 4) {
    fprintf(stderr, "usage: forward_gait MODEL.xml [SECONDS=0.1] [EXCITATION=0.05]\n");
    return 2;
  }
  double duration = argc > 2 ? atof(argv[2]) : 0.1;     // simulated time (s)
  double excitation = argc > 3 ? atof(argv[3]) : 0.05;  // every muscle's excitation (-)

  // load, then switch to gaitsim's physics before mj_makeData; install the callbacks once
  char err[1000];
  mjModel* m = mj_loadXML(argv[1], NULL, err, sizeof(err));
  if (!m) {
    fprintf(stderr, "forward_gait: %s: %s\n", argv[1], err);
    return 1;
  }
  if (gs_lib_prepare(m, err, sizeof(err)) != 0) {
    fprintf(stderr, "forward_gait: %s: %s\n", argv[1], err);
    mj_deleteModel(m);
    return 1;
  }
  gs_lib_install();
  mjData* d = mj_makeData(m);

  // standing keyframe, excitations and activations at E, elastic tendons at rest
  int key = mj_name2id(m, mjOBJ_KEY, "standing");
  if (key >= 0) {
    mj_resetDataKeyframe(m, d, key);
  }
  for (int i = 0; i < m->nu; i++) d->ctrl[i] = excitation;
  for (int i = 0; i < m->na; i++) d->act[i] = excitation;
  gs_lib_equilibrate(m, d);

  // step, one line every 10 ms
  int pelvis = mj_name2id(m, mjOBJ_JOINT, "pelvis_ty");
  int steps = (int)lround(duration / m->opt.timestep);
  int every = (int)lround(0.01 / m->opt.timestep);
  every = every < 1 ? 1 : every;
  printf("gaitsim %s, MuJoCo %s: %d muscles, %d steps of %g s\n", gs_lib_version(),
         mj_versionString(), m->nu, steps, m->opt.timestep);
  printf("time_s pelvis_ty_m grf_r_z_N grf_l_z_N\n");
  int status = 0;
  for (int s = 0; s <= steps; s++) {
    if (s % every == 0) {
      mj_forward(m, d);
      double fr[3], fl[3], cop[3];
      gs_lib_foot_force(m, d, 'r', fr, cop);
      gs_lib_foot_force(m, d, 'l', fl, cop);
      printf("%.6f %.17g %.17g %.17g\n", d->time,
             pelvis >= 0 ? d->qpos[m->jnt_qposadr[pelvis]] : NAN, fr[2], fl[2]);
    }
    if (s < steps && gs_lib_step(m, d) != 0) {
      fprintf(stderr, "forward_gait: the state became non-finite at t = %g s\n", d->time);
      status = 1;
      break;
    }
  }
  mj_deleteData(d);
  mj_deleteModel(m);
  return status;
}
