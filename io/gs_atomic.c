// gs_atomic.c: atomic file output (temporary file + fsync + rename) and mkdir -p.
#define _POSIX_C_SOURCE 200809L

#include "io/gs_atomic.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
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
  a->f = NULL;
  a->path = NULL;
  a->tmppath = NULL;
}

int gs_atomic_open(gsAtomicFile* a, const char* path, char* err, int errsz) {
  a->f = NULL;
  a->path = NULL;
  a->tmppath = NULL;
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

  a->f = fdopen(fd, "wb");
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
  if (!failed && fsync(fileno(a->f)) != 0) {
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
    gs_error_set(err, errsz, "%s: write failed: %s", path, strerror(errno));
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

int gs_mkdir_p(const char* path, char* err, int errsz) {
  if (!path || !path[0]) {
    gs_error_set(err, errsz, "gs_mkdir_p: empty path");
    return -1;
  }
  char* buf = gs_string_dup(path);
  if (!buf) {
    gs_error_set(err, errsz, "%s: out of memory", path);
    return -1;
  }

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
