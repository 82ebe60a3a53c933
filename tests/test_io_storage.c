// test_io_storage.c: tables, OpenSim storage and CSV reading/writing, atomic output.
//
// Fixtures are generated into a mkdtemp directory; malformed inputs are parsed from memory with
// gs_storage_read_buffer, whose error messages carry "NAME:LINE:" (checked by substring).
#define _XOPEN_SOURCE 700

#include <dirent.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/gs_atomic.h"
#include "io/gs_storage.h"
#include "io/gs_table.h"
#include "tests/gs_test.h"

static char g_dir[256];  // temporary directory of this run
static char g_err[512];  // last error message

// ---------------------------------------------------------------------------------------------
// helpers
// ---------------------------------------------------------------------------------------------

// path of name inside the temporary directory (static buffer, one at a time per slot)
static const char* tmp_path(const char* name, int slot) {
  static char buf[4][512];
  snprintf(buf[slot], sizeof(buf[slot]), "%s/%s", g_dir, name);
  return buf[slot];
}

// write a fixture file
static void write_file(const char* path, const char* text) {
  FILE* f = fopen(path, "wb");
  if (f) {
    fputs(text, f);
    fclose(f);
  }
}

// whole file as a malloc'ed string, or NULL
static char* slurp(const char* path) {
  FILE* f = fopen(path, "rb");
  if (!f) {
    return NULL;
  }
  char* buf = calloc(1, 1 << 16);
  if (buf) {
    size_t n = fread(buf, 1, (1 << 16) - 1, f);
    buf[n] = '\0';
  }
  fclose(f);
  return buf;
}

// number of leftover temporary files ("*.tmp.*") in the temporary directory
static int count_tmp_files(void) {
  DIR* d = opendir(g_dir);
  int n = 0;
  struct dirent* e;
  while (d && (e = readdir(d)) != NULL) {
    if (strstr(e->d_name, ".tmp.")) {
      n++;
    }
  }
  if (d) {
    closedir(d);
  }
  return n;
}

static int rm_one(const char* path, const struct stat* sb, int flag, struct FTW* ftw) {
  return remove(path);
}

// parse text as `name`: 0 ok, -1 error (message in g_err)
static int parse(const char* text, const char* name, gsTable* t) {
  g_err[0] = '\0';
  return gs_storage_read_buffer(text, strlen(text), name, t, g_err, sizeof(g_err));
}

// the text must be rejected with a message containing both substrings
#define EXPECT_REJECT(text, name, sub1, sub2)                                           \
  do {                                                                                  \
    gsTable t_;                                                                         \
    gs_table_init(&t_);                                                                 \
    int rc_ = parse(text, name, &t_);                                                   \
    EXPECT_EQ_INT(-1, rc_);                                                             \
    EXPECT_TRUE(strstr(g_err, sub1) != NULL);                                           \
    EXPECT_TRUE(strstr(g_err, sub2) != NULL);                                           \
    EXPECT_TRUE(strchr(g_err, '\n') == NULL);                                           \
    if (!strstr(g_err, sub1) || !strstr(g_err, sub2)) {                                 \
      fprintf(stderr, "  message was: %s\n", g_err);                                    \
    }                                                                                   \
    EXPECT_EQ_INT(0, t_.nrow);                                                          \
    gs_table_free(&t_);                                                                 \
  } while (0)

// a 4 x 3 table: time 0, .1, .2, .3; a = t^2 * 100; b = 10 + 100 t; c = -t
static void make_small(gsTable* t) {
  const char* labels[] = {"a", "b", "c"};
  gs_table_create(t, 4, 3, labels, NULL, 0);
  for (int i = 0; i < 4; i++) {
    t->time[i] = 0.1 * i;
    t->data[i * 3 + 0] = (double)(i * i);
    t->data[i * 3 + 1] = 10.0 + 10.0 * i;
    t->data[i * 3 + 2] = -0.1 * i;
  }
}

// ---------------------------------------------------------------------------------------------
// reading valid files
// ---------------------------------------------------------------------------------------------

static void write_then_read_should_round_trip(void) {
  const char* labels[] = {"hip_flexion_r", "pelvis_tx", "ground_force_r_vy"};
  const double vals[] = {1.0 / 3.0, -0.0, 1e-300, 1e300, -12345.678901234567, 4.9e-324,
                         0.1,       2.5,  -7e-12, 3.0,   1e5,                 -1e-5};
  gsTable t, r;
  gs_table_init(&t);
  gs_table_init(&r);
  EXPECT_EQ_INT(0, gs_table_create(&t, 4, 3, labels, g_err, sizeof(g_err)));
  for (int i = 0; i < 4; i++) {
    t.time[i] = 0.01 * i + 1.0 / 7.0;
  }
  memcpy(t.data, vals, sizeof(vals));
  t.in_degrees = 1;
  gs_table_set_name(&t, "walk_trial", NULL, 0);
  const char* extra[] = {"gaitsim_version=0.1.0", "provenance: unit test"};
  const char* path = tmp_path("round.sto", 0);
  EXPECT_EQ_INT(0, gs_storage_write(path, &t, extra, 2, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(0, gs_storage_read(path, &r, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(4, r.nrow);
  EXPECT_EQ_INT(3, r.ncol);
  EXPECT_EQ_INT(1, r.in_degrees);
  EXPECT_TRUE(r.name && strcmp(r.name, "walk_trial") == 0);
  for (int j = 0; j < 3 && r.ncol == 3; j++) {
    EXPECT_TRUE(strcmp(r.labels[j], labels[j]) == 0);
  }
  for (int i = 0; i < 4 && r.nrow == 4; i++) {
    EXPECT_REL(t.time[i], r.time[i], 1e-9, 1e-300);
    for (int j = 0; j < 3; j++) {
      EXPECT_REL(t.data[i * 3 + j], r.data[i * 3 + j], 1e-9, 1e-300);
      EXPECT_TRUE(t.data[i * 3 + j] == r.data[i * 3 + j]);  // shortest exact formatting
    }
  }

  // the header OpenSim reads
  char* text = slurp(path);
  EXPECT_TRUE(text && strncmp(text, "walk_trial\nversion=1\nnRows=4\nnColumns=4\n", 40) == 0);
  EXPECT_TRUE(text && strstr(text, "inDegrees=yes\n") != NULL);
  EXPECT_TRUE(text && strstr(text, "provenance: unit test\nendheader\n") != NULL);
  EXPECT_TRUE(text && strstr(text, "endheader\ntime\thip_flexion_r\tpelvis_tx\t") != NULL);
  free(text);
  EXPECT_EQ_INT(0, count_tmp_files());

  // without a name, the file's base name
  gs_table_set_name(&t, NULL, NULL, 0);
  t.in_degrees = 0;
  EXPECT_EQ_INT(0, gs_storage_write(tmp_path("states.mot", 1), &t, NULL, 0, g_err, 512));
  EXPECT_EQ_INT(0, gs_storage_read(tmp_path("states.mot", 1), &r, g_err, sizeof(g_err)));
  EXPECT_TRUE(r.name && strcmp(r.name, "states") == 0);
  EXPECT_EQ_INT(0, r.in_degrees);
  gs_table_free(&t);
  gs_table_free(&r);
}

static void opensim3_mot_header_should_be_read(void) {
  const char* text =
      "Coordinates\n"
      "version=1\n"
      "nRows=3\n"
      "nColumns=3\n"
      "inDegrees=yes\n"
      "\n"
      "Units are S.I. units (second, meters, Newtons, ...)\n"
      "Angles are in degrees.\n"
      "\n"
      "endheader\n"
      "time\thip_flexion_r\tpelvis_tx\n"
      "      0.00000000\t     10.00000000\t      0.50000000\n"
      "      0.01000000\t     11.00000000\t      0.60000000\n"
      "      0.02000000\t     12.50000000\t      0.70000000\n";
  const char* path = tmp_path("coordinates.mot", 0);
  write_file(path, text);
  gsTable t;
  gs_table_init(&t);
  EXPECT_EQ_INT(0, gs_storage_read(path, &t, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(3, t.nrow);
  EXPECT_EQ_INT(2, t.ncol);
  EXPECT_EQ_INT(1, t.in_degrees);
  EXPECT_TRUE(t.name && strcmp(t.name, "Coordinates") == 0);
  EXPECT_EQ_INT(1, gs_table_column(&t, "pelvis_tx"));
  EXPECT_EQ_INT(-1, gs_table_column(&t, "time"));
  EXPECT_NEAR(12.5, t.data[2 * 2 + 0], 1e-15);
  EXPECT_NEAR(0.02, t.time[2], 1e-15);
  gs_table_free(&t);
}

static void opensim4_sto_header_should_be_read(void) {
  const char* text =
      "version=1\r\n"
      "OpenSimVersion=4.1\r\n"
      "DataType=double\r\n"
      "inDegrees=no\r\n"
      "endheader\r\n"
      "time\t/jointset/hip_r/hip_flexion_r/value\tknee_angle_r\r\n"
      "0\t0.1\t0.2\r\n"
      "0.5\t0.3\t0.4\r\n";
  gsTable t;
  gs_table_init(&t);
  EXPECT_EQ_INT(0, parse(text, "states.sto", &t));
  EXPECT_EQ_INT(2, t.nrow);
  EXPECT_EQ_INT(2, t.ncol);
  EXPECT_EQ_INT(0, t.in_degrees);
  EXPECT_TRUE(t.name == NULL);
  EXPECT_EQ_INT(0, gs_table_column(&t, "/jointset/hip_r/hip_flexion_r/value"));
  EXPECT_NEAR(0.4, t.data[3], 1e-15);
  gs_table_free(&t);
}

static void space_separated_and_simm_headers_should_be_read(void) {
  const char* text =
      "name walk\n"
      "datacolumns 3\n"
      "datarows 2\n"
      "endheader\n"
      "\n"
      "  time   a    b  \n"
      "0 1 2\n"
      "0.1   3\t 4";  // complete last line without newline
  gsTable t;
  gs_table_init(&t);
  EXPECT_EQ_INT(0, parse(text, "old.mot", &t));
  EXPECT_EQ_INT(2, t.nrow);
  EXPECT_EQ_INT(2, t.ncol);
  EXPECT_TRUE(t.ncol == 2 && strcmp(t.labels[1], "b") == 0);
  EXPECT_NEAR(4.0, t.data[3], 0.0);
  EXPECT_TRUE(t.name && strcmp(t.name, "name walk") == 0);
  gs_table_free(&t);
}

static void csv_should_be_read(void) {
  const char* text =
      "# exported by a motion capture system\n"
      "Time(sec), hip , \"knee\"\n"
      "0,1,2\n"
      "# a comment inside\n"
      "\n"
      "0.1, 3 ,4e0\n";
  gsTable t;
  gs_table_init(&t);
  EXPECT_EQ_INT(0, parse(text, "grf.csv", &t));
  EXPECT_EQ_INT(2, t.nrow);
  EXPECT_EQ_INT(2, t.ncol);
  EXPECT_TRUE(t.ncol == 2 && strcmp(t.labels[0], "hip") == 0 && strcmp(t.labels[1], "knee") == 0);
  EXPECT_NEAR(3.0, t.data[2], 0.0);
  EXPECT_EQ_INT(0, t.in_degrees);

  // detected by content without an extension; other spellings of time in seconds
  EXPECT_EQ_INT(0, parse("time,x\n0,1\n1,2\n", "buffer", &t));
  EXPECT_EQ_INT(0, parse("time (s),x\n0,1\n", "a.csv", &t));
  EXPECT_EQ_INT(0, parse("TIME[seconds],x\n0,1\n", "a.csv", &t));
  EXPECT_EQ_INT(1, t.ncol);
  gs_table_free(&t);
}

// ---------------------------------------------------------------------------------------------
// rejecting malformed files
// ---------------------------------------------------------------------------------------------

#define HDR "x\nversion=1\ninDegrees=no\nendheader\ntime\ta\tb\n"  // labels on line 5

static void malformed_storage_should_be_rejected_with_line(void) {
  EXPECT_REJECT("x\nversion=1\ntime\ta\n0\t1\n", "m.sto", "m.sto:4:", "missing endheader");
  EXPECT_REJECT(HDR "0\t1\t2\n0.1\t2\n", "m.sto", "m.sto:7:", "too few");
  EXPECT_REJECT(HDR "0\t1\t2\n0.1\t2\t3\t4\n", "m.sto", "m.sto:7:", "too many");
  EXPECT_REJECT(HDR "0\t1\t2\n0.1\tabc\t3\n", "m.sto", "m.sto:7:", "'abc' is not a number");
  EXPECT_REJECT(HDR "0\t1\t2\n0.1\t2\t1.5x\n", "m.sto", "m.sto:7:", "column 3 'b'");
  EXPECT_REJECT(HDR "0\t1\t2\n0.1\tnan\t3\n", "m.sto", "m.sto:7:", "not finite");
  EXPECT_REJECT(HDR "0\t1\t2\n0.1\t2\t-inf\n", "m.sto", "m.sto:7:", "not finite");
  EXPECT_REJECT(HDR "0\t1\t2\n0.1\t2\t1e999\n", "m.sto", "m.sto:7:", "not finite");
  EXPECT_REJECT(HDR "0\t1\t2\n0.2\t2\t3\n0.1\t4\t5\n", "m.sto", "m.sto:8:", "not greater");
  EXPECT_REJECT(HDR "0\t1\t2\n0\t2\t3\n", "m.sto", "m.sto:7:", "not greater");
  EXPECT_REJECT("x\nendheader\ntime\ta\tb\ta\n0\t1\t2\t3\n", "m.sto", "m.sto:3:",
                "duplicate column 'a' (columns 2 and 4)");
  EXPECT_REJECT("x\nendheader\ntime\ta\tTime\n0\t1\t2\n", "m.sto", "m.sto:3:",
                "duplicates the time column");
  EXPECT_REJECT("x\nendheader\nframe\ta\n0\t1\n", "m.sto", "m.sto:3:", "expected 'time'");
  EXPECT_REJECT("x\nendheader\ntime\n0\n", "m.sto", "m.sto:3:", "no data columns");
  EXPECT_REJECT("x\nendheader\ntime\t\ta\n0\t1\n", "m.sto", "m.sto:3:", "empty column label");
  EXPECT_REJECT("", "m.sto", "m.sto:1:", "empty file");
  EXPECT_REJECT(" \n\r\n\n", "m.sto", "m.sto:1:", "empty file");
  EXPECT_REJECT(HDR, "m.sto", "m.sto:5:", "no data rows");
  EXPECT_REJECT(HDR "\n\n", "m.sto", "m.sto:7:", "no data rows");
  EXPECT_REJECT("x\nendheader\n\n", "m.sto", "m.sto:3:", "no column labels");
  EXPECT_REJECT(HDR "0\t1\t2\n0.1\t2", "m.sto", "m.sto:7:", "truncated");
  EXPECT_REJECT("x\nnRows=3\nnColumns=3\nendheader\ntime\ta\tb\n0\t1\t2\n0.1\t2\t3\n", "m.sto",
                "m.sto:2:", "nRows=3 but the file has 2 data rows");
  EXPECT_REJECT("x\nnRows=1\nnColumns=2\nendheader\ntime\ta\tb\n0\t1\t2\n", "m.sto", "m.sto:5:",
                "3 column labels but nColumns=2 (line 3)");
  EXPECT_REJECT("x\nnRows=99999999999\nendheader\n", "m.sto", "m.sto:2:", "not a count");
  EXPECT_REJECT("x\nnRows=-1\nendheader\n", "m.sto", "m.sto:2:", "not a count");
  EXPECT_REJECT("x\nnRows=5000000\nnColumns=3\nendheader\n", "m.sto", "m.sto:2:",
                "exceeds 10000000 cells");
  EXPECT_REJECT("x\ninDegrees=maybe\nendheader\n", "m.sto", "m.sto:2:", "inDegrees");
  EXPECT_REJECT("x\nDataType=Vec3\nendheader\n", "m.sto", "m.sto:2:", "not supported");

  // binary content and absurd lines
  static const char nul[] = "x\nendheader\ntime\ta\n0\t1\0\n";
  gsTable t;
  gs_table_init(&t);
  EXPECT_EQ_INT(-1, gs_storage_read_buffer(nul, sizeof(nul) - 1, "n.sto", &t, g_err, 512));
  EXPECT_TRUE(strstr(g_err, "n.sto:4: NUL byte") != NULL);
  size_t big = (size_t)GS_STORAGE_MAX_LINE + 100;
  char* longline = malloc(big + 64);
  if (longline) {
    strcpy(longline, HDR "0\t1\t");
    size_t k = strlen(longline);
    memset(longline + k, '1', big);
    strcpy(longline + k + big, "\n");
    EXPECT_REJECT(longline, "m.sto", "m.sto:6:", "longer than 1048576 bytes");
    free(longline);
  }
}

static void malformed_csv_should_be_rejected_with_line(void) {
  EXPECT_REJECT("# c\ntime,a\n0,1\n0.1,\n", "m.csv", "m.csv:4:", "empty");
  EXPECT_REJECT("time,a\n0,1\n0.1,2,3\n", "m.csv", "m.csv:3:", "too many");
  EXPECT_REJECT("time,a,b\n0,1\n", "m.csv", "m.csv:2:", "too few");
  EXPECT_REJECT("time,a,a\n0,1,2\n", "m.csv", "m.csv:1:", "duplicate column 'a'");
  EXPECT_REJECT("Time(ms),a\n0,1\n", "m.csv", "m.csv:1:", "expected 'time'");
  EXPECT_REJECT("# only\n# comments\n", "m.csv", "m.csv:2:", "no header line");
  EXPECT_REJECT("time,a\n", "m.csv", "m.csv:1:", "no data rows");
  EXPECT_REJECT("time,a\n0,1\n1,x\n", "m.csv", "m.csv:3:", "'x' is not a number");

  // a last line without newline is fine when complete ("2." is a number)
  gsTable t;
  gs_table_init(&t);
  EXPECT_EQ_INT(0, parse("time,a\n0,1\n1,2.", "m.csv", &t));
  EXPECT_EQ_INT(2, t.nrow);
  gs_table_free(&t);
}

static void missing_file_should_be_reported(void) {
  gsTable t;
  gs_table_init(&t);
  EXPECT_EQ_INT(-1, gs_storage_read(tmp_path("absent.sto", 0), &t, g_err, sizeof(g_err)));
  EXPECT_TRUE(strstr(g_err, "absent.sto: cannot open") != NULL);
}

// ---------------------------------------------------------------------------------------------
// table operations
// ---------------------------------------------------------------------------------------------

static void select_should_pick_columns_by_name(void) {
  gsTable t, s;
  gs_table_init(&t);
  gs_table_init(&s);
  make_small(&t);
  const char* want[] = {"c", "a"};
  EXPECT_EQ_INT(0, gs_table_select(&t, want, 2, &s, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(2, s.ncol);
  EXPECT_EQ_INT(4, s.nrow);
  EXPECT_TRUE(strcmp(s.labels[0], "c") == 0 && strcmp(s.labels[1], "a") == 0);
  EXPECT_NEAR(-0.3, s.data[3 * 2 + 0], 1e-15);
  EXPECT_NEAR(9.0, s.data[3 * 2 + 1], 0.0);

  // a missing column is named; the output keeps its content
  const char* bad[] = {"a", "zz"};
  EXPECT_EQ_INT(-1, gs_table_select(&t, bad, 2, &s, g_err, sizeof(g_err)));
  EXPECT_TRUE(strstr(g_err, "column 'zz' not found") != NULL);
  EXPECT_EQ_INT(2, s.ncol);
  const char* twice[] = {"a", "a"};
  EXPECT_EQ_INT(-1, gs_table_select(&t, twice, 2, &s, g_err, sizeof(g_err)));

  // a deep copy is independent of its source
  gsTable c;
  gs_table_init(&c);
  gs_table_set_name(&t, "src", NULL, 0);
  EXPECT_EQ_INT(0, gs_table_copy(&t, &c, g_err, sizeof(g_err)));
  t.data[0] = 99.0;
  EXPECT_NEAR(0.0, c.data[0], 0.0);
  EXPECT_TRUE(c.name && strcmp(c.name, "src") == 0 && strcmp(c.labels[2], "c") == 0);
  gs_table_free(&c);
  EXPECT_TRUE(c.data == NULL && c.nrow == 0);

  // in place
  const char* one[] = {"b"};
  EXPECT_EQ_INT(0, gs_table_select(&t, one, 1, &t, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(1, t.ncol);
  EXPECT_NEAR(40.0, t.data[3], 0.0);
  gs_table_free(&t);
  gs_table_free(&s);
}

static void resample_should_interpolate_linearly(void) {
  gsTable t, r;
  gs_table_init(&t);
  gs_table_init(&r);
  make_small(&t);

  // a: 0 1 4 9 at t = 0 .1 .2 .3
  const double times[] = {0.05, 0.1, 0.25, 0.3};
  EXPECT_EQ_INT(0, gs_table_resample(&t, times, 4, &r, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(4, r.nrow);
  EXPECT_NEAR(0.5, r.data[0], 1e-12);
  EXPECT_NEAR(15.0, r.data[1], 1e-12);
  EXPECT_NEAR(1.0, r.data[3], 0.0);    // exact at a sample
  EXPECT_NEAR(6.5, r.data[6], 1e-12);
  EXPECT_NEAR(9.0, r.data[9], 1e-12);
  EXPECT_NEAR(-0.25, r.data[8], 1e-12);
  EXPECT_NEAR(0.25, r.time[2], 0.0);

  // exact at the last sample
  EXPECT_EQ_INT(0, gs_table_resample(&t, &t.time[3], 1, &r, g_err, sizeof(g_err)));
  EXPECT_NEAR(9.0, r.data[0], 0.0);
  EXPECT_NEAR(40.0, r.data[1], 0.0);

  // outside the range, or not increasing
  const double out[] = {0.1, 0.31};
  EXPECT_EQ_INT(-1, gs_table_resample(&t, out, 2, &r, g_err, sizeof(g_err)));
  EXPECT_TRUE(strstr(g_err, "outside the table's range") != NULL);
  const double back[] = {0.2, 0.1};
  EXPECT_EQ_INT(-1, gs_table_resample(&t, back, 2, &r, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(1, r.nrow);
  gs_table_free(&t);
  gs_table_free(&r);
}

static void cut_should_interpolate_both_ends(void) {
  gsTable t, c;
  gs_table_init(&t);
  gs_table_init(&c);
  make_small(&t);
  EXPECT_EQ_INT(0, gs_table_cut(&t, 0.05, 0.25, 0, &c, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(4, c.nrow);
  EXPECT_NEAR(0.05, c.time[0], 0.0);
  EXPECT_NEAR(0.25, c.time[3], 0.0);
  EXPECT_NEAR(0.5, c.data[0], 1e-12);
  EXPECT_NEAR(1.0, c.data[3], 0.0);
  EXPECT_NEAR(4.0, c.data[6], 0.0);
  EXPECT_NEAR(6.5, c.data[9], 1e-12);

  // shifted to start at zero
  EXPECT_EQ_INT(0, gs_table_cut(&t, 0.05, 0.25, 1, &c, g_err, sizeof(g_err)));
  EXPECT_NEAR(0.0, c.time[0], 0.0);
  EXPECT_NEAR(0.15, c.time[2], 1e-15);
  EXPECT_NEAR(0.2, c.time[3], 1e-15);

  // an end on a sample does not duplicate it
  EXPECT_EQ_INT(0, gs_table_cut(&t, 0.1, 0.25, 0, &c, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(3, c.nrow);
  EXPECT_NEAR(1.0, c.data[0], 0.0);
  EXPECT_EQ_INT(-1, gs_table_cut(&t, 0.2, 0.1, 0, &c, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(-1, gs_table_cut(&t, 0.1, 0.4, 0, &c, g_err, sizeof(g_err)));
  EXPECT_TRUE(strstr(g_err, "gs_table_cut: time 0.4 outside") != NULL);
  gs_table_free(&t);
  gs_table_free(&c);
}

static void to_radians_should_convert_angle_columns_only(void) {
  const char* labels[] = {"hip_flexion_r", "pelvis_tx", "ground_force_r_vy", "knee_angle_r_u",
                          "/jointset/ground_pelvis/pelvis_ty/value", "ground_force_r_px",
                          "/jointset/hip_r/hip_adduction_r/speed", "soleus_r/activation"};
  gsTable t;
  gs_table_init(&t);
  gs_table_create(&t, 1, 8, labels, NULL, 0);
  for (int j = 0; j < 8; j++) {
    t.data[j] = 180.0;
  }
  gs_table_to_radians(&t, NULL, NULL);  // in_degrees 0: nothing
  EXPECT_NEAR(180.0, t.data[0], 0.0);
  t.in_degrees = 1;
  gs_table_to_radians(&t, NULL, NULL);
  EXPECT_EQ_INT(0, t.in_degrees);
  const double want[] = {3.14159265358979, 180, 180, 3.14159265358979, 180, 180,
                         3.14159265358979, 180};
  for (int j = 0; j < 8; j++) {
    EXPECT_NEAR(want[j], t.data[j], 1e-12);
  }
  gs_table_to_degrees(&t, NULL, NULL);
  EXPECT_EQ_INT(1, t.in_degrees);
  EXPECT_NEAR(180.0, t.data[0], 1e-12);

  // an explicit list
  const char* list[] = {"pelvis_tx", NULL};
  gs_table_to_radians(&t, gs_table_is_angle_in_list, (void*)list);
  EXPECT_NEAR(180.0, t.data[0], 1e-12);
  EXPECT_NEAR(3.14159265358979, t.data[1], 1e-12);
  gs_table_free(&t);
}

// ---------------------------------------------------------------------------------------------
// writing and atomic output
// ---------------------------------------------------------------------------------------------

static void failed_write_should_leave_old_file_intact(void) {
  const char* path = tmp_path("keep.sto", 0);
  write_file(path, "old content\n");
  gsTable t;
  gs_table_init(&t);
  make_small(&t);

  // refused before anything is written: NaN, bad labels, bad header lines
  t.data[5] = NAN;
  EXPECT_EQ_INT(-1, gs_storage_write(path, &t, NULL, 0, g_err, sizeof(g_err)));
  EXPECT_TRUE(strstr(g_err, "column 'c' is NaN or Inf at row 2") != NULL);
  t.data[5] = 0.0;
  t.time[2] = t.time[1];
  EXPECT_EQ_INT(-1, gs_storage_write(path, &t, NULL, 0, g_err, sizeof(g_err)));
  t.time[2] = 0.2;
  const char* hdr1[] = {"nRows=7"};
  const char* hdr2[] = {"endheader"};
  const char* hdr3[] = {"two\nlines"};
  EXPECT_EQ_INT(-1, gs_storage_write(path, &t, hdr1, 1, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(-1, gs_storage_write(path, &t, hdr2, 1, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(-1, gs_storage_write(path, &t, hdr3, 1, g_err, sizeof(g_err)));
  free(t.labels[1]);
  t.labels[1] = malloc(8);
  strcpy(t.labels[1], "a");
  EXPECT_EQ_INT(-1, gs_storage_write(path, &t, NULL, 0, g_err, sizeof(g_err)));
  EXPECT_TRUE(strstr(g_err, "duplicate column 'a'") != NULL);
  strcpy(t.labels[1], "b c");
  EXPECT_EQ_INT(-1, gs_storage_write(path, &t, NULL, 0, g_err, sizeof(g_err)));
  strcpy(t.labels[1], "b");

  // opened, written, then abandoned
  gsAtomicFile a;
  EXPECT_EQ_INT(0, gs_atomic_open(&a, path, g_err, sizeof(g_err)));
  fputs("half a fi", a.f);
  EXPECT_EQ_INT(1, count_tmp_files());
  gs_atomic_abort(&a);

  char* text = slurp(path);
  EXPECT_TRUE(text && strcmp(text, "old content\n") == 0);
  free(text);
  EXPECT_EQ_INT(0, count_tmp_files());

  // rename fails (the target is a directory): temporary removed, directory kept
  const char* dirpath = tmp_path("adir", 1);
  EXPECT_EQ_INT(0, gs_mkdir_p(dirpath, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(-1, gs_storage_write(dirpath, &t, NULL, 0, g_err, sizeof(g_err)));
  EXPECT_TRUE(strstr(g_err, "cannot rename") != NULL);
  EXPECT_EQ_INT(0, count_tmp_files());
  struct stat st;
  EXPECT_TRUE(stat(dirpath, &st) == 0 && S_ISDIR(st.st_mode));

  // a directory that does not exist
  EXPECT_EQ_INT(-1, gs_storage_write(tmp_path("nodir/x.sto", 2), &t, NULL, 0, g_err, 512));
  EXPECT_TRUE(strstr(g_err, "cannot create temporary file") != NULL);

  // a read-only directory (not for root, who may write anywhere)
  if (geteuid() != 0) {
    const char* ro = tmp_path("ro", 2);
    gs_mkdir_p(ro, NULL, 0);
    char target[600];
    snprintf(target, sizeof(target), "%s/x.sto", ro);
    write_file(target, "old\n");
    chmod(ro, 0555);
    EXPECT_EQ_INT(-1, gs_storage_write(target, &t, NULL, 0, g_err, sizeof(g_err)));
    chmod(ro, 0755);
    text = slurp(target);
    EXPECT_TRUE(text && strcmp(text, "old\n") == 0);
    free(text);
  }

  // and a good write replaces it
  EXPECT_EQ_INT(0, gs_storage_write(path, &t, NULL, 0, g_err, sizeof(g_err)));
  text = slurp(path);
  EXPECT_TRUE(text && strncmp(text, "keep\nversion=1\n", 15) == 0);
  free(text);
  gs_table_free(&t);
}

static void write_stream_should_use_the_default_name(void) {
  gsTable t, r;
  gs_table_init(&t);
  gs_table_init(&r);
  make_small(&t);
  char* buf = NULL;
  size_t n = 0;
  FILE* f = open_memstream(&buf, &n);
  EXPECT_EQ_INT(0, gs_storage_write_stream(f, "out/grf.mot", &t, NULL, 0, g_err, 512));
  fclose(f);
  EXPECT_TRUE(buf && strncmp(buf, "grf\nversion=1\nnRows=4\nnColumns=4\ninDegrees=no\n", 44) == 0);
  EXPECT_EQ_INT(0, gs_storage_read_buffer(buf, n, "grf.mot", &r, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(4, r.nrow);
  EXPECT_NEAR(0.1, r.time[1], 0.0);
  free(buf);
  gs_table_free(&t);
  gs_table_free(&r);
}

static void atomic_buffer_and_mkdir_p_should_work(void) {
  const char* path = tmp_path("a/b/c", 0);
  EXPECT_EQ_INT(0, gs_mkdir_p(path, g_err, sizeof(g_err)));
  EXPECT_EQ_INT(0, gs_mkdir_p(path, g_err, sizeof(g_err)));  // exists: fine
  const char* file = tmp_path("a/b/c/summary.json", 1);
  EXPECT_EQ_INT(0, gs_atomic_write_buffer(file, "{}\n", 3, g_err, sizeof(g_err)));
  char* text = slurp(file);
  EXPECT_TRUE(text && strcmp(text, "{}\n") == 0);
  free(text);
  struct stat st;
  EXPECT_TRUE(stat(file, &st) == 0 && (st.st_mode & 0777) == 0644);

  // a component that is a file
  EXPECT_EQ_INT(-1, gs_mkdir_p(tmp_path("a/b/c/summary.json/d", 2), g_err, sizeof(g_err)));
  EXPECT_TRUE(strstr(g_err, "cannot create directory") != NULL);
}

int main(void) {
  snprintf(g_dir, sizeof(g_dir), "/tmp/gs_test_io_XXXXXX");
  const char* base = getenv("TMPDIR");
  if (base && *base) {
    snprintf(g_dir, sizeof(g_dir), "%s/gs_test_io_XXXXXX", base);
  }
  if (!mkdtemp(g_dir)) {
    fprintf(stderr, "cannot create a temporary directory\n");
    return 1;
  }

  write_then_read_should_round_trip();
  opensim3_mot_header_should_be_read();
  opensim4_sto_header_should_be_read();
  space_separated_and_simm_headers_should_be_read();
  csv_should_be_read();
  malformed_storage_should_be_rejected_with_line();
  malformed_csv_should_be_rejected_with_line();
  missing_file_should_be_reported();
  select_should_pick_columns_by_name();
  resample_should_interpolate_linearly();
  cut_should_interpolate_both_ends();
  to_radians_should_convert_angle_columns_only();
  failed_write_should_leave_old_file_intact();
  write_stream_should_use_the_default_name();
  atomic_buffer_and_mkdir_p_should_work();

  nftw(g_dir, rm_one, 16, FTW_DEPTH | FTW_PHYS);
  return GS_TEST_RESULT();
}
