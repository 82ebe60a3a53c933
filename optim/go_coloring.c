// go_coloring.c: greedy distance-1 column colouring for sparse finite differences.
#include "optim/go_coloring.h"

#include <stdio.h>
#include <stdlib.h>

int go_color_columns(int nrow, int ncol, const int* col_ptr, const int* row_idx,
                     const unsigned char* skip, int* color, char* err, int errsz) {
  // validate: rows in range, no row twice in a column
  int* row_seen = malloc(sizeof(int) * (size_t)(nrow > 0 ? nrow : 1));
  unsigned char* used = calloc((size_t)(ncol > 0 ? ncol : 1) * (size_t)(nrow > 0 ? nrow : 1), 1);
  if (!row_seen || !used) {
    free(row_seen);
    free(used);
    snprintf(err, (size_t)errsz, "colouring: out of memory");
    return -1;
  }
  for (int r = 0; r < nrow; r++) row_seen[r] = -1;
  for (int j = 0; j < ncol; j++) {
    for (int p = col_ptr[j]; p < col_ptr[j + 1]; p++) {
      int r = row_idx[p];
      if (r < 0 || r >= nrow) {
        snprintf(err, (size_t)errsz, "pattern: row %d out of range [0,%d) in column %d", r, nrow, j);
        free(row_seen);
        free(used);
        return -1;
      }
      if (row_seen[r] == j) {
        snprintf(err, (size_t)errsz, "pattern: row %d repeated in column %d", r, j);
        free(row_seen);
        free(used);
        return -1;
      }
      row_seen[r] = j;
    }
  }

  // greedy: smallest colour none of whose rows (used[c*nrow + r]) this column touches
  int ncolor = 0;
  for (int j = 0; j < ncol; j++) {
    color[j] = -1;
    if ((skip && skip[j]) || col_ptr[j + 1] == col_ptr[j]) continue;
    int c = 0;
    for (; c < ncolor; c++) {
      const unsigned char* u = used + (size_t)c * (size_t)nrow;
      int clash = 0;
      for (int p = col_ptr[j]; p < col_ptr[j + 1] && !clash; p++) clash = u[row_idx[p]];
      if (!clash) break;
    }
    if (c == ncolor) ncolor++;
    color[j] = c;
    unsigned char* u = used + (size_t)c * (size_t)nrow;
    for (int p = col_ptr[j]; p < col_ptr[j + 1]; p++) u[row_idx[p]] = 1;
  }
  free(row_seen);
  free(used);
  return ncolor;
}
