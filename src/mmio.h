/* The Matrix Market reader's privates (src/mmio.c).  Internal. */
#ifndef ULAM_MMIO_H
#define ULAM_MMIO_H

#include "internal.h"

#include <stdio.h>

/* As ulam_mm_read_matrix_opts with reals by the C library's strtod (the same doubles, slower: the
 * reader as it was), for the reader's benchmark and tests to compare (src/mmio.c). */
int ulam__mm_read_matrix_libc(FILE *f, const char *name, const ulam_mm_opts *o, ulam_csr **A, ulam_error *err);

/* As ulam_mm_read_matrix, from an open file; name is used only in error details. */
int ulam__mm_read_matrix_file(FILE *f, const char *name, ulam_csr **A, ulam_error *err);

#endif
