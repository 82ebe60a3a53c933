// gs_table.c: in-memory time-series tables: create, select, resample, cut, unit conversion.
#include "io/gs_table.h"

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/gs_text.h"

#define GS_TABLE_PI 3.14159265358979323846

void gs_table_init(gsTable* t) {
  memset(t, 0, sizeof(*t));
}

void gs_table_free(gsTable* t) {
  if (!t) {
    return;
  }
  if (t->labels) {
    for (int j = 0; j < t->ncol; j++) {
      free(t->labels[j]);
    }
  }
  free(t->labels);
  free(t->time);
  free(t->data);
  free(t->name);
  gs_table_init(t);
}

// allocate an nrow x ncol zero table into a fresh struct (labels left NULL)
static int alloc_table(gsTable* t, int nrow, int ncol, const char* fn, char* err, int errsz) {
  gs_table_init(t);
  if (nrow < 0 || ncol < 0) {
    gs_error_set(err, errsz, "%s: negative size %d x %d", fn, nrow, ncol);
    return -1;
  }
  size_t cells = (size_t)nrow * (size_t)ncol;
  if (ncol > 0 && cells / (size_t)ncol != (size_t)nrow) {
    gs_error_set(err, errsz, "%s: size %d x %d overflows", fn, nrow, ncol);
    return -1;
  }
  if (cells > SIZE_MAX / sizeof(double)) {
    gs_error_set(err, errsz, "%s: size %d x %d too large", fn, nrow, ncol);
    return -1;
  }
  t->nrow = nrow;
  t->ncol = ncol;
  t->time = calloc(nrow > 0 ? (size_t)nrow : 1, sizeof(double));
  t->data = calloc(cells > 0 ? cells : 1, sizeof(double));
  t->labels = calloc(ncol > 0 ? (size_t)ncol : 1, sizeof(char*));
  if (!t->time || !t->data || !t->labels) {
    gs_table_free(t);
    gs_error_set(err, errsz, "%s: out of memory for %d x %d table", fn, nrow, ncol);
    return -1;
  }
  return 0;
}

// replace *dst by *tmp (dst's old content is freed)
static void swap_in(gsTable* dst, gsTable* tmp) {
  gs_table_free(dst);
  *dst = *tmp;
  gs_table_init(tmp);
}

int gs_table_create(gsTable* t, int nrow, int ncol, const char* const* labels, char* err,
                    int errsz) {
  gsTable tmp;
  if (alloc_table(&tmp, nrow, ncol, "gs_table_create", err, errsz) != 0) {
    return -1;
  }
  for (int j = 0; j < ncol; j++) {
    char buf[32];
    const char* s = labels ? labels[j] : NULL;
    if (!s) {
      snprintf(buf, sizeof(buf), "c%d", j + 1);
      s = buf;
    }
    tmp.labels[j] = gs_string_dup(s);
    if (!tmp.labels[j]) {
      gs_table_free(&tmp);
      gs_error_set(err, errsz, "gs_table_create: out of memory");
      return -1;
    }
  }
  swap_in(t, &tmp);
  return 0;
}

int gs_table_copy(const gsTable* src, gsTable* dst, char* err, int errsz) {
  if (src == dst) {
    return 0;
  }
  gsTable tmp;
  gs_table_init(&tmp);
  if (gs_table_create(&tmp, src->nrow, src->ncol, (const char* const*)src->labels, err, errsz)) {
    return -1;
  }
  if (src->nrow > 0) {
    memcpy(tmp.time, src->time, (size_t)src->nrow * sizeof(double));
    memcpy(tmp.data, src->data, (size_t)src->nrow * (size_t)src->ncol * sizeof(double));
  }
  tmp.in_degrees = src->in_degrees;
  if (gs_table_set_name(&tmp, src->name, err, errsz) != 0) {
    gs_table_free(&tmp);
    return -1;
  }
  swap_in(dst, &tmp);
  return 0;
}

int gs_table_set_name(gsTable* t, const char* name, char* err, int errsz) {
  char* copy = NULL;
  if (name) {
    copy = gs_string_dup(name);
    if (!copy) {
      gs_error_set(err, errsz, "gs_table_set_name: out of memory");
      return -1;
    }
  }
  free(t->name);
  t->name = copy;
  return 0;
}

int gs_table_column(const gsTable* t, const char* label) {
  if (!t || !label || !t->labels) {
    return -1;
  }
  for (int j = 0; j < t->ncol; j++) {
    if (t->labels[j] && strcmp(t->labels[j], label) == 0) {
      return j;
    }
  }
  return -1;
}

int gs_table_select(const gsTable* src, const char* const* labels, int n, gsTable* dst, char* err,
                    int errsz) {
  if (n < 1 || !labels) {
    gs_error_set(err, errsz, "gs_table_select: no columns requested");
    return -1;
  }

  // map requested names to source columns
  int* idx = malloc((size_t)n * sizeof(int));
  if (!idx) {
    gs_error_set(err, errsz, "gs_table_select: out of memory");
    return -1;
  }
  for (int k = 0; k < n; k++) {
    idx[k] = labels[k] ? gs_table_column(src, labels[k]) : -1;
    if (idx[k] < 0) {
      gs_error_set(err, errsz, "gs_table_select: column '%.64s' not found in table '%.64s'",
              labels[k] ? labels[k] : "(null)", src->name ? src->name : "");
      free(idx);
      return -1;
    }
    for (int m = 0; m < k; m++) {
      if (idx[m] == idx[k]) {
        gs_error_set(err, errsz, "gs_table_select: column '%.64s' requested twice", labels[k]);
        free(idx);
        return -1;
      }
    }
  }

  // copy the columns
  gsTable tmp;
  gs_table_init(&tmp);
  if (gs_table_create(&tmp, src->nrow, n, labels, err, errsz) != 0 ||
      gs_table_set_name(&tmp, src->name, err, errsz) != 0) {
    gs_table_free(&tmp);
    free(idx);
    return -1;
  }
  tmp.in_degrees = src->in_degrees;
  for (int i = 0; i < src->nrow; i++) {
    tmp.time[i] = src->time[i];
    for (int k = 0; k < n; k++) {
      tmp.data[(size_t)i * n + k] = src->data[(size_t)i * src->ncol + idx[k]];
    }
  }
  free(idx);
  swap_in(dst, &tmp);
  return 0;
}

int gs_table_resample(const gsTable* src, const double* times, int n, gsTable* dst, char* err,
                      int errsz) {
  if (n < 1 || !times) {
    gs_error_set(err, errsz, "gs_table_resample: no times requested");
    return -1;
  }
  if (src->nrow < 1) {
    gs_error_set(err, errsz, "gs_table_resample: source table has no rows");
    return -1;
  }

  // the source time must be a strictly increasing grid
  for (int i = 0; i < src->nrow; i++) {
    if (!isfinite(src->time[i]) || (i > 0 && !(src->time[i] > src->time[i - 1]))) {
      gs_error_set(err, errsz, "gs_table_resample: source time not strictly increasing at row %d", i);
      return -1;
    }
  }
  double lo = src->time[0], hi = src->time[src->nrow - 1];
  if (!isfinite(hi - lo)) {
    gs_error_set(err, errsz, "gs_table_resample: time span [%.10g, %.10g] too large", lo, hi);
    return -1;
  }
  double tol = 1e-9 * (hi - lo) + 1e-12;

  // the requested times: finite, strictly increasing, within the range
  for (int k = 0; k < n; k++) {
    if (!isfinite(times[k]) || (k > 0 && !(times[k] > times[k - 1]))) {
      gs_error_set(err, errsz, "gs_table_resample: requested times not strictly increasing at %d", k);
      return -1;
    }
    if (times[k] < lo - tol || times[k] > hi + tol) {
      gs_error_set(err, errsz, "gs_table_resample: time %.10g outside the table's range [%.10g, %.10g]",
              times[k], lo, hi);
      return -1;
    }
  }

  gsTable tmp;
  gs_table_init(&tmp);
  if (gs_table_create(&tmp, n, src->ncol, (const char* const*)src->labels, err, errsz) != 0 ||
      gs_table_set_name(&tmp, src->name, err, errsz) != 0) {
    gs_table_free(&tmp);
    return -1;
  }
  tmp.in_degrees = src->in_degrees;

  // walk both grids together: interval [time[i], time[i+1]] holds t
  int i = 0;
  for (int k = 0; k < n; k++) {
    double t = times[k] < lo ? lo : (times[k] > hi ? hi : times[k]);
    while (i + 1 < src->nrow - 1 && src->time[i + 1] <= t) {
      i++;
    }
    double* row = tmp.data + (size_t)k * src->ncol;
    tmp.time[k] = times[k];
    if (src->nrow == 1) {
      memcpy(row, src->data, (size_t)src->ncol * sizeof(double));
      continue;
    }

    // (1-w) y0 + w y1 is exact at both ends (w = 0 or 1)
    double t0 = src->time[i], t1 = src->time[i + 1];
    double w = (t - t0) / (t1 - t0);
    const double* y0 = src->data + (size_t)i * src->ncol;
    const double* y1 = y0 + src->ncol;
    for (int j = 0; j < src->ncol; j++) {
      row[j] = (1.0 - w) * y0[j] + w * y1[j];
    }
  }
  swap_in(dst, &tmp);
  return 0;
}

int gs_table_cut(const gsTable* src, double t0, double t1, int shift_to_zero, gsTable* dst,
                 char* err, int errsz) {
  if (!isfinite(t0) || !isfinite(t1) || !(t0 < t1)) {
    gs_error_set(err, errsz, "gs_table_cut: need t0 < t1, got %.10g, %.10g", t0, t1);
    return -1;
  }
  if (src->nrow < 2) {
    gs_error_set(err, errsz, "gs_table_cut: source table has %d rows, need at least 2", src->nrow);
    return -1;
  }

  // times: t0, the samples strictly inside (away from the ends), t1
  double eps = 1e-9 * (t1 - t0);
  double* times = malloc(((size_t)src->nrow + 2) * sizeof(double));
  if (!times) {
    gs_error_set(err, errsz, "gs_table_cut: out of memory");
    return -1;
  }
  int n = 0;
  times[n++] = t0;
  for (int i = 0; i < src->nrow; i++) {
    if (src->time[i] > t0 + eps && src->time[i] < t1 - eps) {
      times[n++] = src->time[i];
    }
  }
  times[n++] = t1;

  gsTable tmp;
  gs_table_init(&tmp);
  int rc = gs_table_resample(src, times, n, &tmp, err, errsz);
  free(times);
  if (rc != 0) {
    if (err && errsz > 0 && strncmp(err, "gs_table_resample", 17) == 0) {
      char inner[256];
      snprintf(inner, sizeof(inner), "%s", err + 17);
      gs_error_set(err, errsz, "gs_table_cut%s", inner);
    }
    return -1;
  }

  // the ends are exact by construction; optionally start the clock at zero
  tmp.time[0] = t0;
  tmp.time[n - 1] = t1;
  if (shift_to_zero) {
    for (int k = 0; k < n; k++) {
      tmp.time[k] -= t0;
    }
    tmp.time[0] = 0.0;
  }
  swap_in(dst, &tmp);
  return 0;
}

// multiply the angle columns by f
static void scale_angles(gsTable* t, gsAnglePredicate is_angle, void* user, double f) {
  if (!is_angle) {
    is_angle = gs_table_is_angle_default;
  }
  for (int j = 0; j < t->ncol; j++) {
    if (!is_angle(t->labels[j], user)) {
      continue;
    }
    for (int i = 0; i < t->nrow; i++) {
      t->data[(size_t)i * t->ncol + j] *= f;
    }
  }
}

void gs_table_to_radians(gsTable* t, gsAnglePredicate is_angle, void* user) {
  if (!t->in_degrees) {
    return;
  }
  scale_angles(t, is_angle, user, GS_TABLE_PI / 180.0);
  t->in_degrees = 0;
}

void gs_table_to_degrees(gsTable* t, gsAnglePredicate is_angle, void* user) {
  if (t->in_degrees) {
    return;
  }
  scale_angles(t, is_angle, user, 180.0 / GS_TABLE_PI);
  t->in_degrees = 1;
}

// 1 when s ends with suffix
static int ends_with(const char* s, size_t n, const char* suffix) {
  size_t m = strlen(suffix);
  return n >= m && memcmp(s + n - m, suffix, m) == 0;
}

// 1 when s contains word, ignoring case
static int contains_nocase(const char* s, const char* word) {
  size_t m = strlen(word);
  for (; *s; s++) {
    size_t k = 0;
    while (k < m && s[k] && tolower((unsigned char)s[k]) == word[k]) {
      k++;
    }
    if (k == m) {
      return 1;
    }
  }
  return 0;
}

int gs_table_is_angle_default(const char* label, void* user) {
  if (!label) {
    return 0;
  }

  // translations, with OpenSim 4 state paths ".../pelvis_tx/value" reduced to their coordinate
  size_t n = strlen(label);
  if (ends_with(label, n, "/value") || ends_with(label, n, "/speed")) {
    n -= 6;
  }
  if (ends_with(label, n, "_tx") || ends_with(label, n, "_ty") || ends_with(label, n, "_tz")) {
    return 0;
  }

  // forces, moments, centres of pressure, muscle states
  static const char* const not_angles[] = {"force",      "torque",     "moment", "cop",
                                           "activation", "excitation", "length"};
  for (size_t k = 0; k < sizeof(not_angles) / sizeof(not_angles[0]); k++) {
    if (contains_nocase(label, not_angles[k])) {
      return 0;
    }
  }
  if (contains_nocase(label, "time") && strlen(label) == 4) {
    return 0;
  }
  return 1;
}

int gs_table_is_angle_in_list(const char* label, void* user) {
  const char* const* list = (const char* const*)user;
  if (!label || !list) {
    return 0;
  }
  for (; *list; list++) {
    if (strcmp(*list, label) == 0) {
      return 1;
    }
  }
  return 0;
}

double gs_table_value_at(const gsTable* t, int c, double time) {
  if (t->nrow == 1 || time <= t->time[0]) {
    return t->data[c];
  }
  if (time >= t->time[t->nrow - 1]) {
    return t->data[(t->nrow - 1) * t->ncol + c];
  }
  int lo = 0, hi = t->nrow - 1;
  while (hi - lo > 1) {
    int mid = (lo + hi) / 2;
    if (t->time[mid] <= time) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  double w = (time - t->time[lo]) / (t->time[hi] - t->time[lo]);
  return (1 - w) * t->data[lo * t->ncol + c] + w * t->data[hi * t->ncol + c];
}
