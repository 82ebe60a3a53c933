// gs_test_csv.h: the one reader of the small numeric CSV tables the knee test and its benchmark
// share (mjmodels/knee/jw_knee_heldout.csv): '#' lines are comments, fields are separated by
// commas or whitespace.
#ifndef GAITSIM_TESTS_GS_TEST_CSV_H_
#define GAITSIM_TESTS_GS_TEST_CSV_H_

#include <stdio.h>
#include <stdlib.h>

// The first ncol numbers of every non-comment row with at least ncol numbers into
// rows[n * stride + k] (k < ncol), at most maxrows rows. Returns the rows read, -1 when the file
// cannot be opened.
static int gs_test_read_csv_rows(const char* path, int ncol, int stride, double* rows,
                                 int maxrows) {
  FILE* f = fopen(path, "r");
  char line[2048];
  int n = 0;
  if (!f) {
    return -1;
  }
  while (n < maxrows && fgets(line, sizeof(line), f)) {
    if (line[0] == '#') {
      continue;
    }
    char* p = line;
    int k = 0;
    for (; k < ncol; k++) {
      char* end;
      rows[(size_t)n * stride + k] = strtod(p, &end);
      if (end == p) {
        break;
      }
      p = (*end == ',') ? end + 1 : end;
    }
    n += k == ncol;
  }
  fclose(f);
  return n;
}

#endif  // GAITSIM_TESTS_GS_TEST_CSV_H_
