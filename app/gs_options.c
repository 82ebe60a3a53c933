// gs_options.c: option checking shared by the subcommands (gs_options.h).
#include "app/gs_options.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/gs_commands.h"

int gs_opt_int(const char* name, const char* arg, long lo, long hi, int* out) {
  char* end;
  errno = 0;
  long v = strtol(arg, &end, 10);
  if (hi > INT_MAX) hi = INT_MAX;
  if (end == arg || *end || errno == ERANGE || v < lo || v > hi) {
    if (hi == INT_MAX) {
      fprintf(stderr, "gaitsim: %s: must be an integer >= %ld (got %s)\n", name, lo, arg);
    } else {
      fprintf(stderr, "gaitsim: %s: must be an integer in %ld..%ld (got %s)\n", name, lo, hi, arg);
    }
    return -1;
  }
  *out = (int)v;
  return 0;
}

int gs_opt_real(const char* name, const char* arg, double lo, double hi, int flags, double* out) {
  char* end;
  errno = 0;
  double v = strtod(arg, &end);
  int lo_ok = (flags & GS_OPT_LO_OPEN) ? v > lo : v >= lo;
  int hi_ok = (flags & GS_OPT_HI_OPEN) ? v < hi : v <= hi;
  if (end == arg || *end || errno == ERANGE || !isfinite(v) || !lo_ok || !hi_ok) {
    const char* lop = (flags & GS_OPT_LO_OPEN) ? ">" : ">=";
    if (isinf(hi)) {
      fprintf(stderr, "gaitsim: %s: must be a number %s %g (got %s)\n", name, lop, lo, arg);
    } else {
      fprintf(stderr, "gaitsim: %s: must be a number in %c%g, %g%c (got %s)\n", name,
              (flags & GS_OPT_LO_OPEN) ? '(' : '[', lo, hi, (flags & GS_OPT_HI_OPEN) ? ')' : ']',
              arg);
    }
    return -1;
  }
  *out = v;
  return 0;
}

int gs_opt_choice(const char* name, const char* arg, const char* const* choices, int* out) {
  for (int i = 0; choices[i]; i++) {
    if (strcmp(arg, choices[i]) == 0) {
      *out = i;
      return 0;
    }
  }
  fprintf(stderr, "gaitsim: %s: must be one of", name);
  for (int i = 0; choices[i]; i++) fprintf(stderr, "%s %s", i ? "," : "", choices[i]);
  fprintf(stderr, " (got %s)\n", arg);
  return -1;
}

int gs_opt_getopt_error(const char* cmd, int c, char** argv) {
  // the word getopt stopped at: the last one it consumed
  const char* word = optind > 0 ? argv[optind - 1] : "?";
  if (c == ':') {
    fprintf(stderr, "gaitsim: %s: option '%s' needs a value (see gaitsim %s --help)\n", cmd,
            word, cmd);
  } else if (optopt && (word[0] != '-' || word[1] != '-')) {
    fprintf(stderr, "gaitsim: %s: unknown option '-%c' (see gaitsim %s --help)\n", cmd, optopt,
            cmd);
  } else {
    fprintf(stderr, "gaitsim: %s: unknown option '%s' (see gaitsim %s --help)\n", cmd, word, cmd);
  }
  return GS_EXIT_USAGE;
}

int gs_opt_usage_error(const char* cmd, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "gaitsim: %s: ", cmd);
  vfprintf(stderr, fmt, ap);
  fprintf(stderr, " (see gaitsim %s --help)\n", cmd);
  va_end(ap);
  return GS_EXIT_USAGE;
}

int gs_opt_speeds(const char* name, const char* arg, double* v) {
  char* end;
  double a = strtod(arg, &end);
  int n = 0;
  if (end != arg && *end == ':') {
    double step = strtod(end + 1, &end);
    double b = *end == ':' ? strtod(end + 1, &end) : NAN;
    if (*end || !(a > 0 && a < 10) || !(step > 0 && step < 10) || !(b >= a && b < 10)) {
      fprintf(stderr, "gaitsim: %s: must be A:STEP:B with 0 < A <= B < 10 and 0 < STEP < 10 m/s, "
              "or V1,V2,... (got %s)\n", name, arg);
      return -1;
    }
    double count = floor((b - a) / step + 1e-9) + 1;
    if (count > GS_MAX_SPEEDS) {
      fprintf(stderr, "gaitsim: %s: at most %d speeds (got %.0f from %s)\n", name, GS_MAX_SPEEDS,
              count, arg);
      return -1;
    }
    for (int i = 0; i < (int)count; i++) v[n++] = a + i * step;
    return n;
  }
  const char* p = arg;
  while (*p) {
    double x = strtod(p, &end);
    if (end == p || !(x > 0 && x < 10) || (*end && *end != ',')) {
      fprintf(stderr, "gaitsim: %s: must be A:STEP:B or V1,V2,... with each speed in (0, 10) m/s "
              "(got %s)\n", name, arg);
      return -1;
    }
    if (n == GS_MAX_SPEEDS) {
      fprintf(stderr, "gaitsim: %s: at most %d speeds (got more in %s)\n", name, GS_MAX_SPEEDS,
              arg);
      return -1;
    }
    v[n++] = x;
    p = *end ? end + 1 : end;
  }
  if (n == 0) {
    fprintf(stderr, "gaitsim: %s: no speed given\n", name);
    return -1;
  }
  for (int i = 1; i < n; i++)  // insertion sort: ascending
    for (int j = i; j > 0 && v[j] < v[j - 1]; j--) {
      double t = v[j];
      v[j] = v[j - 1];
      v[j - 1] = t;
    }
  // each speed gets a folder predict_<%.4g>: two in one folder would overwrite each other
  for (int i = 1; i < n; i++) {
    char a4[32], b4[32];
    snprintf(a4, sizeof(a4), "%.4g", v[i - 1]);
    snprintf(b4, sizeof(b4), "%.4g", v[i]);
    if (strcmp(a4, b4) == 0) {
      fprintf(stderr, "gaitsim: %s: speeds %.17g and %.17g are the same to 4 digits (got %s)\n",
              name, v[i - 1], v[i], arg);
      return -1;
    }
  }
  return n;
}

int gs_opt_solve_limit(int c, const char* arg, const char** word) {
  int k;
  double x;
  *word = arg;
  if (c == 'n') return gs_opt_int("--nodes", arg, GS_MIN_NODES, GS_MAX_NODES, &k);
  if (c == 'T') return gs_opt_real("--max-time", arg, 0, HUGE_VAL, GS_OPT_LO_OPEN, &x);
  return gs_opt_int("--max-iter", arg, 0, GS_OPT_NO_MAX, &k);
}

int gs_opt_one_operand(const char* cmd, const char* what, int argc, char** argv) {
  if (optind == argc) return gs_opt_usage_error(cmd, "missing %s", what);
  if (optind < argc - 1)
    return gs_opt_usage_error(cmd, "unexpected argument '%s'", argv[optind + 1]);
  return 0;
}
