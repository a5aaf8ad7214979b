/* Internal helpers shared by the library's source files (not installed). */
#ifndef ULAM_INTERNAL_H
#define ULAM_INTERNAL_H

#include "ulam.h"

#include <stdarg.h>

/* Record a failure in err (which may be NULL) and return status. */
int ulam__fail(ulam_error *err, int status, long line, int64_t index, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* Reset err (which may be NULL) to "no error". */
void ulam__clear(ulam_error *err);

/* malloc of n items of size sz, NULL on overflow or failure (n == 0 allocates one byte). */
void *ulam__malloc(size_t n, size_t sz);

/* calloc of n items of size sz, NULL on failure (n == 0 allocates one byte). */
void *ulam__calloc(size_t n, size_t sz);

/* An output file written under a temporary name and renamed into place on commit. */
typedef struct ulam__outfile {
    FILE *f;
    char *path;
    char *tmp;
} ulam__outfile;

/* Open a temporary file beside path; ULAM_EIO if that fails. */
int ulam__out_open(ulam__outfile *o, const char *path);

/* Flush, close and rename into place; on any error remove the temporary file. */
int ulam__out_commit(ulam__outfile *o);

/* Close and remove the temporary file, leaving any old file at path intact. */
void ulam__out_abort(ulam__outfile *o);

#endif
