/* EULUMDAT photometric files (.ldt), read from the format's specification (one field a line):
 * 1 identification; 2 type indicator Ityp (0 .. 3); 3 symmetry indicator Isym (0 none, 1 about
 * the vertical axis, 2 about the C0-C180 plane, 3 about C90-C270, 4 about both); 4 Mc, the
 * number of C planes in 0 .. 360; 5 Dc; 6 Ng, the intensities a C plane; 7 Dg; 8 .. 12 report
 * number, luminaire name and number, file name, date and user; 13 .. 21 dimensions (mm);
 * 22 downward flux fraction, 23 light output ratio (%); 24 conversion factor for the
 * intensities; 25 tilt during measurement; 26 n, the standard lamp sets, then per set (26a-f)
 * number of lamps, type, total flux (lm), colour, colour rendering, wattage; 27 the ten direct
 * ratios; 28 the Mc C angles; 29 the Ng gamma angles; 30 the intensities (cd/klm) of planes
 * Mc1 .. Mc2 (Isym 0: 1 .. Mc; 1: 1 .. 1; 2: 1 .. Mc/2 + 1; 3: 3 Mc/4 + 1 .. 3 Mc/4 + 1 + Mc/2,
 * counted modulo Mc; 4: 1 .. Mc/4 + 1), Ng values each.  Candela = value x conversion factor x
 * the first set's flux / 1000.  A decimal comma is read as a point.  Every count is bounded and
 * every error names its line. */
#include "photo.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

/* The next line, or ULAM_ESYNTAX at the end naming what was expected. */
static int next(ulam__text *t, const char *what, char **s, ulam_error *err)
{
    *s = ulam__text_line(t);
    if (!*s) return ulam__fail(err, ULAM_ESYNTAX, t->line + 1, -1, "%s, got the end of the file", what);
    return ULAM_OK;
}

/* The next line as one number (a decimal comma read as a point, blanks around it allowed). */
static int number(ulam__text *t, const char *what, double *x, ulam_error *err)
{
    char *s, *end;
    int st = next(t, what, &s, err);
    if (st) return st;
    for (char *p = s; *p; p++)
        if (*p == ',') *p = '.';
    *x = strtod(s, &end);
    while (isspace((unsigned char)*end)) end++;
    if (end == s || *end || !isfinite(*x)) return ulam__fail(err, ULAM_ESYNTAX, t->line, -1, "%s (one number), got '%.40s'", what, s);
    return ULAM_OK;
}

/* The next line as an integer in [lo, hi]. */
static int integer(ulam__text *t, const char *what, long lo, long hi, long *v, ulam_error *err)
{
    double x;
    int st = number(t, what, &x, err);
    if (st) return st;
    if (x != floor(x) || x < lo || x > hi)
        return ulam__fail(err, ULAM_ERANGE, t->line, -1, "%s, an integer from %ld to %ld, got %.17g", what, lo, hi, x);
    *v = (long)x;
    return ULAM_OK;
}

/* The next line as a number in [lo, hi]. */
static int real(ulam__text *t, const char *what, double lo, double hi, double *v, ulam_error *err)
{
    int st = number(t, what, v, err);
    if (st) return st;
    if (*v < lo || *v > hi) return ulam__fail(err, ULAM_ERANGE, t->line, -1, "%s within %g .. %g, got %.17g", what, lo, hi, *v);
    return ULAM_OK;
}

/* Read a EULUMDAT file. */
int ulam_gonio_read_ldt(const char *path, ulam_gonio **out, ulam_error *err)
{
    ulam__clear(err);
    if (!path || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a path and an output");
    *out = NULL;
    ulam__text t;
    int st = ulam__text_read(path, &t, err);
    if (st) return st;
    char *s;
    long ityp, isym, mc, ng, nsets, sym_line;
    double x, cf = 1.0, flux = NAN, *ca = NULL, *ga = NULL, *v = NULL, *cm = NULL;
    if ((st = next(&t, "the identification (line 1)", &s, err)) ||
        (st = integer(&t, "the type indicator Ityp (line 2)", 0, 3, &ityp, err)) ||
        (st = integer(&t, "the symmetry indicator Isym (line 3)", 0, 4, &isym, err)))
        goto done;
    sym_line = t.line;
    if ((st = integer(&t, "the number of C planes Mc (line 4)", 1, ULAM_GONIO_MAX_ANGLES - 1, &mc, err)) ||
        (st = real(&t, "the distance between C planes Dc (line 5)", 0.0, 360.0, &x, err)) ||
        (st = integer(&t, "the number of intensities a C plane Ng (line 6)", 1, ULAM_GONIO_MAX_ANGLES, &ng, err)) ||
        (st = real(&t, "the distance between intensities Dg (line 7)", 0.0, 180.0, &x, err)))
        goto done;
    if ((isym == 2 && mc % 2) || ((isym == 3 || isym == 4) && mc % 4)) {
        st = ulam__fail(err, ULAM_ERANGE, t.line - 3, -1, "Mc a multiple of %d for symmetry Isym %ld, got %ld",
                        isym == 2 ? 2 : 4, isym, mc);
        goto done;
    }
    for (int k = 8; k <= 12; k++)
        if ((st = next(&t, "a text line (lines 8 .. 12: report, luminaire name and number, file name, date)", &s, err)))
            goto done;
    for (int k = 13; k <= 25; k++) {
        static const char *const what[] = {"the luminaire's length (line 13)", "its width (line 14)",
                                           "its height (line 15)", "the luminous area's length (line 16)",
                                           "its width (line 17)", "its height at C0 (line 18)", "at C90 (line 19)",
                                           "at C180 (line 20)", "at C270 (line 21)",
                                           "the downward flux fraction (line 22)",
                                           "the light output ratio (line 23)",
                                           "the conversion factor for intensities (line 24)",
                                           "the tilt during measurement (line 25)"};
        double lo = k <= 21 ? 0.0 : k <= 23 ? 0.0 : k == 24 ? 1e-300 : -180.0, hi = k <= 21 ? 1e9 : k <= 23 ? 100.0 : k == 24 ? 1e300 : 180.0;
        if ((st = real(&t, what[k - 13], lo, hi, &x, err))) goto done;
        if (k == 24) cf = x;
    }
    if ((st = integer(&t, "the number of standard lamp sets n (line 26)", 1, 20, &nsets, err))) goto done;
    for (long k = 0; k < nsets; k++) {
        long nl;
        double fl, w;
        if ((st = integer(&t, "the number of lamps (line 26a)", -1000, 1000, &nl, err)) ||
            (st = next(&t, "the type of lamps (line 26b)", &s, err)) ||
            (st = real(&t, "the total flux of the lamps in lm (line 26c)", 0.0, 1e12, &fl, err)) ||
            (st = next(&t, "the colour appearance (line 26d)", &s, err)) ||
            (st = next(&t, "the colour rendering (line 26e)", &s, err)) ||
            (st = real(&t, "the wattage (line 26f)", 0.0, 1e12, &w, err)))
            goto done;
        if (k == 0 && !(fl > 0)) {
            st = ulam__fail(err, ULAM_ERANGE, t.line - 3, -1, "the first lamp set's flux above 0 lm, got %.17g", fl);
            goto done;
        }
        if (k == 0) flux = fl;
    }
    for (int k = 0; k < 10; k++)
        if ((st = real(&t, "a direct ratio (line 27, ten of them)", 0.0, 1.0 + 1e-6, &x, err))) goto done;
    long mc1 = 1, mc2 = isym == 0 ? mc : isym == 1 ? 1 : isym == 2 ? mc / 2 + 1 : isym == 4 ? mc / 4 + 1 : 0;
    if (isym == 3) mc1 = 3 * mc / 4 + 1, mc2 = mc1 + mc / 2;
    long nm = mc2 - mc1 + 1;
    if (nm * ng > ULAM_GONIO_MAX_VALUES) {
        st = ulam__fail(err, ULAM_ERANGE, sym_line, -1, "at most %d intensities, got %ld x %ld", ULAM_GONIO_MAX_VALUES,
                        nm, ng);
        goto done;
    }
    ca = ulam__malloc((size_t)mc, sizeof *ca), ga = ulam__malloc((size_t)ng, sizeof *ga);
    v = ulam__malloc((size_t)(nm * ng), sizeof *v), cm = ulam__malloc((size_t)nm, sizeof *cm);
    if (!ca || !ga || !v || !cm) {
        st = ulam__fail(err, ULAM_ENOMEM, t.line, -1, "memory for the intensities");
        goto done;
    }
    for (long k = 0; k < mc; k++) {
        if ((st = real(&t, "a C angle (line 28: Mc of them, from 0, ascending, below 360)", 0.0, 360.0, &ca[k], err)))
            goto done;
        if ((k == 0 && ca[0] != 0.0) || (k && !(ca[k] > ca[k - 1])) || ca[k] >= 360.0) {
            st = ulam__fail(err, ULAM_ESYNTAX, t.line, -1, "C angles from 0, ascending, below 360, got %.17g", ca[k]);
            goto done;
        }
    }
    for (long k = 0; k < ng; k++) {
        if ((st = real(&t, "a gamma angle (line 29: Ng of them, ascending, within 0 .. 180)", 0.0, 180.0, &ga[k], err)))
            goto done;
        if (k && !(ga[k] > ga[k - 1])) {
            st = ulam__fail(err, ULAM_ESYNTAX, t.line, -1, "gamma angles ascending, got %.17g after %.17g", ga[k],
                            ga[k - 1]);
            goto done;
        }
    }
    for (long k = 0; k < nm; k++) cm[k] = ca[(mc1 - 1 + k) % mc];
    if (isym == 3) /* the planes from 270 through 0 to 90: one side of the C90-C270 plane */
        for (long k = 0; k < nm; k++)
            if (cm[k] < 180.0) cm[k] += 360.0;
    double f = cf * flux / 1000.0;
    for (long k = 0; k < nm * ng; k++) {
        if ((st = real(&t, "an intensity in cd/klm (line 30)", 0.0, 1e12, &v[k], err))) goto done;
        v[k] *= f;
    }
    while ((s = ulam__text_line(&t))) {
        while (isspace((unsigned char)*s)) s++;
        if (*s) {
            st = ulam__fail(err, ULAM_ESYNTAX, t.line, -1, "the end of the file after %ld x %ld intensities, got '%.20s'",
                            nm, ng, s);
            goto done;
        }
    }
    static const int syms[] = {ULAM__SYM_NONE, ULAM__SYM_ROTATION, ULAM__SYM_C0_C180, ULAM__SYM_C90_C270,
                               ULAM__SYM_QUADRANT};
    st = ulam__gonio_make((int)nm, cm, (int)ng, ga, v, syms[isym], flux, out);
    if (st) ulam__fail(err, st, 0, -1, "memory for the table");
done:
    free(ca), free(ga), free(v), free(cm), free(t.buf);
    return st;
}
