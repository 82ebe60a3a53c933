// gs_atomic.h: atomic file output and directory creation.
//
// Every output file of gaitsim is written to a temporary file in the target's directory
// (`path.tmp.XXXXXX`, created by mkstemp), flushed to disk (fflush + fsync) and renamed over the
// target. rename() within one directory is atomic on POSIX file systems, so a reader sees either
// the old file or the complete new one, and a crash never leaves half a file under the final
// name. On any error the temporary file is removed and an existing target is left untouched.
// A symbolic link at the target path is replaced by the new file, not followed.
//
// Errors: functions return 0 on success and -1 on failure, and then write one line
// "PATH: reason" into err (errsz bytes, always NUL-terminated when errsz > 0; err may be NULL).
// Nothing is printed and nothing exits.
#ifndef GAITSIM_IO_GS_ATOMIC_H_
#define GAITSIM_IO_GS_ATOMIC_H_

#include <stddef.h>
#include <stdio.h>

// An output file being written: open with gs_atomic_open, write to `f`, then either
// gs_atomic_commit (publish) or gs_atomic_abort (discard). Both release everything.
typedef struct gsAtomicFile_ {
  FILE* f;        // stream to write to (the temporary file); NULL when not open
  char* path;     // final path (owned)
  char* tmppath;  // temporary path in the same directory, path.tmp.XXXXXX (owned)
} gsAtomicFile;

// Create the temporary file for `path`. The new file gets the mode of an existing target, else
// 0644. On failure nothing is left on disk and `a` is zeroed.
int gs_atomic_open(gsAtomicFile* a, const char* path, char* err, int errsz);

// Flush, fsync and close the temporary file, then rename it over the target (and fsync the
// directory, best effort). On failure the temporary file is removed and the target untouched.
// Always releases `a`.
int gs_atomic_commit(gsAtomicFile* a, char* err, int errsz);

// Close and remove the temporary file; the target is untouched. Safe on a zeroed struct.
void gs_atomic_abort(gsAtomicFile* a);

// Write n bytes atomically to path (open + fwrite + commit).
int gs_atomic_write_buffer(const char* path, const void* bytes, size_t n, char* err, int errsz);

// Create directory `path` and its missing parents (mode 0777 minus umask), like `mkdir -p`.
// Succeeds when the directory already exists; fails when a component exists and is not a
// directory.
int gs_mkdir_p(const char* path, char* err, int errsz);

#endif  // GAITSIM_IO_GS_ATOMIC_H_
