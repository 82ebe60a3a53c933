// gs_storage.c: OpenSim storage (.sto/.mot) and CSV reading with validation; atomic writing.
#define _POSIX_C_SOURCE 200809L

#include "io/gs_storage.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io/gs_atomic.h"
#include "io/gs_text.h"

// equal ignoring ASCII case
static int ieq(const char* a, const char* b) {
  for (; *a && *b; a++, b++) {
    if (tolower((unsigned char)*a) != tolower((unsigned char)*b)) {
      return 0;
    }
  }
  return *a == *b;
}

// space or tab
static int is_blank_char(char c) {
  return c == ' ' || c == '\t';
}

// strip leading and trailing spaces and tabs in place
static char* trim(char* s) {
  while (is_blank_char(*s)) {
    s++;
  }
  size_t n = strlen(s);
  while (n > 0 && is_blank_char(s[n - 1])) {
    s[--n] = '\0';
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// lines
// ---------------------------------------------------------------------------------------------

typedef struct lineReader_ {
  const char* buf;   // the whole input                                   (n bytes)
  size_t n;          // input size                                        (bytes)
  size_t pos;        // start of the next line                            (byte offset)
  const char* name;  // file name for messages
  int lineno;        // number of the current line, 1-based (0 before the first)
  char* line;        // current line without "\n" or "\r\n", NUL-terminated (owned)
  int newline;       // 1 when the current line ended with '\n'
} lineReader;

// advance to the next line: 1 a line, 0 end of input, -1 error
static int next_line(lineReader* r, char* err, int errsz) {
  if (r->pos >= r->n) {
    return 0;
  }
  const char* s = r->buf + r->pos;
  size_t rest = r->n - r->pos;
  const char* nl = memchr(s, '\n', rest);
  size_t len = nl ? (size_t)(nl - s) : rest;
  r->lineno++;
  r->pos += len + (nl ? 1 : 0);
  r->newline = nl != NULL;
  if (len > 0 && s[len - 1] == '\r') {
    len--;
  }
  if (len > GS_STORAGE_MAX_LINE) {
    gs_error_set(err, errsz, "%s:%d: line longer than %d bytes", r->name, r->lineno,
            GS_STORAGE_MAX_LINE);
    return -1;
  }
  if (memchr(s, '\0', len)) {
    gs_error_set(err, errsz, "%s:%d: NUL byte in line (binary file?)", r->name, r->lineno);
    return -1;
  }
  memcpy(r->line, s, len);
  r->line[len] = '\0';
  return 1;
}

// 1 when the line holds only spaces and tabs
static int is_blank_line(const char* s) {
  while (is_blank_char(*s)) {
    s++;
  }
  return *s == '\0';
}

// ---------------------------------------------------------------------------------------------
// cells
// ---------------------------------------------------------------------------------------------

typedef struct tokenizer_ {
  char* p;   // where the next cell starts
  char sep;  // separator: ',' or '\t', or 0 for runs of spaces and tabs
  int done;  // 1 after the last cell
} tokenizer;

// next cell (trimmed, NUL-terminated in place), or NULL after the last
static char* next_cell(tokenizer* t) {
  if (t->done) {
    return NULL;
  }
  if (t->sep == 0) {
    while (is_blank_char(*t->p)) {
      t->p++;
    }
    if (*t->p == '\0') {
      t->done = 1;
      return NULL;
    }
    char* s = t->p;
    while (*t->p && !is_blank_char(*t->p)) {
      t->p++;
    }
    if (*t->p) {
      *t->p++ = '\0';
    }
    return s;
  }
  char* s = t->p;
  char* e = strchr(s, t->sep);
  if (e) {
    *e = '\0';
    t->p = e + 1;
  } else {
    t->done = 1;
  }
  return trim(s);
}

// strtod that must consume the whole cell: 0 ok, -1 not a number, -2 not finite
static int parse_number(const char* s, double* v) {
  if (*s == '\0') {
    return -1;
  }
  char* end = NULL;
  errno = 0;
  double x = strtod(s, &end);
  if (end == s || *end != '\0') {
    return -1;
  }
  if (!isfinite(x) || (errno == ERANGE && fabs(x) > DBL_MIN)) {
    return -2;
  }
  *v = x;
  return 0;
}

// strtol for header sizes: 0 ok (0 <= value <= INT_MAX), -1 otherwise
static int parse_count(const char* s, int* v) {
  if (!isdigit((unsigned char)*s)) {
    return -1;
  }
  char* end = NULL;
  errno = 0;
  long x = strtol(s, &end, 10);
  if (*end != '\0' || errno == ERANGE || x > INT_MAX) {
    return -1;
  }
  *v = (int)x;
  return 0;
}

// the time label: "time", optionally with a unit in seconds: "Time(sec)", "time (s)", "time[s]"
static int is_time_label(const char* s) {
  static const char* const units[] = {"s", "sec", "secs", "second", "seconds"};
  if (strlen(s) < 4 || tolower((unsigned char)s[0]) != 't' ||
      tolower((unsigned char)s[1]) != 'i' || tolower((unsigned char)s[2]) != 'm' ||
      tolower((unsigned char)s[3]) != 'e') {
    return 0;
  }
  s += 4;
  while (is_blank_char(*s)) {
    s++;
  }
  if (*s == '\0') {
    return 1;
  }
  char close = *s == '(' ? ')' : (*s == '[' ? ']' : '\0');
  size_t n = strlen(s);
  if (!close || n < 2 || s[n - 1] != close || n - 2 > 16) {
    return 0;
  }
  char unit[17];
  memcpy(unit, s + 1, n - 2);
  unit[n - 2] = '\0';
  char* u = trim(unit);
  for (size_t k = 0; k < sizeof(units) / sizeof(units[0]); k++) {
    if (ieq(u, units[k])) {
      return 1;
    }
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// the parse
// ---------------------------------------------------------------------------------------------

typedef struct parser_ {
  lineReader r;      // input lines
  char** labels;     // all labels, time first (owned)                    (nlabels)
  int nlabels;       // number of labels including time
  int labels_line;   // line of the labels
  char** cells;      // cells of the current row                          (nlabels)
  double* time;      // sample times (owned)                              (cap)
  double* data;      // values, row-major (owned)                         (cap x (nlabels-1))
  int nrow;          // rows read
  int cap;           // rows allocated
  char* name;        // table name (owned) or NULL
  int in_degrees;    // inDegrees header value
} parser;

static void parser_free(parser* p) {
  if (p->labels) {
    for (int k = 0; k < p->nlabels; k++) {
      free(p->labels[k]);
    }
  }
  free(p->labels);
  free(p->cells);
  free(p->time);
  free(p->data);
  free(p->name);
  free(p->r.line);
}

// append a label copy
static int add_label(parser* p, const char* s, int* cap, char* err, int errsz) {
  if (p->nlabels == *cap) {
    int ncap = *cap ? 2 * *cap : 16;
    char** nl = realloc(p->labels, (size_t)ncap * sizeof(char*));
    if (!nl) {
      gs_error_set(err, errsz, "%s:%d: out of memory", p->r.name, p->r.lineno);
      return -1;
    }
    p->labels = nl;
    *cap = ncap;
  }
  p->labels[p->nlabels] = gs_string_dup(s);
  if (!p->labels[p->nlabels]) {
    gs_error_set(err, errsz, "%s:%d: out of memory", p->r.name, p->r.lineno);
    return -1;
  }
  p->nlabels++;
  return 0;
}

// a label and its position, for finding duplicates by sorting
typedef struct labelRef_ {
  const char* s;  // the label
  int index;      // its column, 0-based
} labelRef;

static int cmp_label_ref(const void* a, const void* b) {
  const labelRef* x = a;
  const labelRef* y = b;
  int c = strcmp(x->s, y->s);
  return c ? c : (x->index > y->index) - (x->index < y->index);
}

// first duplicate among n labels (n log n; a line may hold 10^5 labels): 1 and the two
// columns when found, 0 when all differ, -1 out of memory
static int find_duplicate(const char* const* labels, int n, int* first, int* second) {
  if (n < 2) {
    return 0;
  }
  labelRef* refs = malloc((size_t)n * sizeof(labelRef));
  if (!refs) {
    return -1;
  }
  for (int k = 0; k < n; k++) {
    refs[k].s = labels[k];
    refs[k].index = k;
  }
  qsort(refs, (size_t)n, sizeof(labelRef), cmp_label_ref);
  int found = 0;
  for (int k = 1; k < n && !found; k++) {
    if (strcmp(refs[k - 1].s, refs[k].s) == 0) {
      *first = refs[k - 1].index;
      *second = refs[k].index;
      found = 1;
    }
  }
  free(refs);
  return found;
}

// split the label line with separator sep and validate the labels
static int read_labels(parser* p, char sep, int strip_quotes, char* err, int errsz) {
  const char* name = p->r.name;
  int line = p->r.lineno;
  int cap = 0;
  p->labels_line = line;
  tokenizer tk = {p->r.line, sep, 0};
  for (char* s = next_cell(&tk); s; s = next_cell(&tk)) {
    size_t n = strlen(s);
    if (strip_quotes && n >= 2 && s[0] == '"' && s[n - 1] == '"') {
      s[n - 1] = '\0';
      s = trim(s + 1);
    }
    if (*s == '\0') {
      gs_error_set(err, errsz, "%s:%d: empty column label (column %d)", name, line, p->nlabels + 1);
      return -1;
    }
    if (p->nlabels >= GS_STORAGE_MAX_CELLS) {
      gs_error_set(err, errsz, "%s:%d: more than %d columns", name, line, GS_STORAGE_MAX_CELLS);
      return -1;
    }
    if (add_label(p, s, &cap, err, errsz) != 0) {
      return -1;
    }
  }

  // time first, then at least one data column, none of them called time
  if (p->nlabels == 0 || !is_time_label(p->labels[0])) {
    gs_error_set(err, errsz, "%s:%d: first column is '%.64s', expected 'time'", name, line,
            p->nlabels ? p->labels[0] : "");
    return -1;
  }
  if (p->nlabels < 2) {
    gs_error_set(err, errsz, "%s:%d: no data columns besides time", name, line);
    return -1;
  }
  for (int k = 1; k < p->nlabels; k++) {
    if (is_time_label(p->labels[k])) {
      gs_error_set(err, errsz, "%s:%d: column %d '%.64s' duplicates the time column", name, line,
              k + 1, p->labels[k]);
      return -1;
    }
  }

  // duplicates
  p->cells = malloc((size_t)p->nlabels * sizeof(char*));
  int c1 = 0, c2 = 0;
  int dup = p->cells ? find_duplicate((const char* const*)p->labels + 1, p->nlabels - 1, &c1, &c2)
                     : -1;
  if (dup < 0) {
    gs_error_set(err, errsz, "%s:%d: out of memory", name, line);
    return -1;
  }
  if (dup) {
    gs_error_set(err, errsz, "%s:%d: duplicate column '%.64s' (columns %d and %d)", name, line,
            p->labels[c2 + 1], c1 + 2, c2 + 2);
    return -1;
  }
  return 0;
}

// parse the current line as a data row with separator sep and append it
static int read_row(parser* p, char sep, char* err, int errsz) {
  const char* name = p->r.name;
  int line = p->r.lineno;
  const char* trunc = p->r.newline ? "" : " (last line has no newline: truncated file?)";

  // split; count every cell, keep the first nlabels
  tokenizer tk = {p->r.line, sep, 0};
  int n = 0;
  for (char* s = next_cell(&tk); s; s = next_cell(&tk)) {
    if (n < p->nlabels) {
      p->cells[n] = s;
    }
    n++;
  }
  if (n != p->nlabels) {
    gs_error_set(err, errsz, "%s:%d: %d cells, expected %d (too %s)%s", name, line, n, p->nlabels,
            n < p->nlabels ? "few" : "many", trunc);
    return -1;
  }

  // room for one more row, within the cell limit
  int ncol = p->nlabels - 1;
  if ((size_t)(p->nrow + 1) * (size_t)p->nlabels > GS_STORAGE_MAX_CELLS) {
    gs_error_set(err, errsz, "%s:%d: more than %d cells", name, line, GS_STORAGE_MAX_CELLS);
    return -1;
  }
  if (p->nrow == p->cap) {
    int ncap = p->cap ? 2 * p->cap : 16;
    double* nt = realloc(p->time, (size_t)ncap * sizeof(double));
    if (nt) {
      p->time = nt;
    }
    double* nd = nt ? realloc(p->data, (size_t)ncap * (size_t)ncol * sizeof(double)) : NULL;
    if (!nd) {
      gs_error_set(err, errsz, "%s:%d: out of memory", name, line);
      return -1;
    }
    p->data = nd;
    p->cap = ncap;
  }

  // numbers
  double* row = p->data + (size_t)p->nrow * ncol;
  for (int k = 0; k < n; k++) {
    double v = 0.0;
    int rc = parse_number(p->cells[k], &v);
    if (rc != 0) {
      gs_error_set(err, errsz, "%s:%d: column %d '%.64s': '%.32s' is %s%s", name, line, k + 1,
              p->labels[k], p->cells[k],
              rc == -1 ? (p->cells[k][0] ? "not a number" : "empty")
                       : "not finite (NaN, Inf or overflow)",
              trunc);
      return -1;
    }
    if (k == 0) {
      p->time[p->nrow] = v;
    } else {
      row[k - 1] = v;
    }
  }

  // time strictly increasing
  if (p->nrow > 0 && !(p->time[p->nrow] > p->time[p->nrow - 1])) {
    gs_error_set(err, errsz, "%s:%d: time %.10g is not greater than the previous time %.10g", name,
            line, p->time[p->nrow], p->time[p->nrow - 1]);
    return -1;
  }
  p->nrow++;
  return 0;
}

// parse an OpenSim storage file after the reader was set up
static int parse_storage(parser* p, char* err, int errsz) {
  lineReader* r = &p->r;
  int nrows_decl = -1, ncols_decl = -1, nrows_line = 0, ncols_line = 0, rc;
  int have_end = 0;

  // header, up to endheader
  while ((rc = next_line(r, err, errsz)) == 1) {
    char* s = trim(r->line);
    if (strcmp(s, "endheader") == 0) {
      have_end = 1;
      break;
    }
    char* eq = strchr(s, '=');
    if (r->lineno == 1 && !eq) {
      if (*s && !(p->name = gs_string_dup(s))) {
        gs_error_set(err, errsz, "%s:1: out of memory", r->name);
        return -1;
      }
      continue;
    }

    // key=value, or SIMM "datarows N"
    char *key = NULL, *val = NULL;
    if (eq) {
      *eq = '\0';
      key = trim(s);
      val = trim(eq + 1);
    } else if (strncmp(s, "datarows", 8) == 0 && is_blank_char(s[8])) {
      key = "nRows";
      val = trim(s + 8);
    } else if (strncmp(s, "datacolumns", 11) == 0 && is_blank_char(s[11])) {
      key = "nColumns";
      val = trim(s + 11);
    } else {
      continue;
    }
    if (ieq(key, "nRows") || ieq(key, "nColumns")) {
      int v = 0;
      if (parse_count(val, &v) != 0 || v > GS_STORAGE_MAX_CELLS) {
        gs_error_set(err, errsz, "%s:%d: %s '%.32s' is not a count in [0, %d]", r->name, r->lineno,
                key, val, GS_STORAGE_MAX_CELLS);
        return -1;
      }
      if (ieq(key, "nRows")) {
        nrows_decl = v;
        nrows_line = r->lineno;
      } else {
        ncols_decl = v;
        ncols_line = r->lineno;
      }
    } else if (ieq(key, "inDegrees")) {
      if (ieq(val, "yes")) {
        p->in_degrees = 1;
      } else if (ieq(val, "no")) {
        p->in_degrees = 0;
      } else {
        gs_error_set(err, errsz, "%s:%d: inDegrees must be yes or no, got '%.32s'", r->name,
                r->lineno, val);
        return -1;
      }
    } else if (ieq(key, "DataType")) {
      if (!ieq(val, "double")) {
        gs_error_set(err, errsz, "%s:%d: DataType=%.32s not supported (only double)", r->name,
                r->lineno, val);
        return -1;
      }
    }
  }
  if (rc < 0) {
    return -1;
  }
  if (!have_end) {
    gs_error_set(err, errsz, "%s:%d: missing endheader (end of file reached in the header)", r->name,
            r->lineno);
    return -1;
  }
  int end_line = r->lineno;
  if (nrows_decl >= 0 && ncols_decl >= 0 &&
      (size_t)nrows_decl * (size_t)ncols_decl > GS_STORAGE_MAX_CELLS) {
    gs_error_set(err, errsz, "%s:%d: nRows x nColumns = %d x %d exceeds %d cells", r->name,
            nrows_line, nrows_decl, ncols_decl, GS_STORAGE_MAX_CELLS);
    return -1;
  }

  // labels: the first non-blank line after endheader; tabs if it has any, else spaces
  while ((rc = next_line(r, err, errsz)) == 1 && is_blank_line(r->line)) {
  }
  if (rc < 0) {
    return -1;
  }
  if (rc == 0) {
    gs_error_set(err, errsz, "%s:%d: no column labels after endheader (line %d)", r->name,
            r->lineno, end_line);
    return -1;
  }
  if (read_labels(p, strchr(r->line, '\t') ? '\t' : 0, 0, err, errsz) != 0) {
    return -1;
  }
  if (ncols_decl >= 0 && ncols_decl != p->nlabels) {
    gs_error_set(err, errsz, "%s:%d: %d column labels but nColumns=%d (line %d)", r->name, r->lineno,
            p->nlabels, ncols_decl, ncols_line);
    return -1;
  }

  // rows
  while ((rc = next_line(r, err, errsz)) == 1) {
    if (!is_blank_line(r->line) && read_row(p, 0, err, errsz) != 0) {
      return -1;
    }
  }
  if (rc < 0) {
    return -1;
  }
  if (p->nrow == 0) {
    gs_error_set(err, errsz, "%s:%d: no data rows (header only)", r->name, r->lineno);
    return -1;
  }
  if (nrows_decl >= 0 && nrows_decl != p->nrow) {
    gs_error_set(err, errsz, "%s:%d: nRows=%d but the file has %d data rows", r->name, nrows_line,
            nrows_decl, p->nrow);
    return -1;
  }
  return 0;
}

// 1 when the line is a CSV comment
static int is_comment(const char* s) {
  while (is_blank_char(*s)) {
    s++;
  }
  return *s == '#';
}

// parse a CSV file after the reader was set up
static int parse_csv(parser* p, char* err, int errsz) {
  lineReader* r = &p->r;
  int rc;

  // header: the first line that is neither blank nor a comment
  while ((rc = next_line(r, err, errsz)) == 1 && (is_blank_line(r->line) || is_comment(r->line))) {
  }
  if (rc < 0) {
    return -1;
  }
  if (rc == 0) {
    gs_error_set(err, errsz, "%s:%d: no header line (only comments)", r->name, r->lineno);
    return -1;
  }
  if (read_labels(p, ',', 1, err, errsz) != 0) {
    return -1;
  }

  // rows
  while ((rc = next_line(r, err, errsz)) == 1) {
    if (!is_blank_line(r->line) && !is_comment(r->line) && read_row(p, ',', err, errsz) != 0) {
      return -1;
    }
  }
  if (rc < 0) {
    return -1;
  }
  if (p->nrow == 0) {
    gs_error_set(err, errsz, "%s:%d: no data rows (header only)", r->name, r->lineno);
    return -1;
  }
  return 0;
}

// 1 when [s, s+n) trimmed is "endheader"
static int is_endheader(const char* s, size_t n) {
  while (n > 0 && (is_blank_char(*s))) {
    s++;
    n--;
  }
  while (n > 0 && (is_blank_char(s[n - 1]) || s[n - 1] == '\r')) {
    n--;
  }
  return n == 9 && memcmp(s, "endheader", 9) == 0;
}

// 1 when the input is CSV: by extension, else a first non-comment line with a comma and no
// endheader line
static int looks_like_csv(const char* bytes, size_t n, const char* name) {
  const char* slash = strrchr(name, '/');
  const char* dot = strrchr(slash ? slash : name, '.');
  if (dot && ieq(dot, ".csv")) {
    return 1;
  }
  if (dot && (ieq(dot, ".sto") || ieq(dot, ".mot"))) {
    return 0;
  }
  int first = -1;
  for (size_t pos = 0; pos < n;) {
    const char* s = bytes + pos;
    const char* nl = memchr(s, '\n', n - pos);
    size_t len = nl ? (size_t)(nl - s) : n - pos;
    pos += len + 1;
    if (is_endheader(s, len)) {
      return 0;
    }
    size_t k = 0;
    while (k < len && (is_blank_char(s[k]) || s[k] == '\r')) {
      k++;
    }
    if (first < 0 && k < len && s[k] != '#') {
      first = memchr(s, ',', len) != NULL;
    }
  }
  return first == 1;
}

int gs_storage_read_buffer(const char* bytes, size_t n, const char* name_for_errors, gsTable* t,
                           char* err, int errsz) {
  const char* name = name_for_errors ? name_for_errors : "buffer";
  if (n > (size_t)GS_STORAGE_MAX_BYTES) {
    gs_error_set(err, errsz, "%s: larger than %ld bytes", name, (long)GS_STORAGE_MAX_BYTES);
    return -1;
  }

  // nothing but whitespace
  size_t k = 0;
  while (k < n && (is_blank_char(bytes[k]) || bytes[k] == '\r' || bytes[k] == '\n')) {
    k++;
  }
  if (k == n) {
    gs_error_set(err, errsz, "%s:1: empty file", name);
    return -1;
  }

  parser p;
  memset(&p, 0, sizeof(p));
  p.r.buf = bytes;
  p.r.n = n;
  p.r.name = name;
  p.r.line = malloc((n < GS_STORAGE_MAX_LINE ? n : GS_STORAGE_MAX_LINE) + 1);
  if (!p.r.line) {
    gs_error_set(err, errsz, "%s: out of memory", name);
    return -1;
  }
  int rc = looks_like_csv(bytes, n, name) ? parse_csv(&p, err, errsz)
                                          : parse_storage(&p, err, errsz);
  if (rc != 0) {
    parser_free(&p);
    return -1;
  }

  // hand the arrays over to a table
  gsTable tmp;
  gs_table_init(&tmp);
  tmp.nrow = p.nrow;
  tmp.ncol = p.nlabels - 1;
  tmp.time = p.time;
  tmp.data = p.data;
  tmp.labels = malloc((size_t)tmp.ncol * sizeof(char*));
  if (!tmp.labels) {
    gs_error_set(err, errsz, "%s: out of memory", name);
    parser_free(&p);
    return -1;
  }
  memcpy(tmp.labels, p.labels + 1, (size_t)tmp.ncol * sizeof(char*));
  free(p.labels[0]);
  free(p.labels);
  tmp.in_degrees = p.in_degrees;
  tmp.name = p.name;
  free(p.cells);
  free(p.r.line);
  gs_table_free(t);
  *t = tmp;
  return 0;
}

int gs_storage_read(const char* path, gsTable* t, char* err, int errsz) {
  FILE* f = fopen(path, "rb");
  if (!f) {
    gs_error_set(err, errsz, "%s: cannot open: %s", path, strerror(errno));
    return -1;
  }

  // slurp, in growing chunks, up to the size limit
  size_t cap = 1 << 16, n = 0;
  char* buf = malloc(cap);
  while (buf) {
    n += fread(buf + n, 1, cap - n, f);
    if (n < cap) {
      break;
    }
    if (cap > (size_t)GS_STORAGE_MAX_BYTES) {
      free(buf);
      fclose(f);
      gs_error_set(err, errsz, "%s: larger than %ld bytes", path, (long)GS_STORAGE_MAX_BYTES);
      return -1;
    }
    char* nb = realloc(buf, 2 * cap);
    if (!nb) {
      free(buf);
    }
    buf = nb;
    cap *= 2;
  }
  if (!buf) {
    fclose(f);
    gs_error_set(err, errsz, "%s: out of memory", path);
    return -1;
  }
  if (ferror(f)) {
    int saved = errno;
    free(buf);
    fclose(f);
    gs_error_set(err, errsz, "%s: read failed: %s", path, strerror(saved));
    return -1;
  }
  fclose(f);
  int rc = gs_storage_read_buffer(buf, n, path, t, err, errsz);
  free(buf);
  return rc;
}

// ---------------------------------------------------------------------------------------------
// writing
// ---------------------------------------------------------------------------------------------

// 1 when s has a character below 0x20 (tab included) or DEL
static int has_control(const char* s) {
  for (; *s; s++) {
    if ((unsigned char)*s < 0x20 || *s == 0x7f) {
      return 1;
    }
  }
  return 0;
}

// 1 when the header line would be read as one of the keys the writer sets
static int is_reserved_header(const char* line) {
  static const char* const keys[] = {"version", "nRows", "nColumns", "inDegrees", "DataType"};
  char buf[64];
  const char* eq = strchr(line, '=');
  size_t n = eq ? (size_t)(eq - line) : 0;
  if (n < sizeof(buf)) {
    memcpy(buf, line, n);
    buf[n] = '\0';
    char* key = trim(buf);
    for (size_t k = 0; k < sizeof(keys) / sizeof(keys[0]); k++) {
      if (eq && ieq(key, keys[k])) {
        return 1;
      }
    }
  }
  while (is_blank_char(*line)) {
    line++;
  }
  return (strncmp(line, "datarows", 8) == 0 && is_blank_char(line[8])) ||
         (strncmp(line, "datacolumns", 11) == 0 && is_blank_char(line[11]));
}

// 1 when the name can be the first header line and read back as the name
static int valid_name(const char* s) {
  char buf[16];
  const char* p = s;
  while (*p == ' ') {
    p++;
  }
  snprintf(buf, sizeof(buf), "%s", p);
  return *p && !has_control(s) && !strchr(s, '=') && strncmp(trim(buf), "endheader", 10) != 0;
}

// check everything the reader will check, before anything is written
static int validate(const gsTable* t, const char* name, const char* const* extra, int nextra,
                    char* err, int errsz) {
  if (t->nrow < 1 || t->ncol < 1 || !t->time || !t->data || !t->labels) {
    gs_error_set(err, errsz, "%s: table is empty (%d rows, %d columns)", name, t->nrow, t->ncol);
    return -1;
  }
  if ((size_t)t->nrow * ((size_t)t->ncol + 1) > GS_STORAGE_MAX_CELLS) {
    gs_error_set(err, errsz, "%s: table has more than %d cells", name, GS_STORAGE_MAX_CELLS);
    return -1;
  }
  if (t->name && !valid_name(t->name)) {
    gs_error_set(err, errsz, "%s: table name '%.64s' cannot be a header line", name, t->name);
    return -1;
  }

  // labels: non-empty, no whitespace, not time, unique
  for (int j = 0; j < t->ncol; j++) {
    const char* s = t->labels[j];
    if (!s || !*s || strchr(s, ' ') || has_control(s) || is_time_label(s)) {
      gs_error_set(err, errsz, "%s: column %d label '%.64s' is empty, has whitespace or is time",
              name, j + 1, s ? s : "(null)");
      return -1;
    }
  }
  int c1 = 0, c2 = 0;
  int dup = find_duplicate((const char* const*)t->labels, t->ncol, &c1, &c2);
  if (dup < 0) {
    gs_error_set(err, errsz, "%s: out of memory", name);
    return -1;
  }
  if (dup) {
    gs_error_set(err, errsz, "%s: duplicate column '%.64s' (columns %d and %d)", name, t->labels[c2],
            c1 + 1, c2 + 1);
    return -1;
  }

  // values finite, time strictly increasing
  for (int i = 0; i < t->nrow; i++) {
    if (!isfinite(t->time[i]) || (i > 0 && !(t->time[i] > t->time[i - 1]))) {
      gs_error_set(err, errsz, "%s: time %.10g at row %d is not finite or not increasing", name,
              t->time[i], i + 1);
      return -1;
    }
    for (int j = 0; j < t->ncol; j++) {
      if (!isfinite(t->data[(size_t)i * t->ncol + j])) {
        gs_error_set(err, errsz, "%s: column '%.64s' is NaN or Inf at row %d (time %.10g)", name,
                t->labels[j], i + 1, t->time[i]);
        return -1;
      }
    }
  }

  // extra header lines: one line each, not endheader, no key the writer owns
  for (int k = 0; k < nextra; k++) {
    const char* s = extra[k];
    char buf[16];
    const char* p = s;
    while (p && is_blank_char(*p)) {
      p++;
    }
    if (p) {
      snprintf(buf, sizeof(buf), "%s", p);
    }
    if (!s || strchr(s, '\n') || strchr(s, '\r') || strncmp(trim(buf), "endheader", 10) == 0 ||
        is_reserved_header(s)) {
      gs_error_set(err, errsz, "%s: extra header line %d '%.64s' is not allowed", name, k + 1,
              s ? s : "(null)");
      return -1;
    }
  }
  return 0;
}

// shortest of %.15g .. %.17g that reads back exactly
static void format_double(char* buf, size_t size, double v) {
  for (int prec = 15; prec <= 17; prec++) {
    snprintf(buf, size, "%.*g", prec, v);
    if (prec == 17 || strtod(buf, NULL) == v) {
      return;
    }
  }
}

// base name of path without extension, when it makes a valid name line
static void default_name(const char* path, char* buf, size_t size) {
  const char* slash = path ? strrchr(path, '/') : NULL;
  snprintf(buf, size, "%s", slash ? slash + 1 : (path ? path : ""));
  char* dot = strrchr(buf, '.');
  if (dot && dot != buf) {
    *dot = '\0';
  }
  if (!valid_name(buf)) {
    snprintf(buf, size, "gaitsim");
  }
}

// header, labels, rows; no validation
static void write_body(FILE* f, const char* title, const gsTable* t, const char* const* extra,
                       int nextra) {
  fprintf(f, "%s\nversion=1\nnRows=%d\nnColumns=%d\ninDegrees=%s\nDataType=double\n", title,
          t->nrow, t->ncol + 1, t->in_degrees ? "yes" : "no");
  for (int k = 0; k < nextra; k++) {
    fprintf(f, "%s\n", extra[k]);
  }
  fputs("endheader\ntime", f);
  for (int j = 0; j < t->ncol; j++) {
    fprintf(f, "\t%s", t->labels[j]);
  }
  fputc('\n', f);
  char num[40];
  for (int i = 0; i < t->nrow; i++) {
    format_double(num, sizeof(num), t->time[i]);
    fputs(num, f);
    for (int j = 0; j < t->ncol; j++) {
      format_double(num, sizeof(num), t->data[(size_t)i * t->ncol + j]);
      fputc('\t', f);
      fputs(num, f);
    }
    fputc('\n', f);
  }
}

int gs_storage_write_stream(FILE* f, const char* name_for_errors, const gsTable* t,
                            const char* const* extra_header, int nextra, char* err, int errsz) {
  const char* name = name_for_errors ? name_for_errors : "stream";
  if (validate(t, name, extra_header, nextra, err, errsz) != 0) {
    return -1;
  }
  char title[256];
  default_name(name_for_errors, title, sizeof(title));
  write_body(f, t->name ? t->name : title, t, extra_header, nextra);
  if (fflush(f) != 0 || ferror(f)) {
    gs_error_set(err, errsz, "%s: write failed: %s", name, strerror(errno));
    return -1;
  }
  return 0;
}

int gs_storage_write(const char* path, const gsTable* t, const char* const* extra_header,
                     int nextra, char* err, int errsz) {
  if (validate(t, path, extra_header, nextra, err, errsz) != 0) {
    return -1;
  }
  gsAtomicFile a;
  if (gs_atomic_open(&a, path, err, errsz) != 0) {
    return -1;
  }
  char title[256];
  default_name(path, title, sizeof(title));
  write_body(a.f, t->name ? t->name : title, t, extra_header, nextra);
  return gs_atomic_commit(&a, err, errsz);
}
