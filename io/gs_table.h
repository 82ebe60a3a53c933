// gs_table.h: an in-memory table of time series (one row per time sample, one column per named
// signal), the form in which gaitsim holds what it reads from and writes to OpenSim storage files.
//
// Ownership: a gsTable owns all its arrays and strings. Start from gs_table_init (or a zeroed
// struct); every function that fills a table frees what it held before; release with
// gs_table_free. Output tables may be the same object as the input (the result is built aside
// and swapped in only on success; on failure the output keeps its previous content).
//
// Errors: functions that can fail return 0 on success and -1 on failure, and then write one line
// "function: reason" into err (errsz bytes; err may be NULL). Nothing is printed.
#ifndef GAITSIM_IO_GS_TABLE_H_
#define GAITSIM_IO_GS_TABLE_H_

typedef struct gsTable_ {
  int nrow;        // number of time samples (rows)
  int ncol;        // number of data columns, time excluded
  double* time;    // sample times, strictly increasing in tables read from files  (s, nrow x 1)
  double* data;    // values, row-major: data[i*ncol + j] = column j at time[i]   (nrow x ncol)
  char** labels;   // column names (OpenSim names, e.g. hip_flexion_r), time excluded (ncol x 1)
  int in_degrees;  // 1: angle columns hold degrees (inDegrees=yes), 0: radians
  char* name;      // table name (first header line of a .sto/.mot); NULL when none
} gsTable;

// Answers 1 when column `label` holds an angle (or angular velocity), 0 otherwise.
typedef int (*gsAnglePredicate)(const char* label, void* user);

// Zero all fields (an empty table). Does not free.
void gs_table_init(gsTable* t);

// Free everything the table owns and zero it. Safe on an initialized or zeroed table.
void gs_table_free(gsTable* t);

// Make t an nrow x ncol table of zeros (times zero too) with copies of `labels` (ncol strings;
// NULL gives "c1", "c2", ...), in_degrees 0, no name. nrow, ncol >= 0.
int gs_table_create(gsTable* t, int nrow, int ncol, const char* const* labels, char* err,
                    int errsz);

// Column c of t at `time` (s): linear interpolation between the neighbouring rows (binary
// search), clamped to the first and last rows outside the table's time range.
double gs_table_value_at(const gsTable* t, int c, double time);

// Deep copy of src into dst.
int gs_table_copy(const gsTable* src, gsTable* dst, char* err, int errsz);

// Set the table name (a copy; NULL clears it).
int gs_table_set_name(gsTable* t, const char* name, char* err, int errsz);

// Index of the column named `label` (exact, case-sensitive match), or -1.
int gs_table_column(const gsTable* t, const char* label);

// dst = the n columns of src named by labels, in that order, with all rows. A missing column,
// or one named twice, is an error naming it. n >= 1.
int gs_table_select(const gsTable* src, const char* const* labels, int n, gsTable* dst, char* err,
                    int errsz);

// dst = src linearly interpolated at the n strictly increasing `times` (n >= 1), all columns.
// Linear, not a spline: it never overshoots (a measured force stays >= 0, an angle stays within
// its range), and it reproduces the samples exactly at their own times. Every time must lie in
// [src->time[0], src->time[nrow-1]] (no extrapolation; a tolerance of 1e-9 of the time span,
// plus 1e-12 s, absorbs rounding, and such times are clamped to the range). src->time must be
// strictly increasing.
int gs_table_resample(const gsTable* src, const double* times, int n, gsTable* dst, char* err,
                      int errsz);

// dst = the part of src between t0 and t1 (t0 < t1, both within the time range, e.g. two heel
// strikes): a row interpolated at exactly t0, the samples strictly inside (those within
// 1e-9 (t1 - t0) of t0 or t1 are dropped, the interpolated rows replace them), and a row at
// exactly t1. With shift_to_zero, t0 is subtracted from all times (the first becomes 0).
int gs_table_cut(const gsTable* src, double t0, double t1, int shift_to_zero, gsTable* dst,
                 char* err, int errsz);

// When t->in_degrees, multiply every column for which is_angle(label, user) answers 1 by pi/180
// and clear in_degrees; otherwise do nothing. is_angle NULL means gs_table_is_angle_default.
void gs_table_to_radians(gsTable* t, gsAnglePredicate is_angle, void* user);

// The reverse: when !t->in_degrees, convert angle columns to degrees and set in_degrees (for
// writing files a biomechanist opens, DESIGN.md: angles in degrees, inDegrees=yes).
void gs_table_to_degrees(gsTable* t, gsAnglePredicate is_angle, void* user);

// Default heuristic for OpenSim column names; user is ignored. A column is an angle unless
//  - after removing a trailing "/value" or "/speed" (OpenSim 4 state paths), its name ends in
//    "_tx", "_ty" or "_tz" (translational coordinates, and their speeds), or
//  - its name contains, case-insensitively, "force", "torque", "moment", "cop" (ground reaction
//    forces, centres of pressure "ground_force_px", moments), "activation", "excitation" or
//    "length" (muscle states), or is "time".
// Rotational coordinate speeds (e.g. "knee_angle_r_u", ".../speed") count as angles: they are
// in deg/s when inDegrees=yes. Pass an explicit list (gs_table_is_angle_in_list) when in doubt.
int gs_table_is_angle_default(const char* label, void* user);

// Predicate for an explicit list: user is a NULL-terminated array of column names
// (const char* const*); a column is an angle when its label is in the list.
int gs_table_is_angle_in_list(const char* label, void* user);

#endif  // GAITSIM_IO_GS_TABLE_H_
