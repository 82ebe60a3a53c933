// gs_commands.h: the gaitsim subcommands. Each takes the arguments after its name (argv[0] is
// the subcommand) and returns the process exit status: 0 success, 1 bad input or failure, 2 a
// usage error, 3 a solve that stopped short (its best iterate written).
#ifndef GAITSIM_APP_GS_COMMANDS_H_
#define GAITSIM_APP_GS_COMMANDS_H_

typedef int (*gsCommandFn)(int argc, char** argv);

typedef struct gsCommand_ {
  const char* name;      // subcommand word
  gsCommandFn run;       // entry point
  const char* synopsis;  // one line for `gaitsim --help`
} gsCommand;

int gs_cmd_info(int argc, char** argv);
int gs_cmd_run(int argc, char** argv);
int gs_cmd_simulate(int argc, char** argv);
int gs_cmd_track(int argc, char** argv);
int gs_cmd_predict(int argc, char** argv);
int gs_cmd_sweep(int argc, char** argv);
int gs_cmd_inspect(int argc, char** argv);
int gs_cmd_balance(int argc, char** argv);
int gs_cmd_work(int argc, char** argv);
int gs_cmd_moments(int argc, char** argv);
int gs_cmd_batch(int argc, char** argv);
int gs_cmd_batch_status(int argc, char** argv);
int gs_cmd_render(int argc, char** argv);
int gs_cmd_report(int argc, char** argv);
int gs_cmd_export(int argc, char** argv);

// The table of subcommands, terminated by an entry with name NULL.
extern const gsCommand gs_commands[];

// Exit statuses shared by the subcommands.
enum {
  GS_EXIT_OK = 0,
  GS_EXIT_FAILURE = 1,
  GS_EXIT_USAGE = 2,
  GS_EXIT_STOPPED_SHORT = 3
};

#endif  // GAITSIM_APP_GS_COMMANDS_H_
