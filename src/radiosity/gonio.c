/* The goniometric intensity table (photometry type C) that IES LM-63 and EULUMDAT files are read
 * into: the measured C planes unfolded by the file's symmetry onto the full circle, bilinear
 * interpolation (periodic in C, 0 outside the gamma range), the flux integral exact for that
 * interpolation; and the whole-file text reader both parsers share. */
#include "photo.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct ulam_gonio {
    int nc, ng;    /* C planes in [0, 360), gamma angles */
    double *c, *g; /* degrees, ascending */
    double *cd;    /* cd[i * ng + j]: plane i, gamma j */
    double rated;  /* the lamps' flux the file states, NaN: none */
    double flux;   /* the integral of I over the sphere */
};

/* Read path whole into t; ULAM_OK or the status in err. */
int ulam__text_read(const char *path, ulam__text *t, ulam_error *err)
{
    memset(t, 0, sizeof *t);
    FILE *f = fopen(path, "rb");
    if (!f) return ulam__fail(err, ULAM_EIO, 0, -1, "a readable file (%s)", strerror(errno));
    size_t cap = 1 << 16;
    t->buf = malloc(cap);
    int status = t->buf ? ULAM_OK : ULAM_ENOMEM;
    while (!status) {
        if (t->len + 1 >= cap) {
            if (cap >= ULAM__PHOTO_MAX_BYTES) {
                status = ulam__fail(err, ULAM_ERANGE, 0, -1, "a photometric file of at most %d bytes",
                                    ULAM__PHOTO_MAX_BYTES);
                break;
            }
            char *b = realloc(t->buf, cap * 2);
            if (!b) {
                status = ULAM_ENOMEM;
                break;
            }
            t->buf = b, cap *= 2;
        }
        size_t got = fread(t->buf + t->len, 1, cap - 1 - t->len, f);
        t->len += got;
        if (got == 0) {
            if (ferror(f)) status = ulam__fail(err, ULAM_EIO, 0, -1, "a readable file (%s)", strerror(errno));
            break;
        }
    }
    fclose(f);
    if (status == ULAM_ENOMEM) ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the file");
    if (!status) {
        t->buf[t->len] = 0;
        long line = 1;
        for (size_t k = 0; k < t->len && !status; k++) {
            if (t->buf[k] == 0) status = ulam__fail(err, ULAM_ESYNTAX, line, -1, "text, not a NUL byte");
            line += t->buf[k] == '\n';
        }
    }
    if (status) free(t->buf), t->buf = NULL;
    return status;
}

/* The next line, NUL-terminated in place (CR LF or LF), t->line its number; NULL at the end. */
char *ulam__text_line(ulam__text *t)
{
    if (t->pos >= t->len) return NULL;
    char *s = t->buf + t->pos, *e = strchr(s, '\n');
    size_t n = e ? (size_t)(e - s) : strlen(s);
    t->pos += n + (e != NULL);
    t->line++;
    s[n] = 0;
    if (n > 0 && s[n - 1] == '\r') s[n - 1] = 0;
    return s;
}

/* a modulo 360 in [0, 360). */
static double wrap360(double a)
{
    double r = fmod(a, 360.0);
    if (r < 0) r += 360.0;
    return r >= 360.0 ? 0.0 : r;
}

/* The images of angle a under symmetry sym (out: up to 4); their count. */
static int images(double a, int sym, double *out)
{
    int n = 0;
    out[n++] = a;
    if (sym == ULAM__SYM_C0_C180 || sym == ULAM__SYM_QUADRANT) out[n++] = 360.0 - a;
    if (sym == ULAM__SYM_C90_C270 || sym == ULAM__SYM_QUADRANT) out[n++] = 180.0 - a;
    if (sym == ULAM__SYM_QUADRANT) out[n++] = 180.0 + a;
    for (int k = 0; k < n; k++) out[k] = wrap360(out[k]);
    return n;
}

/* Sort the planes (angle, measured index) by angle. */
typedef struct {
    double c;
    int k;
} plane;
static int by_angle(const void *a, const void *b)
{
    double x = ((const plane *)a)->c, y = ((const plane *)b)->c;
    return (x > y) - (x < y);
}

/* The integral of I sin gamma over gamma for plane i, exact for I linear between the angles. */
static double zone(const ulam_gonio *g, int i)
{
    double z = 0.0;
    for (int j = 0; j + 1 < g->ng; j++) {
        double a = g->g[j] * M_PI / 180.0, b = g->g[j + 1] * M_PI / 180.0;
        double Ia = g->cd[(size_t)i * g->ng + j], Ib = g->cd[(size_t)i * g->ng + j + 1], s = (Ib - Ia) / (b - a);
        /* int_a^b (Ia + s (x - a)) sin x dx */
        z += Ia * (cos(a) - cos(b)) + s * (sin(b) - sin(a) - (b - a) * cos(b));
    }
    return z;
}

/* The flux: the trapezoid across C (exact for I linear in C between planes) of the zones. */
static double flux_of(const ulam_gonio *g)
{
    if (g->nc == 1) return 2.0 * M_PI * zone(g, 0);
    double f = 0.0;
    for (int i = 0; i < g->nc; i++) {
        int k = (i + 1) % g->nc;
        double dc = (k ? g->c[k] : g->c[0] + 360.0) - g->c[i];
        f += 0.5 * dc * M_PI / 180.0 * (zone(g, i) + zone(g, k));
    }
    return f;
}

/* The table from the measured planes, unfolded by sym. */
int ulam__gonio_make(int nm, const double *cm, int ng, const double *gm, const double *v, int sym, double rated,
                     ulam_gonio **out)
{
    *out = NULL;
    ulam_gonio *g = calloc(1, sizeof *g);
    plane *pl = ulam__malloc((size_t)nm * 4, sizeof *pl);
    if (!g || !pl) {
        free(g), free(pl);
        return ULAM_ENOMEM;
    }
    int np = 0;
    if (sym == ULAM__SYM_ROTATION || nm == 1) {
        pl[np++] = (plane){0.0, 0};
    } else {
        for (int k = 0; k < nm; k++) {
            double im[4];
            int n = images(cm[k], sym, im);
            for (int m = 0; m < n; m++) pl[np++] = (plane){im[m], k};
        }
        qsort(pl, (size_t)np, sizeof *pl, by_angle);
        int w = 0; /* one plane an angle (within 1e-9 degree), the first measured */
        for (int k = 0; k < np; k++)
            if (!w || pl[k].c - pl[w - 1].c > 1e-9) pl[w++] = pl[k];
        if (w > 1 && pl[w - 1].c > 360.0 - 1e-9) w--; /* 360 is 0 */
        np = w;
    }
    g->nc = np, g->ng = ng, g->rated = rated;
    g->c = ulam__malloc((size_t)np, sizeof *g->c);
    g->g = ulam__malloc((size_t)ng, sizeof *g->g);
    g->cd = ulam__malloc((size_t)np * (size_t)ng, sizeof *g->cd);
    if (!g->c || !g->g || !g->cd) {
        free(pl);
        ulam_gonio_free(g);
        return ULAM_ENOMEM;
    }
    for (int j = 0; j < ng; j++) g->g[j] = gm[j];
    for (int i = 0; i < np; i++) {
        g->c[i] = pl[i].c;
        memcpy(g->cd + (size_t)i * ng, v + (size_t)pl[i].k * ng, (size_t)ng * sizeof *v);
    }
    free(pl);
    g->flux = flux_of(g);
    *out = g;
    return ULAM_OK;
}

/* Free; accepts and returns NULL. */
ulam_gonio *ulam_gonio_free(ulam_gonio *g)
{
    if (g) free(g->c), free(g->g), free(g->cd), free(g);
    return NULL;
}

/* I at plane i, gamma index j and fraction t toward j + 1. */
static double along(const ulam_gonio *g, int i, int j, double t)
{
    const double *r = g->cd + (size_t)i * g->ng;
    return t > 0 ? (1.0 - t) * r[j] + t * r[j + 1] : r[j];
}

/* I(C, gamma) in cd. */
double ulam_gonio_intensity(const ulam_gonio *g, double c_deg, double gamma_deg)
{
    if (!g || !isfinite(c_deg) || !isfinite(gamma_deg)) return NAN;
    double gm = fmin(180.0, fmax(0.0, gamma_deg));
    if (gm < g->g[0] || gm > g->g[g->ng - 1]) return 0.0;
    int lo = 0, hi = g->ng - 1; /* the last gamma angle <= gm */
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (g->g[mid] <= gm) lo = mid;
        else hi = mid;
    }
    int j = g->ng == 1 || g->g[hi] <= gm ? hi : lo;
    double t = j + 1 < g->ng ? (gm - g->g[j]) / (g->g[j + 1] - g->g[j]) : 0.0;
    if (g->nc == 1) return along(g, 0, j, t);
    double c = wrap360(c_deg);
    int i = g->nc - 1; /* the last plane <= c, or the wrap segment from the last plane */
    if (c >= g->c[0]) {
        int a = 0, b = g->nc - 1;
        while (b - a > 1) {
            int mid = (a + b) / 2;
            if (g->c[mid] <= c) a = mid;
            else b = mid;
        }
        i = g->c[b] <= c ? b : a;
    }
    int k = (i + 1) % g->nc;
    double c0 = g->c[i], c1 = k ? g->c[k] : g->c[0] + 360.0;
    if (c < c0) c += 360.0;
    double u = (c - c0) / (c1 - c0);
    return (1.0 - u) * along(g, i, j, t) + u * along(g, k, j, t);
}

/* The luminous flux in lm. */
double ulam_gonio_flux(const ulam_gonio *g)
{
    return g ? g->flux : NAN;
}

/* The stated lamp flux in lm, NaN when none. */
double ulam_gonio_rated_flux(const ulam_gonio *g)
{
    return g ? g->rated : NAN;
}

/* The unfolded table's size. */
void ulam_gonio_size(const ulam_gonio *g, int *nc, int *ng)
{
    if (nc) *nc = g ? g->nc : 0;
    if (ng) *ng = g ? g->ng : 0;
}
