/* IES LM-63 photometric files (ANSI/IES LM-63-2002; the 1991 and 1995 layouts are the same past
 * the keywords), read from the format's specification: header lines up to TILT=; with
 * TILT=INCLUDE the lamp-to-luminaire geometry, the count of tilt angles, the angles and their
 * multiplying factors (read and checked, not applied: the luminaire is taken as photometered);
 * then, whitespace- or comma-separated across lines, the number of lamps, lumens a lamp (-1:
 * absolute photometry), the candela multiplier, the numbers of vertical and horizontal angles,
 * the photometric type (1 = C; A and B are refused), the units type, the luminous opening's
 * width, length and height, the ballast factor, the ballast-lamp photometric factor (future
 * use in 2002) and the input watts; the vertical angles, the horizontal angles, and the
 * candela values, for each horizontal angle all the vertical ones.  Every count is bounded and
 * every error names its line. */
#include "photo.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

/* The next number of t from its position (separators: whitespace and commas); its line in
 * *line.  ULAM_OK, or ULAM_ESYNTAX in err naming `what` (at the end of the file too). */
static int number(ulam__text *t, const char *what, double *x, long *line, ulam_error *err)
{
    while (t->pos < t->len && (isspace((unsigned char)t->buf[t->pos]) || t->buf[t->pos] == ',')) {
        if (t->buf[t->pos] == '\n') t->line++;
        t->pos++;
    }
    *line = t->line;
    if (t->pos >= t->len) return ulam__fail(err, ULAM_ESYNTAX, t->line, -1, "%s, got the end of the file", what);
    char *s = t->buf + t->pos, *end;
    *x = strtod(s, &end);
    size_t n = strcspn(s, " \t\r\n,");
    if (end == s || (size_t)(end - s) != n || !isfinite(*x))
        return ulam__fail(err, ULAM_ESYNTAX, t->line, -1, "%s (a finite number), got '%.*s'", what,
                          (int)(n < 40 ? n : 40), s);
    t->pos += n;
    return ULAM_OK;
}

/* The next number as an integer in [lo, hi]. */
static int integer(ulam__text *t, const char *what, long lo, long hi, long *v, ulam_error *err)
{
    double x;
    long line;
    int st = number(t, what, &x, &line, err);
    if (st) return st;
    if (x != floor(x) || x < lo || x > hi)
        return ulam__fail(err, ULAM_ERANGE, line, -1, "%s, an integer from %ld to %ld, got %.17g", what, lo, hi, x);
    *v = (long)x;
    return ULAM_OK;
}

/* The next number in [lo, hi] (positive: lo > 0 means > 0 when open). */
static int real(ulam__text *t, const char *what, double lo, double hi, int open, double *v, ulam_error *err)
{
    long line;
    int st = number(t, what, v, &line, err);
    if (st) return st;
    if (*v < lo || *v > hi || (open && *v == lo))
        return ulam__fail(err, ULAM_ERANGE, line, -1, "%s %s %g%s, got %.17g", what, open ? "above" : "at least", lo,
                          hi < 1e300 ? " and at most the range's end" : "", *v);
    return ULAM_OK;
}

/* n ascending angles in [lo, hi] into a (what: their name). */
static int angles(ulam__text *t, const char *what, long n, double lo, double hi, double *a, ulam_error *err)
{
    for (long k = 0; k < n; k++) {
        long line;
        int st = number(t, what, &a[k], &line, err);
        if (st) return st;
        if (a[k] < lo || a[k] > hi)
            return ulam__fail(err, ULAM_ERANGE, line, -1, "%s within %g .. %g degrees, got %.17g", what, lo, hi, a[k]);
        if (k && !(a[k] > a[k - 1]))
            return ulam__fail(err, ULAM_ESYNTAX, line, -1, "%s in ascending order, got %.17g after %.17g", what, a[k],
                              a[k - 1]);
    }
    return ULAM_OK;
}

/* The symmetry that type C horizontal angles h[0..n) state (LM-63-2002 4.14). */
static int symmetry(const double *h, long n, long line, int *sym, ulam_error *err)
{
    double first = h[0], last = h[n - 1];
    if (n == 1 && first == 0.0) *sym = ULAM__SYM_ROTATION;
    else if (first == 0.0 && last == 90.0) *sym = ULAM__SYM_QUADRANT;
    else if (first == 0.0 && last == 180.0) *sym = ULAM__SYM_C0_C180;
    else if (first == 90.0 && last == 270.0) *sym = ULAM__SYM_C90_C270;
    else if (first == 0.0 && last > 180.0 && last <= 360.0) *sym = ULAM__SYM_NONE;
    else
        return ulam__fail(err, ULAM_ESYNTAX, line, -1,
                          "type C horizontal angles 0 (one: symmetric about the axis), 0 .. 90, 0 .. 180, "
                          "90 .. 270 or 0 .. 360, got %g .. %g (%ld of them)",
                          first, last, n);
    return ULAM_OK;
}

/* Read an IES LM-63 file. */
int ulam_gonio_read_ies(const char *path, ulam_gonio **out, ulam_error *err)
{
    ulam__clear(err);
    if (!path || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a path and an output");
    *out = NULL;
    ulam__text t;
    int st = ulam__text_read(path, &t, err);
    if (st) return st;
    char *s, *tilt = NULL;
    long tilt_line = 0;
    while (!tilt && (s = ulam__text_line(&t))) { /* header: IESNA:LM-63-..., [KEYWORD] lines, free text */
        if (!strncmp(s, "TILT=", 5) || !strncmp(s, "TILT =", 6)) tilt = strchr(s, '=') + 1, tilt_line = t.line;
        else if (t.line > 10000) break;
    }
    double *va = NULL, *ha = NULL, *cd = NULL;
    long lamps = 0, nv = 0, nh = 0, ptype = 0, units = 0, line;
    double lumens, mult, dim[3], ballast, blp, watts;
    if (!tilt) {
        st = ulam__fail(err, ULAM_ESYNTAX, t.line, -1,
                        "a TILT= line ending the header of an IES LM-63 file (IESNA:LM-63-2002, keywords, TILT=NONE)");
        goto done;
    }
    t.line++; /* the cursor is at the start of the line after TILT= */
    while (*tilt == ' ' || *tilt == '\t') tilt++;
    for (size_t n = strlen(tilt); n > 0 && isspace((unsigned char)tilt[n - 1]);) tilt[--n] = 0;
    if (!strcmp(tilt, "INCLUDE")) {
        long geom, npairs;
        if ((st = integer(&t, "the lamp-to-luminaire geometry", 1, 3, &geom, err)) ||
            (st = integer(&t, "the number of tilt angles", 0, ULAM_GONIO_MAX_ANGLES, &npairs, err)))
            goto done;
        for (long k = 0; k < 2 * npairs && !st; k++) {
            double x;
            st = k < npairs ? real(&t, "a tilt angle", -90.0, 180.0, 0, &x, err)
                            : real(&t, "a tilt multiplying factor", 0.0, 1e300, 0, &x, err);
        }
        if (st) goto done;
    } else if (strcmp(tilt, "NONE")) {
        st = ulam__fail(err, *tilt ? ULAM_EUNSUPPORTED : ULAM_ESYNTAX, tilt_line, -1,
                        "TILT=NONE or TILT=INCLUDE (a separate tilt file is not read), got TILT=%.40s", tilt);
        goto done;
    }
    if ((st = integer(&t, "the number of lamps", 1, 1000, &lamps, err))) goto done;
    if ((st = number(&t, "lumens a lamp", &lumens, &line, err))) goto done;
    if (!(lumens > 0 || lumens == -1)) {
        st = ulam__fail(err, ULAM_ERANGE, line, -1, "lumens a lamp above 0, or -1 (absolute photometry), got %.17g",
                        lumens);
        goto done;
    }
    if ((st = real(&t, "the candela multiplier", 0.0, 1e300, 1, &mult, err)) ||
        (st = integer(&t, "the number of vertical angles", 1, ULAM_GONIO_MAX_ANGLES, &nv, err)) ||
        (st = integer(&t, "the number of horizontal angles", 1, ULAM_GONIO_MAX_ANGLES, &nh, err)))
        goto done;
    line = t.line;
    if (nv * nh > ULAM_GONIO_MAX_VALUES) {
        st = ulam__fail(err, ULAM_ERANGE, line, -1, "at most %d candela values, got %ld x %ld", ULAM_GONIO_MAX_VALUES,
                        nv, nh);
        goto done;
    }
    if ((st = integer(&t, "the photometric type (1 = C, 2 = B, 3 = A)", 1, 3, &ptype, err))) goto done;
    if (ptype != 1) {
        st = ulam__fail(err, ULAM_EUNSUPPORTED, t.line, -1, "photometric type 1 (type C), got type %s",
                        ptype == 2 ? "B (2)" : "A (3)");
        goto done;
    }
    if ((st = integer(&t, "the units type (1 feet, 2 metres)", 1, 2, &units, err))) goto done;
    for (int k = 0; k < 3; k++)
        if ((st = real(&t, k == 0 ? "the width" : k == 1 ? "the length" : "the height", -1e300, 1e300, 0, &dim[k], err)))
            goto done;
    if ((st = real(&t, "the ballast factor", 0.0, 1e300, 1, &ballast, err)) ||
        (st = real(&t, "the ballast-lamp photometric factor", 0.0, 1e300, 1, &blp, err)) ||
        (st = real(&t, "the input watts", 0.0, 1e300, 0, &watts, err)))
        goto done;
    va = ulam__malloc((size_t)nv, sizeof *va), ha = ulam__malloc((size_t)nh, sizeof *ha);
    cd = ulam__malloc((size_t)(nv * nh), sizeof *cd);
    if (!va || !ha || !cd) {
        st = ulam__fail(err, ULAM_ENOMEM, t.line, -1, "memory for the candela table");
        goto done;
    }
    if ((st = angles(&t, "vertical angles", nv, 0.0, 180.0, va, err))) goto done;
    if ((st = angles(&t, "horizontal angles", nh, 0.0, 360.0, ha, err))) goto done;
    line = t.line; /* the last horizontal angle's */
    int sym = ULAM__SYM_NONE;
    if ((st = symmetry(ha, nh, line, &sym, err))) goto done;
    double f = mult * ballast * blp;
    for (long k = 0; k < nv * nh; k++) {
        if ((st = real(&t, "a candela value", 0.0, 1e300, 0, &cd[k], err))) goto done;
        cd[k] *= f;
    }
    while (t.pos < t.len && isspace((unsigned char)t.buf[t.pos])) t.line += t.buf[t.pos++] == '\n';
    if (t.pos < t.len) {
        st = ulam__fail(err, ULAM_ESYNTAX, t.line, -1, "the end of the file after %ld x %ld candela values, got '%.20s'",
                        nh, nv, t.buf + t.pos);
        goto done;
    }
    st = ulam__gonio_make((int)nh, ha, (int)nv, va, cd, sym, lumens > 0 ? lamps * lumens : NAN, out);
    if (st) ulam__fail(err, st, 0, -1, "memory for the table");
done:
    free(va), free(ha), free(cd), free(t.buf);
    return st;
}
