// gs_atomic.h: atomic file and folder output, and directory creation.
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
  void* sink;     // the stream's file descriptor and the errno of its first failed write, so
                  // that a full disk is reported as ENOSPC, not as a bare stream error (owned)
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

// --- whole folders ------------------------------------------------------------------------------
//
// A result folder (a solution: states.sto, ..., summary.json) is written as a whole: into a
// temporary folder beside it (`PARENT/.NAME.tmp.XXXXXX`, created by mkdtemp), which then replaces
// the target in one step: rename() when the target does not exist, else an atomic exchange
// (renameat2 RENAME_EXCHANGE; on a file system without it, two renames with a moment in between
// where the target is absent) after which the old folder is removed. A reader sees the old
// complete folder or the new complete one, never a mix, and a failed run leaves neither an empty
// folder nor old and new files side by side.

// A folder being written: write files into `staging`, then gs_folder_commit or gs_folder_abort.
typedef struct gsFolderTx_ {
  char* path;     // final folder (owned)
  char* staging;  // temporary folder beside it, PARENT/.NAME.tmp.XXXXXX (owned); NULL: not open
  char* made;     // the first parent folder this transaction created (removed on abort), or NULL
} gsFolderTx;

// May the folder at path be replaced by a new result? Yes when it does not exist, is empty, or
// holds `marker` (e.g. "summary.json": an earlier result). Otherwise -1 with the reason (a file,
// or a folder that is not a result: nothing of it is touched).
int gs_folder_replaceable(const char* path, const char* marker, char* err, int errsz);

// Create the temporary folder for path (and path's missing parents). On failure nothing is left
// on disk and tx is zeroed.
int gs_folder_begin(gsFolderTx* tx, const char* path, char* err, int errsz);

// Sync the temporary folder and put it in place of path; the old folder, if any, is removed.
// On failure the temporary folder is removed and path is as it was. Always releases tx.
int gs_folder_commit(gsFolderTx* tx, char* err, int errsz);

// For a single file at path written as a whole with its companions (e.g. a video and the
// temporary files of its encoder): write it as staging/BASENAME (BASENAME: path's last
// component), then this renames it over path and removes the temporary folder with whatever
// else is in it. On failure the temporary folder is removed and path is as it was. Always
// releases tx.
int gs_folder_commit_file(gsFolderTx* tx, char* err, int errsz);

// Remove the temporary folder (and parents this transaction created); path is untouched. Safe
// on a zeroed or released tx.
void gs_folder_abort(gsFolderTx* tx);

// From a signal handler: remove the open transactions' temporary folders with everything in
// them (three levels of folders deep: a sweep's folder holds its solves' folders), innermost
// first, with async-signal-safe calls only (open, getdents64, unlinkat). Nothing when no
// transaction is open. Up to 4 transactions may be open at once (nested: a sweep and its solve;
// side by side: a video and its frames); only one of them is committed or aborted at a time.
void gs_folder_abort_from_signal(void);

// For a command that stops at once on a signal (render): SIGINT, SIGTERM and SIGHUP write
// `line` (one line, newline added) on stderr, remove the open transactions' temporary folders
// (gs_folder_abort_from_signal) and end the process by that signal (exit status 128 + signal
// in a shell). Nothing when a SIGINT handler is already
// installed (e.g. the solver's stop signals, go_ipopt_install_stop_signals, when `run` renders:
// the render then completes and `run` stops after it). 0, or -1 when sigaction fails.
int gs_folder_abort_on_signals(const char* line);

// Remove path and everything below it (like rm -rf; symbolic links are removed, not followed).
int gs_remove_tree(const char* path, char* err, int errsz);

#endif  // GAITSIM_IO_GS_ATOMIC_H_
