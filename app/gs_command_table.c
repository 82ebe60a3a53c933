// gs_command_table.c: the subcommands gaitsim knows, in the order --help lists them.
#include <stddef.h>

#include "app/gs_commands.h"

const gsCommand gs_commands[] = {
    {"run", gs_cmd_run, "run the default pipeline on the bundled trial"},
    {"info", gs_cmd_info, "summarise a model: degrees of freedom, muscles, contacts, mass"},
    {"simulate", gs_cmd_simulate, "forward simulation with gaitsim's muscles and foot contact"},
    {"inspect", gs_cmd_inspect, "one row per muscle at one instant: lengths, force, metabolics, moment arms"},
    {"balance", gs_cmd_balance, "frontal-plane balance of a gait by inverse dynamics: feet, hips, CoM, momentum"},
    {"moments", gs_cmd_moments, "net joint moments by inverse dynamics (OpenSim's ID tool) into a .sto"},
    {"work", gs_cmd_work, "mechanical work of a gait per source: muscles, foot contact, knee, limits"},
    {"track", gs_cmd_track, "tracking solve of one stride by direct collocation"},
    {"predict", gs_cmd_predict, "predictive solve at a new speed: minimum cost of transport, free stride time"},
    {"sweep", gs_cmd_sweep, "predictive solves over a range of speeds, each from the tracking solution"},
    {"batch", gs_cmd_batch, "many solves from a plan, here (--local N) or on Slurm (--slurm)"},
    {"batch-status", gs_cmd_batch_status, "done / running / pending / failed per solve of a batch"},
    {"render", gs_cmd_render, "headless gait video, picture or filmstrip of a solution (OSMesa)"},
    {"export", gs_cmd_export, "a solution as MuJoCo keyframes in an MJCF that includes the model"},
    {"report", gs_cmd_report, "figures and a table of a solution vs the measured trial (matplotlib)"},
    {NULL, NULL, NULL},
};
