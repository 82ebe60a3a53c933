// gs_atomic.c: atomic file output (temporary file + fsync + rename), whole-folder transactions
// and mkdir -p.

#include "io/gs_atomic.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/types.h>
#include <unistd.h>

#include "io/gs_text.h"

// directory part of path ("." when there is none), malloc'ed
static char* dir_of(const char* path) {
  const char* slash = strrchr(path, '/');
  if (!slash) {
    return gs_string_dup(".");
  }
  if (slash == path) {
    return gs_string_dup("/");
  }
  size_t n = (size_t)(slash - path);
  char* d = malloc(n + 1);
  if (d) {
    memcpy(d, path, n);
    d[n] = '\0';
  }
  return d;
}

// release the strings and zero the struct
static void release(gsAtomicFile* a) {
  free(a->path);
  free(a->tmppath);
  free(a->sink);
  a->f = NULL;
  a->path = NULL;
  a->tmppath = NULL;
  a->sink = NULL;
}

// the stream's sink: its file descriptor and the errno of the first write that failed
typedef struct {
  int fd;   // the temporary file
  int err;  // errno of the first failed write, 0 none
} atomicSink;

static ssize_t sink_write(void* cookie, const char* buf, size_t n) {
  atomicSink* s = (atomicSink*)cookie;
  size_t done = 0;
  while (done < n) {
    ssize_t w = write(s->fd, buf + done, n - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      if (!s->err) s->err = w < 0 ? errno : ENOSPC;
      return done > 0 ? (ssize_t)done : -1;
    }
    done += (size_t)w;
  }
  return (ssize_t)done;
}

static int sink_close(void* cookie) {
  atomicSink* s = (atomicSink*)cookie;
  int rc = s->fd >= 0 ? close(s->fd) : 0;
  s->fd = -1;
  return rc;
}

// the errno of a's first failed write, else fallback
static int sink_errno(const gsAtomicFile* a, int fallback) {
  const atomicSink* s = (const atomicSink*)a->sink;
  return s && s->err ? s->err : fallback;
}

int gs_atomic_open(gsAtomicFile* a, const char* path, char* err, int errsz) {
  a->f = NULL;
  a->path = NULL;
  a->tmppath = NULL;
  a->sink = NULL;
  if (!path || !path[0]) {
    gs_error_set(err, errsz, "gs_atomic_open: empty path");
    return -1;
  }

  // the temporary name lives next to the target so rename stays within one file system
  size_t n = strlen(path);
  a->path = gs_string_dup(path);
  a->tmppath = malloc(n + sizeof(".tmp.XXXXXX"));
  if (!a->path || !a->tmppath) {
    release(a);
    gs_error_set(err, errsz, "%s: out of memory", path);
    return -1;
  }
  memcpy(a->tmppath, path, n);
  memcpy(a->tmppath + n, ".tmp.XXXXXX", sizeof(".tmp.XXXXXX"));

  int fd = mkstemp(a->tmppath);
  if (fd < 0) {
    gs_error_set(err, errsz, "%s: cannot create temporary file: %s", path, strerror(errno));
    release(a);
    return -1;
  }

  // keep the mode of an existing target, else rw-r--r--
  struct stat st;
  mode_t mode = 0644;
  if (stat(path, &st) == 0 && S_ISREG(st.st_mode)) {
    mode = st.st_mode & 07777;
  }
  if (fchmod(fd, mode) != 0) {
    gs_error_set(err, errsz, "%s: cannot set mode of temporary file: %s", path, strerror(errno));
    close(fd);
    unlink(a->tmppath);
    release(a);
    return -1;
  }

  atomicSink* sink = (atomicSink*)malloc(sizeof(atomicSink));
  cookie_io_functions_t io = {NULL, sink_write, NULL, sink_close};
  if (sink) {
    sink->fd = fd;
    sink->err = 0;
    a->sink = sink;
    a->f = fopencookie(sink, "wb", io);
  }
  if (!a->f) {
    gs_error_set(err, errsz, "%s: cannot open temporary file: %s", path, strerror(errno));
    close(fd);
    unlink(a->tmppath);
    release(a);
    return -1;
  }
  return 0;
}

void gs_atomic_abort(gsAtomicFile* a) {
  if (!a) {
    return;
  }
  if (a->f) {
    fclose(a->f);
  }
  if (a->tmppath) {
    unlink(a->tmppath);
  }
  release(a);
}

int gs_atomic_commit(gsAtomicFile* a, char* err, int errsz) {
  if (!a || !a->f || !a->path || !a->tmppath) {
    gs_error_set(err, errsz, "gs_atomic_commit: file is not open");
    gs_atomic_abort(a);
    return -1;
  }

  // everything written must reach the disk before the rename publishes it
  int failed = ferror(a->f) != 0;
  int saved = EIO;
  if (!failed && fflush(a->f) != 0) {
    failed = 1;
    saved = errno;
  }
  if (!failed && fsync(((atomicSink*)a->sink)->fd) != 0) {
    failed = 1;
    saved = errno;
  }
  int rc = fclose(a->f);
  a->f = NULL;
  if (!failed && rc != 0) {
    failed = 1;
    saved = errno;
  }
  if (failed) {
    saved = sink_errno(a, saved);
    gs_error_set(err, errsz, "%s: write failed: %s", a->path, strerror(saved));
    gs_atomic_abort(a);
    return -1;
  }

  // publish
  if (rename(a->tmppath, a->path) != 0) {
    gs_error_set(err, errsz, "%s: cannot rename temporary file: %s", a->path, strerror(errno));
    gs_atomic_abort(a);
    return -1;
  }

  // make the rename itself durable; failure here does not undo a completed rename
  char* dir = dir_of(a->path);
  if (dir) {
    int dfd = open(dir, O_RDONLY);
    if (dfd >= 0) {
      fsync(dfd);
      close(dfd);
    }
    free(dir);
  }
  release(a);
  return 0;
}

int gs_atomic_write_buffer(const char* path, const void* bytes, size_t n, char* err, int errsz) {
  gsAtomicFile a;
  if (gs_atomic_open(&a, path, err, errsz) != 0) {
    return -1;
  }
  if (n > 0 && fwrite(bytes, 1, n, a.f) != n) {
    gs_error_set(err, errsz, "%s: write failed: %s", path, strerror(sink_errno(&a, errno)));
    gs_atomic_abort(&a);
    return -1;
  }
  return gs_atomic_commit(&a, err, errsz);
}

// mkdir one component; an existing directory is fine
static int mkdir_one(const char* dir, const char* full, char* err, int errsz) {
  if (mkdir(dir, 0777) == 0) {
    return 0;
  }
  int saved = errno;
  struct stat st;
  if (stat(dir, &st) == 0) {
    if (S_ISDIR(st.st_mode)) {
      return 0;
    }
    gs_error_set(err, errsz, "%s: cannot create directory: '%s' exists and is not a directory", full,
            dir);
    return -1;
  }
  gs_error_set(err, errsz, "%s: cannot create directory '%s': %s", full, dir, strerror(saved));
  return -1;
}

// a malloc'ed copy of a non-empty path, or NULL with the reason (fn: the caller's name)
static char* path_copy(const char* path, const char* fn, char* err, int errsz) {
  if (!path || !path[0]) {
    gs_error_set(err, errsz, "%s: empty path", fn);
    return NULL;
  }
  char* buf = gs_string_dup(path);
  if (!buf) gs_error_set(err, errsz, "%s: out of memory", path);
  return buf;
}

int gs_mkdir_p(const char* path, char* err, int errsz) {
  char* buf = path_copy(path, "gs_mkdir_p", err, errsz);
  if (!buf) return -1;

  // create each prefix that ends before a '/', then the whole path
  for (char* p = buf + 1; *p; p++) {
    if (*p != '/' || p[-1] == '/') {
      continue;
    }
    *p = '\0';
    int rc = mkdir_one(buf, path, err, errsz);
    *p = '/';
    if (rc != 0) {
      free(buf);
      return -1;
    }
  }
  int rc = mkdir_one(buf, path, err, errsz);
  free(buf);
  return rc;
}

// --- whole folders ------------------------------------------------------------------------------

// the open transactions' temporary folders, for gs_folder_abort_from_signal: a stack, since a
// sweep's folder holds the folders of its solves (entries [0, g_nstaging) are valid)
#define GS_MAX_OPEN_FOLDERS 4
static char g_staging[GS_MAX_OPEN_FOLDERS][4096];
static volatile sig_atomic_t g_nstaging = 0;

// register staging as open (nothing when the stack is full or the path too long)
static void staging_push(const char* staging) {
  int n = g_nstaging;
  if (n < GS_MAX_OPEN_FOLDERS && strlen(staging) < sizeof(g_staging[0])) {
    memcpy(g_staging[n], staging, strlen(staging) + 1);
    g_nstaging = n + 1;
  }
}

// drop staging, and the entries above it, from the stack
static void staging_pop(const char* staging) {
  for (int i = g_nstaging - 1; staging && i >= 0; i--)
    if (strcmp(g_staging[i], staging) == 0) {
      g_nstaging = i;
      return;
    }
}

// lstat path: 1 it exists, 0 it does not, -1 another error (with the reason)
static int lstat_entry(const char* path, struct stat* st, char* err, int errsz) {
  if (lstat(path, st) == 0) return 1;
  if (errno == ENOENT) return 0;
  gs_error_set(err, errsz, "%s: %s", path, strerror(errno));
  return -1;
}

int gs_remove_tree(const char* path, char* err, int errsz) {
  struct stat st;
  int exists = lstat_entry(path, &st, err, errsz);
  if (exists <= 0) return exists;
  if (!S_ISDIR(st.st_mode)) {
    if (unlink(path) != 0) {
      gs_error_set(err, errsz, "%s: cannot remove: %s", path, strerror(errno));
      return -1;
    }
    return 0;
  }
  DIR* d = opendir(path);
  if (!d) {
    gs_error_set(err, errsz, "%s: %s", path, strerror(errno));
    return -1;
  }
  int rc = 0;
  struct dirent* e;
  while (rc == 0 && (e = readdir(d)) != NULL) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
    size_t n = strlen(path) + strlen(e->d_name) + 2;
    char* child = malloc(n);
    if (!child) {
      gs_error_set(err, errsz, "%s: out of memory", path);
      rc = -1;
      break;
    }
    snprintf(child, n, "%s/%s", path, e->d_name);
    rc = gs_remove_tree(child, err, errsz);
    free(child);
  }
  closedir(d);
  if (rc == 0 && rmdir(path) != 0) {
    gs_error_set(err, errsz, "%s: cannot remove: %s", path, strerror(errno));
    rc = -1;
  }
  return rc;
}

int gs_folder_replaceable(const char* path, const char* marker, char* err, int errsz) {
  struct stat st;
  int exists = lstat_entry(path, &st, err, errsz);
  if (exists <= 0) return exists;
  if (!S_ISDIR(st.st_mode)) {
    gs_error_set(err, errsz, "%s: exists and is not a folder", path);
    return -1;
  }
  DIR* d = opendir(path);
  if (!d) {
    gs_error_set(err, errsz, "%s: %s", path, strerror(errno));
    return -1;
  }
  int entries = 0, has_marker = 0;
  struct dirent* e;
  while ((e = readdir(d)) != NULL) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
    entries++;
    has_marker |= strcmp(e->d_name, marker) == 0;
  }
  closedir(d);
  if (entries > 0 && !has_marker) {
    gs_error_set(err, errsz, "%s: exists and holds no %s (not an earlier result of this "
                 "command), so it is not replaced: choose another folder or remove it", path,
                 marker);
    return -1;
  }
  return 0;
}

// release the strings and zero the struct
static void folder_release(gsFolderTx* tx) {
  staging_pop(tx->staging);
  free(tx->path);
  free(tx->staging);
  free(tx->made);
  tx->path = tx->staging = tx->made = NULL;
}

// the first missing ancestor of path that mkdir -p would create (malloc'ed), or NULL
static char* first_missing(const char* path) {
  char* buf = gs_string_dup(path);
  char* found = NULL;
  struct stat st;
  while (buf && stat(buf, &st) != 0 && errno == ENOENT) {
    free(found);
    found = gs_string_dup(buf);
    char* up = dir_of(buf);
    if (!up || strcmp(up, buf) == 0) {
      free(up);
      break;
    }
    free(buf);
    buf = up;
  }
  free(buf);
  return found;
}

int gs_folder_begin(gsFolderTx* tx, const char* path, char* err, int errsz) {
  tx->path = tx->staging = tx->made = NULL;
  // the parent folder, created when missing (and removed again on abort)
  char* trimmed = path_copy(path, "gs_folder_begin", err, errsz);
  if (!trimmed) return -1;
  for (size_t n = strlen(trimmed); n > 1 && trimmed[n - 1] == '/'; n--) trimmed[n - 1] = '\0';
  tx->path = trimmed;
  char* parent = dir_of(trimmed);
  const char* base = strrchr(trimmed, '/') ? strrchr(trimmed, '/') + 1 : trimmed;
  if (!parent) {
    gs_error_set(err, errsz, "%s: out of memory", path);
    folder_release(tx);
    return -1;
  }
  char* made = first_missing(parent);
  if (gs_mkdir_p(parent, err, errsz) != 0) {
    free(parent);
    free(made);
    folder_release(tx);
    return -1;
  }
  tx->made = made;
  size_t n = strlen(parent) + strlen(base) + sizeof("/..tmp.XXXXXX");
  tx->staging = malloc(n);
  if (!tx->staging) {
    gs_error_set(err, errsz, "%s: out of memory", path);
    free(parent);
    gs_folder_abort(tx);
    return -1;
  }
  snprintf(tx->staging, n, "%s/.%s.tmp.XXXXXX", parent, base);
  free(parent);
  if (!mkdtemp(tx->staging)) {
    gs_error_set(err, errsz, "%s: cannot create temporary folder: %s", path, strerror(errno));
    free(tx->staging);
    tx->staging = NULL;
    gs_folder_abort(tx);
    return -1;
  }
  // mkdtemp makes it rwx------; a result folder gets the mode mkdir would give it
  mode_t um = umask(0);
  umask(um);
  chmod(tx->staging, 0777 & ~um);
  staging_push(tx->staging);
  return 0;
}

void gs_folder_abort(gsFolderTx* tx) {
  if (!tx) return;
  staging_pop(tx->staging);
  if (tx->staging) gs_remove_tree(tx->staging, NULL, 0);
  if (tx->made) gs_remove_tree(tx->made, NULL, 0);
  folder_release(tx);
}

// fsync a folder, best effort
static void sync_dir(const char* dir) {
  int dfd = open(dir, O_RDONLY | O_DIRECTORY);
  if (dfd >= 0) {
    fsync(dfd);
    close(dfd);
  }
}

// after a rename into place: fsync path's parent folder (best effort); tx keeps the parents it
// made, which now hold the result
static void published(gsFolderTx* tx) {
  char* parent = dir_of(tx->path);
  if (parent) sync_dir(parent);
  free(parent);
  free(tx->made);
  tx->made = NULL;
}

int gs_folder_commit(gsFolderTx* tx, char* err, int errsz) {
  if (!tx || !tx->staging || !tx->path) {
    gs_error_set(err, errsz, "gs_folder_commit: no folder open");
    gs_folder_abort(tx);
    return -1;
  }
  sync_dir(tx->staging);
  staging_pop(tx->staging);  // from here on the temporary name may hold the old folder
  // a new folder: one rename
  if (rename(tx->staging, tx->path) == 0) {
    published(tx);
    folder_release(tx);
    return 0;
  }
  int saved = errno;
  if (saved != EEXIST && saved != ENOTEMPTY && saved != EISDIR) {
    gs_error_set(err, errsz, "%s: cannot rename temporary folder: %s", tx->path, strerror(saved));
    gs_folder_abort(tx);
    return -1;
  }
  // an existing folder: exchange the two, then the temporary name holds the old one
  int rc = (int)syscall(SYS_renameat2, AT_FDCWD, tx->staging, AT_FDCWD, tx->path,
                        1 << 1 /* RENAME_EXCHANGE */);
  if (rc != 0 && (errno == EINVAL || errno == ENOSYS)) {
    // no exchange on this file system: move the old folder aside, then the new one in
    size_t n = strlen(tx->path) + sizeof(".old.XXXXXX");
    char* old = malloc(n);
    if (old) snprintf(old, n, "%s.old.XXXXXX", tx->path);
    if (old && mkdtemp(old) && rename(tx->path, old) == 0) {
      if (rename(tx->staging, tx->path) == 0) {
        gs_remove_tree(old, NULL, 0);
        free(tx->staging);
        tx->staging = NULL;
        rc = 0;
      } else {
        saved = errno;
        rename(old, tx->path);  // put the old one back
        errno = saved;
      }
    }
    free(old);
  }
  if (rc != 0) {
    gs_error_set(err, errsz, "%s: cannot replace folder: %s", tx->path, strerror(errno));
    gs_folder_abort(tx);
    return -1;
  }
  published(tx);
  // the old folder, now under the temporary name
  if (tx->staging) gs_remove_tree(tx->staging, NULL, 0);
  folder_release(tx);
  return 0;
}

int gs_folder_commit_file(gsFolderTx* tx, char* err, int errsz) {
  if (!tx || !tx->staging || !tx->path) {
    gs_error_set(err, errsz, "gs_folder_commit_file: no folder open");
    gs_folder_abort(tx);
    return -1;
  }
  const char* base = strrchr(tx->path, '/') ? strrchr(tx->path, '/') + 1 : tx->path;
  size_t n = strlen(tx->staging) + strlen(base) + 2;
  char* inner = malloc(n);
  if (!inner) {
    gs_error_set(err, errsz, "%s: out of memory", tx->path);
    gs_folder_abort(tx);
    return -1;
  }
  snprintf(inner, n, "%s/%s", tx->staging, base);
  int rc = rename(inner, tx->path);
  free(inner);
  if (rc != 0) {
    gs_error_set(err, errsz, "%s: cannot rename temporary file: %s", tx->path, strerror(errno));
    gs_folder_abort(tx);
    return -1;
  }
  published(tx);
  // the temporary folder, now empty but for what the writer left beside its file
  gs_folder_abort(tx);
  return 0;
}

// struct linux_dirent64 (getdents64(2)); glibc 2.36 has no wrapper
struct gs_dirent64 {
  unsigned long long d_ino;
  long long d_off;
  unsigned short d_reclen;
  unsigned char d_type;
  char d_name[];
};

// remove everything below the open folder dfd and close it, with async-signal-safe calls only;
// depth: how many levels of folders below it are removed too
static void remove_below_from_signal(int dfd, int depth) {
  char buf[2048] __attribute__((aligned(8)));
  // entries removed while the folder is read may be skipped: read it again until nothing is left
  for (int pass = 0, removed = 1; removed && pass < 16; pass++) {
    removed = 0;
    lseek(dfd, 0, SEEK_SET);
    long n;
    while ((n = syscall(SYS_getdents64, dfd, buf, sizeof(buf))) > 0) {
      for (long off = 0; off < n;) {
        struct gs_dirent64* e = (struct gs_dirent64*)(buf + off);
        const char* name = e->d_name;
        off += e->d_reclen;
        if (name[0] == '.' && (name[1] == 0 || (name[1] == '.' && name[2] == 0))) continue;
        if (unlinkat(dfd, name, 0) == 0) {
          removed = 1;
        } else if (depth > 0) {
          int sub = openat(dfd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW);
          if (sub >= 0) remove_below_from_signal(sub, depth - 1);
          if (unlinkat(dfd, name, AT_REMOVEDIR) == 0) removed = 1;
        }
      }
    }
  }
  close(dfd);
}

void gs_folder_abort_from_signal(void) {
  // the innermost first: a solve's folder inside a sweep's
  for (int i = g_nstaging - 1; i >= 0; i--) {
    int dfd = open(g_staging[i], O_RDONLY | O_DIRECTORY | O_NOFOLLOW);
    if (dfd >= 0) remove_below_from_signal(dfd, 3);
    rmdir(g_staging[i]);
  }
  g_nstaging = 0;
}

// the line gs_folder_abort_on_signals writes, and its length
static char g_stop_line[256];
static size_t g_stop_len = 0;

// installed with SA_RESETHAND | SA_NODEFER: the signal raised again ends the process
static void on_abort_signal(int sig) {
  ssize_t w = write(2, g_stop_line, g_stop_len);
  (void)w;
  gs_folder_abort_from_signal();
  raise(sig);
  _exit(128 + sig);
}

int gs_folder_abort_on_signals(const char* line) {
  static const int sigs[3] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction old;
  if (sigaction(SIGINT, NULL, &old) != 0) return -1;
  if ((old.sa_flags & SA_SIGINFO) || (old.sa_handler != SIG_DFL && old.sa_handler != SIG_IGN))
    return 0;  // the solver's stop signals (or another handler) are in place
  g_stop_len = (size_t)snprintf(g_stop_line, sizeof(g_stop_line), "%s\n", line);
  if (g_stop_len >= sizeof(g_stop_line)) g_stop_len = sizeof(g_stop_line) - 1;
  struct sigaction sa;
  memset(&sa, 0, sizeof(sa));
  sa.sa_handler = on_abort_signal;
  sa.sa_flags = SA_RESETHAND | SA_NODEFER;
  sigemptyset(&sa.sa_mask);
  for (int i = 0; i < 3; i++) sigaddset(&sa.sa_mask, sigs[i]);
  for (int i = 0; i < 3; i++)
    if (sigaction(sigs[i], &sa, NULL) != 0) return -1;
  return 0;
}
