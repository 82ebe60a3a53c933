// gs_options.h: option checking shared by the subcommands. Every value is checked as it is read,
// before any work starts, and a bad one is reported in one line on stderr that names the option
// and what it accepts:
//   gaitsim: --nodes: must be an integer >= 4 (got 0)
// after which the subcommand returns GS_EXIT_USAGE (2). The usage text is printed only for
// --help. Each function returns 0 when the value is good (stored in *out), -1 after printing.
#ifndef GAITSIM_APP_GS_OPTIONS_H_
#define GAITSIM_APP_GS_OPTIONS_H_

#include <limits.h>

// no upper bound for gs_opt_int
#define GS_OPT_NO_MAX LONG_MAX

// collocation nodes accepted by track, predict, sweep and run (--nodes)
#define GS_MIN_NODES 4
#define GS_MAX_NODES 1000

// speeds of one sweep (--speeds), at most
#define GS_MAX_SPEEDS 64

// bounds of gs_opt_real: closed unless these flags say open
enum { GS_OPT_LO_OPEN = 1, GS_OPT_HI_OPEN = 2 };

// An integer in [lo, hi] (hi GS_OPT_NO_MAX: no upper bound), whole word, no overflow.
int gs_opt_int(const char* name, const char* arg, long lo, long hi, int* out);

// A finite number in [lo, hi] (HUGE_VAL: no upper bound; flags GS_OPT_LO_OPEN, GS_OPT_HI_OPEN
// make a bound strict), whole word; "nan", "inf" and overflow are refused.
int gs_opt_real(const char* name, const char* arg, double lo, double hi, int flags, double* out);

// One of the words of choices (NULL-terminated); *out gets its index.
int gs_opt_choice(const char* name, const char* arg, const char* const* choices, int* out);

// --speeds LIST: "A:STEP:B" (m/s, 0 < A <= B, STEP > 0) or "V1,V2,..." (each > 0), at most
// GS_MAX_SPEEDS, into v (ascending); the count, or -1 after printing.
int gs_opt_speeds(const char* name, const char* arg, double* v);

// The limits sweep and run pass on to each solve as words: c 'n' (--nodes, GS_MIN_NODES..
// GS_MAX_NODES), 'T' (--max-time, s > 0) or 'i' (--max-iter >= 0). Checks arg and points *word
// at it; 0, or -1 after printing.
int gs_opt_solve_limit(int c, const char* arg, const char** word);

// After getopt_long returned '?' or ':' (the caller set opterr = 0 and starts its optstring with
// ':'): print "gaitsim: CMD: unknown option '--foo' (see gaitsim CMD --help)" or "option
// '--nodes' needs a value" and return GS_EXIT_USAGE.
int gs_opt_getopt_error(const char* cmd, int c, char** argv);

// The one operand (e.g. TRIAL_DIR) after the options: 0 when argv[optind] is the last word,
// else GS_EXIT_USAGE after "gaitsim: CMD: missing WHAT" or "unexpected argument 'X'".
int gs_opt_one_operand(const char* cmd, const char* what, int argc, char** argv);

// Print "gaitsim: CMD: REASON (see gaitsim CMD --help)" (printf-style reason) and return
// GS_EXIT_USAGE.
int gs_opt_usage_error(const char* cmd, const char* fmt, ...)
    __attribute__((format(printf, 2, 3)));

#endif  // GAITSIM_APP_GS_OPTIONS_H_
