// main.c: the gaitsim command line. Dispatches to a subcommand (app/gs_commands.h).
#include <stdio.h>
#include <string.h>

#include <coin/IpoptConfig.h>
#include <mujoco/mujoco.h>

#include "app/gs_commands.h"
#include "callbacks/gs_mujoco.h"

static void print_usage(FILE* f) {
  fprintf(f,
          "usage: gaitsim <command> [options]\n"
          "       gaitsim <command> --help\n"
          "       gaitsim --version\n\n"
          "Full-body, muscle-driven 3D gait by direct collocation (MuJoCo + Ipopt).\n\n"
          "commands:\n");
  for (const gsCommand* c = gs_commands; c->name; c++) {
    fprintf(f, "  %-10s %s\n", c->name, c->synopsis);
  }
}

int main(int argc, char** argv) {
  gs_mujoco_install_handlers();
  if (argc < 2) {
    print_usage(stderr);
    return GS_EXIT_USAGE;
  }
  const char* word = argv[1];
  if (strcmp(word, "--help") == 0 || strcmp(word, "-h") == 0 || strcmp(word, "help") == 0) {
    print_usage(stdout);
    return GS_EXIT_OK;
  }
  if (strcmp(word, "--version") == 0 || strcmp(word, "version") == 0) {
    printf("gaitsim %s\nMuJoCo %s\nIpopt %s\n", GAITSIM_VERSION, mj_versionString(),
           IPOPT_VERSION);
    return GS_EXIT_OK;
  }
  for (const gsCommand* c = gs_commands; c->name; c++) {
    if (strcmp(word, c->name) == 0) {
      return c->run(argc - 1, argv + 1);
    }
  }
  fprintf(stderr, "gaitsim: unknown command '%s' (see gaitsim --help)\n", word);
  return GS_EXIT_USAGE;
}
