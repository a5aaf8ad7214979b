/* Photometry internals shared by the goniometric table (gonio.c) and its two readers (ies.c,
 * ldt.c): a file's text with line numbers, and the table made from measured planes. */
#ifndef ULAM_PHOTO_H
#define ULAM_PHOTO_H

#include "rad.h"
#include "ulam_photometry.h"

/* The largest photometric file read (bytes). */
#define ULAM__PHOTO_MAX_BYTES (64 << 20)

/* A file's text, read whole, and a cursor in it with its line (1-based). */
typedef struct {
    char *buf;
    size_t len, pos;
    long line;
} ulam__text;

/* Read path whole into t (NUL-terminated; a NUL byte inside, or a file past
 * ULAM__PHOTO_MAX_BYTES, is refused with its line); ULAM_OK or the status in err. */
int ulam__text_read(const char *path, ulam__text *t, ulam_error *err);

/* The next line (without its CR LF), NUL-terminated in place, t->line its number; NULL at the end. */
char *ulam__text_line(ulam__text *t);

/* The symmetries a file may state about its measured C planes. */
enum {
    ULAM__SYM_NONE,     /* the planes cover the full circle */
    ULAM__SYM_ROTATION, /* one plane: the same in every C */
    ULAM__SYM_C0_C180,  /* I(C) = I(360 - C) */
    ULAM__SYM_C90_C270, /* I(C) = I(180 - C) */
    ULAM__SYM_QUADRANT  /* both */
};

/* The table from nm measured planes at angles cm[] (degrees) with ng gamma angles gm[] (ascending
 * in [0, 180]) and candela v[k * ng + j] (plane k), unfolded by sym; rated the stated lamp flux
 * (NaN: none).  ULAM_OK or ULAM_ENOMEM. */
int ulam__gonio_make(int nm, const double *cm, int ng, const double *gm, const double *v, int sym, double rated,
                     ulam_gonio **out);

#endif
