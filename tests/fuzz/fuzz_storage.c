// fuzz_storage.c: libFuzzer target for the storage/CSV reader and the table operations.
//
// Each input is parsed with gs_storage_read_buffer (format sniffed from the content). When it
// parses, the table must satisfy the reader's promises (finite values, strictly increasing
// time), survive select/resample/cut, and round-trip exactly through the writer and the reader
// again; any violation aborts, which libFuzzer reports as a crash.
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/gs_storage.h"
#include "io/gs_table.h"

// abort with a reason (libFuzzer saves the input)
static void fail(const char* what, const char* err) {
  fprintf(stderr, "fuzz_storage: %s: %s\n", what, err ? err : "");
  abort();
}

// the reader's promises about a table it returns
static void check_table(const gsTable* t) {
  if (t->nrow < 1 || t->ncol < 1 || !t->time || !t->data || !t->labels) {
    fail("empty table accepted", NULL);
  }
  for (int i = 0; i < t->nrow; i++) {
    if (!isfinite(t->time[i]) || (i > 0 && !(t->time[i] > t->time[i - 1]))) {
      fail("time not finite or not increasing", NULL);
    }
    for (int j = 0; j < t->ncol; j++) {
      if (!isfinite(t->data[(size_t)i * t->ncol + j])) {
        fail("non-finite value accepted", NULL);
      }
    }
  }
  for (int j = 0; j < t->ncol; j++) {
    if (!t->labels[j] || !t->labels[j][0] || gs_table_column(t, t->labels[j]) != j) {
      fail("empty or duplicate label accepted", t->labels[j]);
    }
  }
}

// write to memory, read back, compare exactly
static void check_round_trip(const gsTable* t) {
  char* buf = NULL;
  size_t n = 0;
  char err[256];
  FILE* f = open_memstream(&buf, &n);
  if (!f) {
    return;
  }
  int rc = gs_storage_write_stream(f, "fuzz.sto", t, NULL, 0, err, sizeof(err));
  fclose(f);
  if (rc == 0) {
    gsTable r;
    gs_table_init(&r);
    if (gs_storage_read_buffer(buf, n, "fuzz.sto", &r, err, sizeof(err)) != 0) {
      fail("written table does not read back", err);
    }
    if (r.nrow != t->nrow || r.ncol != t->ncol || r.in_degrees != t->in_degrees ||
        (t->name && (!r.name || strcmp(r.name, t->name) != 0))) {
      fail("round trip changed the shape, inDegrees or name", NULL);
    }
    for (int j = 0; j < t->ncol; j++) {
      if (strcmp(r.labels[j], t->labels[j]) != 0) {
        fail("round trip changed a label", t->labels[j]);
      }
    }
    for (int i = 0; i < t->nrow; i++) {
      if (r.time[i] != t->time[i] ||
          memcmp(r.data + (size_t)i * t->ncol, t->data + (size_t)i * t->ncol,
                 (size_t)t->ncol * sizeof(double)) != 0) {
        fail("round trip changed a value", NULL);
      }
    }
    gs_table_free(&r);
  }
  free(buf);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  char err[256];
  gsTable t;
  gs_table_init(&t);
  if (gs_storage_read_buffer((const char*)data, size, "fuzz", &t, err, sizeof(err)) != 0) {
    if (!memchr(err, '\0', sizeof(err)) || strchr(err, '\n')) {
      fail("error message not one terminated line", NULL);
    }
    return 0;
  }
  check_table(&t);
  check_round_trip(&t);

  // table operations on what was read
  gsTable u;
  gs_table_init(&u);
  const char* last = t.labels[t.ncol - 1];
  if (gs_table_select(&t, &last, 1, &u, err, sizeof(err)) != 0 || u.ncol != 1) {
    fail("select of an existing column failed", err);
  }
  if (t.nrow >= 2) {
    double t0 = t.time[0], t1 = t.time[t.nrow - 1];
    double mid = t0 + 0.5 * (t1 - t0);
    if (mid > t0 && mid < t1 && gs_table_cut(&t, mid, t1, 1, &u, err, sizeof(err)) != 0) {
      fail("cut within the range failed", err);
    }
    if (gs_table_resample(&t, t.time, t.nrow, &u, err, sizeof(err)) != 0) {
      fail("resample at the table's own times failed", err);
    }
    for (size_t k = 0; k < (size_t)t.nrow * (size_t)t.ncol; k++) {
      if (u.data[k] != t.data[k]) {
        fail("resample at the samples changed a value", NULL);
      }
    }
  }
  t.in_degrees = 1;
  gs_table_to_radians(&t, NULL, NULL);
  gs_table_free(&u);
  gs_table_free(&t);
  return 0;
}
