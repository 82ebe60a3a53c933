// gs_storage.h: read and write OpenSim storage files (.sto, .mot) and CSV tables.
//
// Reading (gs_storage_read, gs_storage_read_buffer) accepts
//  - OpenSim 3 and 4 storage files: header lines up to a line "endheader": an optional first
//    line that is the table name (a line without '='), key=value lines (version, nRows,
//    nColumns, inDegrees=yes|no (absent means no), DataType=double, anything else ignored), SIMM
//    style "datarows N" / "datacolumns N", and free text; then a label line whose first label is
//    "time"; then one row per sample. Labels are separated by tabs (or by spaces when the line
//    has no tab); numbers by any run of tabs and spaces. nColumns counts the time column (as
//    OpenSim 3 and 4 write it) and nRows the data rows; both are checked against the data.
//  - CSV: lines starting with '#' are comments; the first other line is the header, separated by
//    commas (labels trimmed, one pair of surrounding double quotes removed); its first label is
//    the time: "time" or "Time" optionally followed by a unit in seconds, e.g. "Time(sec)",
//    "time (s)", "time[s]" (other units are refused). Values separated by commas. CSV has no
//    inDegrees: the table gets in_degrees 0 and no name; set them yourself.
// The format is chosen by the name's extension (.csv; .sto or .mot), else by the content: a
// line "endheader" means storage, otherwise a first non-comment line with a comma means CSV.
//
// Validation (each an error "NAME:LINE: reason"): missing endheader, missing or bad labels,
// duplicate column names, rows with too few or too many cells, non-numeric cells (strtod must
// consume the whole cell), NaN or Inf, time not strictly increasing, nRows/nColumns disagreeing
// with the data, empty or header-only files, a last line without newline that is incomplete,
// NUL bytes, lines longer than GS_STORAGE_MAX_LINE bytes, more than GS_STORAGE_MAX_CELLS cells.
// Blank lines are skipped. Numbers are parsed with strtod in the C locale (the library never
// calls setlocale; a program that does must keep LC_NUMERIC "C").
//
// Writing (gs_storage_write) produces what OpenSim 4 (and 3) opens:
//   NAME / version=1 / nRows=R / nColumns=C+1 / inDegrees=yes|no / DataType=double /
//   [caller's extra header lines] / endheader / time<TAB>label... / rows, tab separated,
// numbers in the shortest of %.15g, %.16g, %.17g that reads back to the same double (exact
// round trip). The file is written atomically (gs_atomic.h); the table is validated first
// (finite values, strictly increasing time, labels without whitespace, unique), so a bad table
// never touches the target.
//
// Errors: 0 on success, -1 on failure with one line in err (errsz bytes; err may be NULL).
// The output table must be initialized (gs_table_init) and keeps its old content on failure.
#ifndef GAITSIM_IO_GS_STORAGE_H_
#define GAITSIM_IO_GS_STORAGE_H_

#include <stddef.h>
#include <stdio.h>

#include "io/gs_table.h"

#define GS_STORAGE_MAX_LINE (1 << 20)    // longest accepted line            (bytes)
#define GS_STORAGE_MAX_CELLS 10000000    // most cells, time column included (count)
#define GS_STORAGE_MAX_BYTES (1L << 30)  // largest accepted file            (bytes)

// Read a .sto/.mot/.csv file into t.
int gs_storage_read(const char* path, gsTable* t, char* err, int errsz);

// Parse n bytes (need not be NUL-terminated; may contain anything) as a file called
// name_for_errors (its extension picks the format as above; NULL means "buffer").
int gs_storage_read_buffer(const char* bytes, size_t n, const char* name_for_errors, gsTable* t,
                           char* err, int errsz);

// Write t as an OpenSim storage file to path, atomically. extra_header: nextra lines put before
// endheader (e.g. "gaitsim_version=0.1.0", provenance); each must be one line, not "endheader",
// and not one of the keys written here. The name line is t->name, or the file's base name
// without extension when t->name is NULL.
int gs_storage_write(const char* path, const gsTable* t, const char* const* extra_header,
                     int nextra, char* err, int errsz);

// The same to an open stream (not atomic; e.g. stdout). name_for_errors labels messages and
// gives the default table name.
int gs_storage_write_stream(FILE* f, const char* name_for_errors, const gsTable* t,
                            const char* const* extra_header, int nextra, char* err, int errsz);

#endif  // GAITSIM_IO_GS_STORAGE_H_
