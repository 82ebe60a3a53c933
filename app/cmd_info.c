// cmd_info.c: `gaitsim info MODEL [--json]`: degrees of freedom with names, muscles with their
// tendon type, foot contact spheres and total mass.
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>

#include <cjson/cJSON.h>
#include <mujoco/mujoco.h>

#include "app/gs_commands.h"
#include "app/gs_options.h"
#include "callbacks/gs_model_info.h"
#include "callbacks/gs_model_layout.h"
#include "callbacks/gs_mujoco.h"

static const char* kInfoUsage =
    "usage: gaitsim info MODEL [--json]\n\n"
    "Summarise an MJCF model: degrees of freedom (names, types, ranges), muscle-tendon units\n"
    "(elastic or rigid tendon), foot contact spheres per side, and total mass.\n\n"
    "  --json   print the summary as JSON (keys: model, dof, coordinates, joints, muscles,\n"
    "           muscles_elastic_tendon, muscles_rigid_tendon, muscle_list, contact_spheres,\n"
    "           mass_kg)\n";

// the muscle's Hill parameter, or 0 for a native muscle
static double muscle_param(const mjModel* m, int i, int k) {
  return gs_actuator_is_gaitsim_muscle(m, i) ? m->actuator_user[i * m->nuser_actuator + k] : 0;
}

static void print_text(const char* path, const mjModel* m, const gsModelInfo* info) {
  printf("model        %s\n", path);
  printf("dof          %d\n", info->ndof);
  printf("coordinates\n");
  for (int j = 0; j < m->njnt; j++) {
    const char* unit = m->jnt_type[j] == mjJNT_SLIDE ? "m" : "rad";
    printf("  %3d  %-20s %-6s", m->jnt_dofadr[j], mj_id2name(m, mjOBJ_JOINT, j),
           gs_joint_type_name(m->jnt_type[j]));
    if (m->jnt_limited[j]) {
      printf(" [%8.4f, %8.4f] %s", m->jnt_range[2 * j], m->jnt_range[2 * j + 1], unit);
    }
    printf("\n");
  }
  printf("muscles      %d (%d elastic tendon, %d rigid tendon)\n", info->nmuscle,
         info->nmuscle - info->nmuscle_rigid, info->nmuscle_rigid);
  if (info->nmuscle > 0) {
    printf("  %-16s %-8s %10s %10s %10s\n", "name", "tendon", "Fmax (N)", "lopt (m)", "lts (m)");
  }
  for (int i = 0; i < m->nu; i++) {
    if (!gs_actuator_is_muscle(m, i)) {
      continue;
    }
    printf("  %-16s %-8s %10.1f %10.4f %10.4f\n", mj_id2name(m, mjOBJ_ACTUATOR, i),
           gs_actuator_has_elastic_tendon(m, i) ? "elastic" : "rigid",
           muscle_param(m, i, GS_ACT_FMAX), muscle_param(m, i, GS_ACT_LOPT),
           muscle_param(m, i, GS_ACT_LTS));
  }
  printf("contacts     %d spheres right foot, %d left foot\n", info->ncontact_r, info->ncontact_l);
  printf("mass         %.3f kg\n", info->mass);
}

static int print_json(const char* path, const mjModel* m, const gsModelInfo* info) {
  cJSON* root = cJSON_CreateObject();
  cJSON_AddStringToObject(root, "model", path);
  cJSON_AddNumberToObject(root, "dof", info->ndof);
  cJSON* names = cJSON_AddArrayToObject(root, "coordinates");
  cJSON* joints = cJSON_AddArrayToObject(root, "joints");
  for (int j = 0; j < m->njnt; j++) {
    cJSON_AddItemToArray(names, cJSON_CreateString(mj_id2name(m, mjOBJ_JOINT, j)));
    cJSON* jo = cJSON_CreateObject();
    cJSON_AddStringToObject(jo, "name", mj_id2name(m, mjOBJ_JOINT, j));
    cJSON_AddStringToObject(jo, "type", gs_joint_type_name(m->jnt_type[j]));
    cJSON_AddStringToObject(jo, "unit", m->jnt_type[j] == mjJNT_SLIDE ? "m" : "rad");
    if (m->jnt_limited[j]) {
      cJSON_AddItemToObject(jo, "range", cJSON_CreateDoubleArray(m->jnt_range + 2 * j, 2));
    }
    cJSON_AddItemToArray(joints, jo);
  }
  cJSON_AddNumberToObject(root, "muscles", info->nmuscle);
  cJSON_AddNumberToObject(root, "muscles_elastic_tendon", info->nmuscle - info->nmuscle_rigid);
  cJSON_AddNumberToObject(root, "muscles_rigid_tendon", info->nmuscle_rigid);
  cJSON* list = cJSON_AddArrayToObject(root, "muscle_list");
  for (int i = 0; i < m->nu; i++) {
    if (!gs_actuator_is_muscle(m, i)) {
      continue;
    }
    cJSON* mo = cJSON_CreateObject();
    cJSON_AddStringToObject(mo, "name", mj_id2name(m, mjOBJ_ACTUATOR, i));
    cJSON_AddStringToObject(mo, "tendon", gs_actuator_has_elastic_tendon(m, i) ? "elastic" : "rigid");
    cJSON_AddNumberToObject(mo, "max_isometric_force_N", muscle_param(m, i, GS_ACT_FMAX));
    cJSON_AddNumberToObject(mo, "optimal_fiber_length_m", muscle_param(m, i, GS_ACT_LOPT));
    cJSON_AddNumberToObject(mo, "tendon_slack_length_m", muscle_param(m, i, GS_ACT_LTS));
    cJSON_AddItemToArray(list, mo);
  }
  cJSON* contacts = cJSON_AddObjectToObject(root, "contact_spheres");
  cJSON_AddNumberToObject(contacts, "r", info->ncontact_r);
  cJSON_AddNumberToObject(contacts, "l", info->ncontact_l);
  cJSON_AddNumberToObject(root, "mass_kg", info->mass);
  char* text = cJSON_Print(root);
  cJSON_Delete(root);
  if (!text) {
    fprintf(stderr, "gaitsim: info: out of memory\n");
    return GS_EXIT_FAILURE;
  }
  printf("%s\n", text);
  free(text);
  return GS_EXIT_OK;
}

int gs_cmd_info(int argc, char** argv) {
  static const struct option options[] = {
      {"json", no_argument, NULL, 'j'}, {"help", no_argument, NULL, 'h'}, {NULL, 0, NULL, 0}};
  int json = 0;
  optind = 1;
  opterr = 0;
  int c;
  while ((c = getopt_long(argc, argv, ":jh", options, NULL)) != -1) {
    switch (c) {
      case 'j': json = 1; break;
      case 'h': fputs(kInfoUsage, stdout); return GS_EXIT_OK;
      default: return gs_opt_getopt_error("info", c, argv);
    }
  }
  if (gs_opt_one_operand("info", "MODEL", argc, argv) != 0) return GS_EXIT_USAGE;
  const char* path = argv[optind];
  char err[1024];
  mjModel* m = gs_model_load(path, err, sizeof(err));
  if (!m) {
    fprintf(stderr, "gaitsim: %s: %s\n", path, err);
    return GS_EXIT_FAILURE;
  }
  gsModelInfo info;
  gs_model_info(m, &info);
  int status = GS_EXIT_OK;
  if (json) {
    status = print_json(path, m, &info);
  } else {
    print_text(path, m, &info);
  }
  mj_deleteModel(m);
  return status;
}
