// go_coloring.h: column grouping for sparse finite differences.
//
// Columns that share no row can be perturbed together: one pair of evaluations (central
// differences) then gives all of them, and each changed row is attributed to the single column of
// the group that touches it. This is a distance-1 colouring of the column intersection graph,
// done greedily in natural column order (Curtis, Powell & Reid 1974), so it is deterministic.
#ifndef GAITSIM_OPTIM_GO_COLORING_H_
#define GAITSIM_OPTIM_GO_COLORING_H_

// Colour the columns of an nrow x ncol pattern in compressed-column form (col_ptr: ncol+1,
// row_idx: col_ptr[ncol]). Columns with skip[j] != 0 (skip may be NULL) and empty columns get
// colour -1 (not perturbed). Writes color[ncol] and returns the number of colours (groups), or -1
// with a reason in err when the pattern is malformed (row out of range or repeated within a
// column) or memory runs out. Set-up time only: allocates ncol*nrow bytes temporarily.
int go_color_columns(int nrow, int ncol, const int* col_ptr, const int* row_idx,
                     const unsigned char* skip, int* color, char* err, int errsz);

#endif  // GAITSIM_OPTIM_GO_COLORING_H_
