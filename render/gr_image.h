// gr_image.h: what the renderer writes: PNG images (libpng) and H.264 mp4 videos through an
// ffmpeg pipe.
//
// Every output is atomic (DESIGN.md): a PNG is written to a temporary file in the target's
// folder and renamed (io/gs_atomic.h); ffmpeg writes the video to a temporary name in the
// target's folder (".NAME.tmp.XXXXXX", muxer forced to mp4) which is renamed over the target
// only when every frame went through and ffmpeg exited 0. A failed or aborted video removes its
// temporary file, so a failure never leaves a partial video under the final name.
//
// Images are 8-bit RGB, rows top-down (row 0 is the top of the picture), w x h x 3 bytes.
//
// Errors: functions return 0 on success and -1 on failure with one line in err (errsz bytes;
// err may be NULL). Nothing is printed and nothing exits.
#ifndef GAITSIM_RENDER_GR_IMAGE_H_
#define GAITSIM_RENDER_GR_IMAGE_H_

#include <stdio.h>
#include <sys/types.h>

// Write an RGB image (w x h, rows top-down) as an 8-bit PNG to path, atomically.
int gr_png_write(const char* path, const unsigned char* rgb, int w, int h, char* err, int errsz);

// Read an 8-bit RGB or RGBA PNG (alpha dropped) into a newly allocated w x h x 3 buffer (rows
// top-down; caller frees with free()). Used by the tests to compare with golden images.
int gr_png_read(const char* path, unsigned char** rgb, int* w, int* h, char* err, int errsz);

// Mean absolute difference per channel between two RGB images of w x h pixels (0..255), and
// the largest single difference in *maxdiff (may be NULL).
double gr_image_mean_abs_diff(const unsigned char* a, const unsigned char* b, int w, int h,
                              int* maxdiff);

// Full path of an executable `name` found on $PATH, into path (size bytes); 0 found, -1 not.
int gr_find_program(const char* name, char* path, int size);

// An mp4 being encoded: ffmpeg reads raw RGB frames on a pipe.
typedef struct grVideo_ {
  pid_t pid;          // ffmpeg's process id; 0 when not running
  FILE* pipe;         // write end of ffmpeg's stdin; NULL when closed
  char* path;         // final path of the video (owned)
  char* tmppath;      // temporary file ffmpeg writes, same folder (owned)
  char* logpath;      // ffmpeg's stderr, for the error message (owned)
  int width, height;  // frame size (pixels; both even, yuv420p needs it)
  long nframes;       // frames written so far (count)
} grVideo;

// Start ffmpeg (the executable at `ffmpeg`) to encode w x h frames at fps frames/s into path:
// H.264 (libx264, preset veryfast, CRF 20), yuv420p, +faststart. w and h must be even. ffmpeg's
// stderr goes to a temporary log (its first line ends up in error messages). Sets SIGPIPE to
// ignored for the process, so that an ffmpeg that dies makes gr_video_write fail instead of
// killing the caller.
int gr_video_open(grVideo* v, const char* ffmpeg, const char* path, int w, int h, int fps,
                  char* err, int errsz);

// Send one frame (w x h x 3 bytes, rows top-down).
int gr_video_write(grVideo* v, const unsigned char* rgb, char* err, int errsz);

// Close the pipe, wait for ffmpeg and rename the temporary file over the target. On failure the
// temporary file is removed and the target untouched. Always releases v.
int gr_video_commit(grVideo* v, char* err, int errsz);

// Stop ffmpeg and remove the temporary file; the target is untouched. Safe on a zeroed struct.
void gr_video_abort(grVideo* v);

#endif  // GAITSIM_RENDER_GR_IMAGE_H_
