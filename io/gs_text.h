// gs_text.h: the two string chores every io/ module needs: a one-line error message into a
// caller's buffer, and a heap copy of a string.
#ifndef GAITSIM_IO_GS_TEXT_H_
#define GAITSIM_IO_GS_TEXT_H_

// Format one line into err (errsz bytes; nothing when err is NULL or errsz <= 0). Control
// characters (a newline in a quoted cell, say) become '?', so the message stays one line.
void gs_error_set(char* err, int errsz, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));

// A malloc'ed copy of s (caller frees), or NULL when out of memory.
char* gs_string_dup(const char* s);

#endif  // GAITSIM_IO_GS_TEXT_H_
