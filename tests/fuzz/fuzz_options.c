// fuzz_options.c: libFuzzer target for the option readers: gs_opt_int, gs_opt_real,
// gs_opt_speeds (app/gs_options.h: every value of the command line) and the Ipopt options
// (go_ipopt_opts_add "key=value", go_ipopt_opts_read_file).
//
// The first byte chooses the reader, the rest is the text. What an accepted value promises must
// hold: integers and numbers within the bounds asked for and finite, speeds ascending within
// (0, 10) m/s, at most GS_MAX_SPEEDS of them and distinct to 4 digits; Ipopt options stored
// NUL-terminated within their fields, at most GO_IPOPT_MAX_OPTIONS. Any violation aborts.
// Rejections print one line on stderr: run with -close_fd_mask=2 (scripts/fuzz.sh).

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/gs_options.h"
#include "optim/go_ipopt.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > 4096) return 0;
  char* text = (char*)malloc(size);
  memcpy(text, data + 1, size - 1);
  text[size - 1] = 0;  // the text ends at its first NUL, as an argv word does
  int k;
  double x, v[GS_MAX_SPEEDS];
  switch (data[0] % 5) {
    case 0:
      if (gs_opt_int("--n", text, 4, 1000, &k) == 0 && !(k >= 4 && k <= 1000)) abort();
      break;
    case 1:
      if (gs_opt_real("--x", text, 0, 10, GS_OPT_LO_OPEN, &x) == 0 && !(x > 0 && x <= 10)) abort();
      if (gs_opt_real("--y", text, 0, HUGE_VAL, 0, &x) == 0 && !(x >= 0 && isfinite(x))) abort();
      break;
    case 2: {
      int n = gs_opt_speeds("--speeds", text, v);
      if (n == 0 || n > GS_MAX_SPEEDS) abort();
      for (int i = 0; i < n; i++) {
        char a[32], b[32];
        if (!(v[i] > 0 && v[i] < 10)) abort();
        if (i == 0) continue;
        snprintf(a, sizeof(a), "%.4g", v[i - 1]);
        snprintf(b, sizeof(b), "%.4g", v[i]);
        if (!(v[i] > v[i - 1]) || strcmp(a, b) == 0) abort();
      }
      break;
    }
    case 3: {
      go_ipopt_opts o;
      char err[256];
      go_ipopt_opts_default(&o);
      for (char* line = strtok(text, "\n"); line; line = strtok(NULL, "\n"))
        go_ipopt_opts_add(&o, line, err, sizeof(err));
      if (o.n_kv < 0 || o.n_kv > GO_IPOPT_MAX_OPTIONS) abort();
      for (int i = 0; i < o.n_kv; i++)
        if (!memchr(o.kv[i].key, 0, sizeof(o.kv[i].key)) || !o.kv[i].key[0] ||
            !memchr(o.kv[i].val, 0, sizeof(o.kv[i].val)))
          abort();
      break;
    }
    default: {
      char path[] = "/tmp/fuzz_options.XXXXXX";
      int fd = mkstemp(path);
      if (fd < 0) abort();
      if (size > 1 && write(fd, data + 1, size - 1) != (ssize_t)(size - 1)) abort();
      close(fd);
      go_ipopt_opts o;
      char err[256];
      go_ipopt_opts_default(&o);
      go_ipopt_opts_read_file(&o, path, err, sizeof(err));
      unlink(path);
      if (o.n_kv < 0 || o.n_kv > GO_IPOPT_MAX_OPTIONS) abort();
    }
  }
  free(text);
  return 0;
}
