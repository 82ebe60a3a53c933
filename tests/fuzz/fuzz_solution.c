// fuzz_solution.c: libFuzzer target for the solution-folder check every reader runs first
// (gs_app_check_solution: predict --guess, track --init, render, report, sweep --guess).
//
// The input is up to four files separated by a line "--8<--": summary.json, states.sto,
// controls.sto, variables.sto (a part left out is a missing file). They are written into one
// temporary folder and checked. When the check accepts the folder, what it promises must hold:
// states.sto reads, and states.sto, controls.sto and variables.sto (when present) have the
// node count of summary.json (when it says). Any violation aborts (libFuzzer saves the input).
// The check's one-line messages go to stderr: run with -close_fd_mask=2 (scripts/fuzz.sh).

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "app/gs_app_model.h"
#include "io/gs_storage.h"

static char dir[64];

int LLVMFuzzerInitialize(int* argc, char*** argv);
int LLVMFuzzerInitialize(int* argc, char*** argv) {
  (void)argc;
  (void)argv;
  snprintf(dir, sizeof(dir), "/tmp/fuzz_solution.XXXXXX");
  if (!mkdtemp(dir)) abort();
  return 0;
}

// rows of dir/name, -1 when missing or unreadable
static int rows_of(const char* name) {
  char path[128], err[256];
  snprintf(path, sizeof(path), "%s/%s", dir, name);
  gsTable t;
  gs_table_init(&t);
  int n = gs_storage_read(path, &t, err, sizeof(err)) == 0 ? t.nrow : -1;
  gs_table_free(&t);
  return n;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const char* const names[4] = {"summary.json", "states.sto", "controls.sto",
                                       "variables.sto"};
  static const char sep[] = "\n--8<--\n";
  const char* p = (const char*)data;
  const char* end = p + size;
  for (int i = 0; i < 4; i++) {
    char path[128];
    snprintf(path, sizeof(path), "%s/%s", dir, names[i]);
    unlink(path);
    if (!p) continue;
    const char* cut = memmem(p, (size_t)(end - p), sep, sizeof(sep) - 1);
    size_t n = cut ? (size_t)(cut - p) : (size_t)(end - p);
    if (n > 0 || cut) {
      FILE* f = fopen(path, "wb");
      if (!f) abort();
      if (n) fwrite(p, 1, n, f);
      fclose(f);
    }
    p = cut ? cut + sizeof(sep) - 1 : NULL;
  }
  if (gs_app_check_solution(dir, 1) != 0) return 0;
  // accepted: its promises
  int states = rows_of("states.sto");
  if (states < 1) abort();
  for (int i = 2; i < 4; i++) {
    int r = rows_of(names[i]);
    if (r >= 0 && r != states) abort();
  }
  char path[128];
  snprintf(path, sizeof(path), "%s/summary.json", dir);
  cJSON* j = gs_app_read_json(path);
  if (!j) abort();
  const cJSON* nodes = cJSON_GetObjectItemCaseSensitive(j, "nodes");
  if (nodes && !(cJSON_IsNumber(nodes) && nodes->valuedouble == (double)states)) abort();
  cJSON_Delete(j);
  return 0;
}
