// gs_text.c: one-line error messages and string copies (see gs_text.h).
#include "io/gs_text.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void gs_error_set(char* err, int errsz, const char* fmt, ...) {
  if (!err || errsz <= 0) {
    return;
  }
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err, (size_t)errsz, fmt, ap);
  va_end(ap);
  for (char* p = err; *p; p++) {
    if ((unsigned char)*p < 0x20 || *p == 0x7f) {
      *p = '?';
    }
  }
}

char* gs_string_dup(const char* s) {
  size_t n = strlen(s) + 1;
  char* c = malloc(n);
  if (c) {
    memcpy(c, s, n);
  }
  return c;
}
