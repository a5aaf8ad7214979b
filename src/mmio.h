/* The Matrix Market reader's privates (src/mmio.c).  Internal. */
#ifndef ULAM_MMIO_H
#define ULAM_MMIO_H

#include "internal.h"

#include <stdio.h>

/* A coordinate Matrix Market file's header, for reading its entries by byte ranges: order n
 * (square), declared entries, field and symmetry (src/mmio.c's enums), the byte after the size
 * line, the file's size, and the lines up to the size line. */
typedef struct {
    int64_t n, nnz;
    int field, symmetry;
    int64_t data, end;
    long lines;
} ulam__mm_coord;

/* One entry: 0-based row and column, value. */
typedef struct {
    int32_t i, j;
    double x;
} ulam__mm_entry;

/* Read and check the header of the coordinate file at fd (src/mmio.c). */
int ulam__mm_coord_header(int fd, const char *name, ulam__mm_coord *c, ulam_error *err);

/* The first line start at or after byte at of c's entries. */
int64_t ulam__mm_line_start(int fd, const ulam__mm_coord *c, int64_t at);

/* The entries of the lines in [from, to) (see src/mmio.c). */
int ulam__mm_read_range(int fd, const ulam__mm_coord *c, int64_t from, int64_t to, int64_t limit, ulam__mm_entry **e,
                        int64_t *len, int64_t *entries, long *lines, ulam_error *err);

/* As ulam_mm_read_matrix, from an open file; name is used only in error details. */
int ulam__mm_read_matrix_file(FILE *f, const char *name, ulam_csr **A, ulam_error *err);

#endif
