// gr_image.c: PNG files (libpng) and mp4 videos (an ffmpeg child process fed on a pipe).
#include "render/gr_image.h"

#include <errno.h>
#include <fcntl.h>
#include <png.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "io/gs_atomic.h"

extern char** environ;

#define SET_ERR(...)                                 \
  do {                                               \
    if (err && errsz > 0) snprintf(err, (size_t)errsz, __VA_ARGS__); \
  } while (0)

// ---------------------------------------------------------------------------------------------
// PNG

// libpng's errors return through longjmp without printing; warnings are ignored
static void png_error_quiet(png_structp png, png_const_charp msg) {
  (void)msg;
  png_longjmp(png, 1);
}
static void png_warning_quiet(png_structp png, png_const_charp msg) {
  (void)png;
  (void)msg;
}

// libpng reports errors by longjmp; keep the setjmp frame free of locals that change after it
static int png_encode(png_structp png, png_infop info, FILE* f, png_bytep* rows, int w, int h) {
  if (setjmp(png_jmpbuf(png))) {
    return -1;
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 6);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, NULL);
  return 0;
}

int gr_png_write(const char* path, const unsigned char* rgb, int w, int h, char* err, int errsz) {
  if (w <= 0 || h <= 0) {
    SET_ERR("%s: empty image %dx%d", path, w, h);
    return -1;
  }
  png_bytep* rows = (png_bytep*)malloc((size_t)h * sizeof(png_bytep));
  if (!rows) {
    SET_ERR("%s: out of memory", path);
    return -1;
  }
  for (int r = 0; r < h; r++) rows[r] = (png_bytep)(rgb + (size_t)r * (size_t)w * 3);
  gsAtomicFile a;
  if (gs_atomic_open(&a, path, err, errsz) != 0) {
    free(rows);
    return -1;
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, png_error_quiet,
                                                png_warning_quiet);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  int status = (png && info) ? png_encode(png, info, a.f, rows, w, h) : -1;
  png_destroy_write_struct(png ? &png : NULL, info ? &info : NULL);
  free(rows);
  if (status != 0) {
    gs_atomic_abort(&a);
    SET_ERR("%s: PNG encoding failed", path);
    return -1;
  }
  return gs_atomic_commit(&a, err, errsz);
}

// decode into *out (allocated here), longjmp-safe as above
static int png_decode(png_structp png, png_infop info, FILE* f, unsigned char** out, int* w,
                      int* h) {
  if (setjmp(png_jmpbuf(png))) {
    return -1;
  }
  png_init_io(png, f);
  png_read_info(png, info);
  png_uint_32 pw = png_get_image_width(png, info), ph = png_get_image_height(png, info);
  int type = png_get_color_type(png, info), depth = png_get_bit_depth(png, info);
  if (depth != 8 || (type != PNG_COLOR_TYPE_RGB && type != PNG_COLOR_TYPE_RGBA) || pw == 0 ||
      ph == 0 || pw > 16384 || ph > 16384) {
    return -2;
  }
  if (type == PNG_COLOR_TYPE_RGBA) png_set_strip_alpha(png);
  png_read_update_info(png, info);
  *out = (unsigned char*)malloc((size_t)pw * ph * 3);
  if (!*out) {
    return -1;
  }
  for (png_uint_32 r = 0; r < ph; r++) png_read_row(png, *out + (size_t)r * pw * 3, NULL);
  *w = (int)pw;
  *h = (int)ph;
  return 0;
}

int gr_png_read(const char* path, unsigned char** rgb, int* w, int* h, char* err, int errsz) {
  *rgb = NULL;
  FILE* f = fopen(path, "rb");
  if (!f) {
    SET_ERR("%s: %s", path, strerror(errno));
    return -1;
  }
  unsigned char* out = NULL;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, png_error_quiet,
                                               png_warning_quiet);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  int status = (png && info) ? png_decode(png, info, f, &out, w, h) : -1;
  png_destroy_read_struct(png ? &png : NULL, info ? &info : NULL, NULL);
  fclose(f);
  if (status != 0) {
    free(out);
    SET_ERR("%s: %s", path, status == -2 ? "not an 8-bit RGB(A) PNG" : "not a readable PNG");
    return -1;
  }
  *rgb = out;
  return 0;
}

double gr_image_mean_abs_diff(const unsigned char* a, const unsigned char* b, int w, int h,
                              int* maxdiff) {
  size_t n = (size_t)w * (size_t)h * 3;
  double sum = 0;
  int big = 0;
  for (size_t i = 0; i < n; i++) {
    int dv = abs((int)a[i] - (int)b[i]);
    sum += dv;
    if (dv > big) big = dv;
  }
  if (maxdiff) *maxdiff = big;
  return n ? sum / (double)n : 0;
}

// ---------------------------------------------------------------------------------------------
// ffmpeg

int gr_find_program(const char* name, char* path, int size) {
  const char* env = getenv("PATH");
  if (!env || !*env) env = "/usr/bin:/bin";
  while (*env) {
    const char* colon = strchr(env, ':');
    size_t len = colon ? (size_t)(colon - env) : strlen(env);
    if (len > 0 && snprintf(path, (size_t)size, "%.*s/%s", (int)len, env, name) < size &&
        access(path, X_OK) == 0) {
      struct stat st;
      if (stat(path, &st) == 0 && S_ISREG(st.st_mode)) return 0;
    }
    env += len + (colon ? 1 : 0);
  }
  return -1;
}

// newly allocated "DIR/.BASE<suffix>" for path "DIR/BASE"
static char* sibling_name(const char* path, const char* suffix) {
  const char* slash = strrchr(path, '/');
  size_t dirlen = slash ? (size_t)(slash - path + 1) : 0;
  size_t n = strlen(path) + strlen(suffix) + 2;
  char* s = (char*)malloc(n);
  if (s) snprintf(s, n, "%.*s.%s%s", (int)dirlen, path, path + dirlen, suffix);
  return s;
}

static void video_release(grVideo* v) {
  free(v->path);
  free(v->tmppath);
  if (v->logpath) {
    unlink(v->logpath);
    free(v->logpath);
  }
  memset(v, 0, sizeof(*v));
}

// first line of ffmpeg's log, for the error message
static void log_first_line(const char* logpath, char* line, size_t n) {
  line[0] = 0;
  FILE* f = logpath ? fopen(logpath, "r") : NULL;
  if (f) {
    if (fgets(line, (int)n, f)) line[strcspn(line, "\r\n")] = 0;
    fclose(f);
  }
}

int gr_video_open(grVideo* v, const char* ffmpeg, const char* path, int w, int h, int fps,
                  char* err, int errsz) {
  memset(v, 0, sizeof(*v));
  if (w <= 0 || h <= 0 || (w % 2) || (h % 2) || fps <= 0) {
    SET_ERR("%s: video size %dx%d must be positive and even, fps %d positive", path, w, h, fps);
    return -1;
  }
  v->path = strdup(path);
  v->tmppath = sibling_name(path, ".tmp.XXXXXX");
  const char* tmpdir = getenv("TMPDIR");
  size_t loglen = strlen(tmpdir && *tmpdir ? tmpdir : "/tmp") + 32;
  v->logpath = (char*)malloc(loglen);
  if (!v->path || !v->tmppath || !v->logpath) {
    video_release(v);
    SET_ERR("%s: out of memory", path);
    return -1;
  }
  snprintf(v->logpath, loglen, "%s/gaitsim-ffmpeg.XXXXXX", tmpdir && *tmpdir ? tmpdir : "/tmp");
  int tfd = mkstemp(v->tmppath);
  if (tfd < 0) {
    SET_ERR("%s: cannot create a temporary file in its folder: %s", path, strerror(errno));
    free(v->tmppath);
    v->tmppath = NULL;
    video_release(v);
    return -1;
  }
  mode_t mask = umask(0);  // the video gets 0666 minus umask, like any created file
  umask(mask);
  fchmod(tfd, 0666 & ~mask);
  close(tfd);
  int lfd = mkstemp(v->logpath);
  if (lfd < 0) {
    free(v->logpath);
    v->logpath = NULL;
  }
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    SET_ERR("%s: pipe: %s", path, strerror(errno));
    if (lfd >= 0) close(lfd);
    gr_video_abort(v);
    return -1;
  }
  char size[32], rate[16];
  snprintf(size, sizeof(size), "%dx%d", w, h);
  snprintf(rate, sizeof(rate), "%d", fps);
  char* args[] = {(char*)ffmpeg, "-nostdin", "-hide_banner", "-loglevel", "error", "-y",
                  "-f", "rawvideo", "-pixel_format", "rgb24", "-video_size", size,
                  "-framerate", rate, "-i", "pipe:0", "-c:v", "libx264", "-preset", "veryfast",
                  "-crf", "20", "-pix_fmt", "yuv420p", "-movflags", "+faststart", "-f", "mp4",
                  v->tmppath, NULL};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, fds[0], 0);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  if (lfd >= 0) {
    posix_spawn_file_actions_adddup2(&fa, lfd, 2);
  } else {
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  }
  // "-nostdin" stops ffmpeg reading keys from the terminal; stdin is our pipe
  int rc = posix_spawn(&v->pid, ffmpeg, &fa, NULL, args, environ);
  posix_spawn_file_actions_destroy(&fa);
  close(fds[0]);
  if (lfd >= 0) close(lfd);
  if (rc != 0) {
    v->pid = 0;
    close(fds[1]);
    SET_ERR("%s: cannot start %s: %s", path, ffmpeg, strerror(rc));
    gr_video_abort(v);
    return -1;
  }
  // a dying ffmpeg must give an error on write, not kill us with SIGPIPE
  signal(SIGPIPE, SIG_IGN);
  v->pipe = fdopen(fds[1], "wb");
  if (!v->pipe) {
    close(fds[1]);
    SET_ERR("%s: fdopen: %s", path, strerror(errno));
    gr_video_abort(v);
    return -1;
  }
  v->width = w;
  v->height = h;
  return 0;
}

int gr_video_write(grVideo* v, const unsigned char* rgb, char* err, int errsz) {
  size_t n = (size_t)v->width * (size_t)v->height * 3;
  if (!v->pipe || fwrite(rgb, 1, n, v->pipe) != n) {
    char line[256];
    log_first_line(v->logpath, line, sizeof(line));
    SET_ERR("%s: ffmpeg stopped reading frames after %ld%s%s", v->path ? v->path : "video",
            v->nframes, line[0] ? ": " : "", line);
    return -1;
  }
  v->nframes++;
  return 0;
}

// wait for the child; its exit status, or -1
static int wait_child(pid_t pid) {
  int st;
  while (waitpid(pid, &st, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

int gr_video_commit(grVideo* v, char* err, int errsz) {
  int ok = v->pipe && fclose(v->pipe) == 0;
  v->pipe = NULL;
  int code = v->pid ? wait_child(v->pid) : -1;
  v->pid = 0;
  if (!ok || code != 0) {
    char line[256];
    log_first_line(v->logpath, line, sizeof(line));
    SET_ERR("%s: ffmpeg failed (exit %d)%s%s", v->path, code, line[0] ? ": " : "", line);
    gr_video_abort(v);
    return -1;
  }
  if (rename(v->tmppath, v->path) != 0) {
    SET_ERR("%s: rename: %s", v->path, strerror(errno));
    gr_video_abort(v);
    return -1;
  }
  video_release(v);
  return 0;
}

void gr_video_abort(grVideo* v) {
  if (v->pipe) {
    fclose(v->pipe);
    v->pipe = NULL;
  }
  if (v->pid > 0) {
    kill(v->pid, SIGTERM);
    wait_child(v->pid);
    v->pid = 0;
  }
  if (v->tmppath) unlink(v->tmppath);
  video_release(v);
}
