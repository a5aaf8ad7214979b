/* Scenes of patches: allocation, geometry, subdivision, labels, sampling points and directions. */
#include "rad.h"

#include <stdlib.h>
#include <string.h>

/* Allocate an empty scene with room for the given counts. */
ulam_scene *ulam__scene_alloc(int64_t np, int64_t nv, int64_t nidx, int64_t ngroups)
{
    ulam_scene *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->npatches = np;
    s->nverts = nv;
    s->vert = ulam__malloc((size_t)(3 * nv), sizeof(double));
    s->start = ulam__malloc((size_t)(np + 1), sizeof(int64_t));
    s->vidx = ulam__malloc((size_t)nidx, sizeof(int32_t));
    s->normal = ulam__malloc((size_t)(3 * np), sizeof(double));
    s->area = ulam__malloc((size_t)np, sizeof(double));
    s->rho = ulam__malloc((size_t)(3 * np), sizeof(double));
    s->emit = ulam__malloc((size_t)(3 * np), sizeof(double));
    s->face = ulam__malloc((size_t)np, sizeof(int64_t));
    s->group = ulam__malloc((size_t)np, sizeof(int32_t));
    s->groups = ulam__calloc((size_t)ngroups, sizeof(char *));
    if (!s->vert || !s->start || !s->vidx || !s->normal || !s->area || !s->rho || !s->emit ||
        !s->face || !s->group || !s->groups)
        return ulam_scene_free(s);
    return s;
}

/* Copy s's group labels into o (allocated with s->ngroups of them); on failure o is freed and
 * ULAM_ENOMEM returned. */
int ulam__scene_copy_groups(ulam_scene *o, const ulam_scene *s)
{
    for (int64_t g = 0; g < s->ngroups; g++) {
        size_t len = strlen(s->groups[g]) + 1;
        if (!(o->groups[g] = malloc(len))) {
            o->ngroups = g;
            ulam_scene_free(o);
            return ULAM_ENOMEM;
        }
        memcpy(o->groups[g], s->groups[g], len);
    }
    return ULAM_OK;
}

/* Free a scene; accepts and returns NULL. */
ulam_scene *ulam_scene_free(ulam_scene *s)
{
    if (!s) return NULL;
    if (s->groups)
        for (int64_t g = 0; g < s->ngroups; g++) free(s->groups[g]);
    free(s->vert), free(s->start), free(s->vidx), free(s->normal), free(s->area);
    free(s->rho), free(s->emit), free(s->face), free(s->group), free(s->groups);
    free(s);
    return NULL;
}

/* Newell's normal (twice the area in length) and the longest edge of a polygon. */
void ulam__polygon_normal(const double *vert, const int32_t *idx, int64_t n, double N[3], double *longest)
{
    N[0] = N[1] = N[2] = 0.0;
    *longest = 0.0;
    for (int64_t a = 0; a < n; a++) {
        const double *p = vert + 3 * idx[a], *q = vert + 3 * idx[(a + 1) % n];
        N[0] += (p[1] - q[1]) * (p[2] + q[2]);
        N[1] += (p[2] - q[2]) * (p[0] + q[0]);
        N[2] += (p[0] - q[0]) * (p[1] + q[1]);
        double e[3];
        ulam__sub3(q, p, e);
        *longest = fmax(*longest, sqrt(ulam__dot3(e, e)));
    }
}

/* Area and unit normal of every patch. */
void ulam__scene_geometry(ulam_scene *s)
{
    for (int64_t p = 0; p < s->npatches; p++) {
        double N[3], L;
        ulam__polygon_normal(s->vert, s->vidx + s->start[p], s->start[p + 1] - s->start[p], N, &L);
        double len = sqrt(ulam__dot3(N, N));
        s->area[p] = 0.5 * len;
        for (int d = 0; d < 3; d++) s->normal[3 * p + d] = len > 0 ? N[d] / len : 0.0;
    }
}

/* A patch being built by subdivision: its vertices are appended to the output scene. */
typedef struct {
    ulam_scene *o;
    int64_t np, nv, nidx; /* used so far */
    int64_t src;          /* the patch being split */
} builder;

/* Append vertex x to the builder's scene; its index. */
static int32_t add_vertex(builder *b, const double x[3])
{
    memcpy(b->o->vert + 3 * b->nv, x, 3 * sizeof(double));
    return (int32_t)b->nv++;
}

/* Append a patch with vertices v[0..n) (already added; v == NULL: the last n vertices added),
 * copying the source's attributes. */
static void add_patch(builder *b, const ulam_scene *s, const int32_t *v, int64_t n)
{
    ulam_scene *o = b->o;
    o->start[b->np] = b->nidx;
    for (int64_t k = 0; k < n; k++) o->vidx[b->nidx++] = v ? v[k] : (int32_t)(b->nv - n + k);
    memcpy(o->rho + 3 * b->np, s->rho + 3 * b->src, 3 * sizeof(double));
    memcpy(o->emit + 3 * b->np, s->emit + 3 * b->src, 3 * sizeof(double));
    o->face[b->np] = s->face[b->src];
    o->group[b->np] = s->group[b->src];
    b->np++;
    o->start[b->np] = b->nidx;
}

/* Divisions of an edge pair so no piece exceeds L (capped at 2^31: more would overflow the
 * patch count, which the caller then refuses). */
static int64_t divisions(const double *a, const double *b, const double *c, const double *d, double L)
{
    double e1[3], e2[3];
    ulam__sub3(b, a, e1);
    ulam__sub3(d, c, e2);
    double len = fmax(sqrt(ulam__dot3(e1, e1)), sqrt(ulam__dot3(e2, e2)));
    double m = ceil(len / L);
    return m < 1 ? 1 : m > 2147483648.0 ? (int64_t)1 << 31 : (int64_t)m;
}

/* Divisions of triangle (A, B, C): its longest side over L. */
static int64_t tri_divisions(const double *A, const double *B, const double *C, double L)
{
    int64_t d = divisions(A, B, B, C, L), d2 = divisions(C, A, A, B, L);
    return d > d2 ? d : d2;
}

/* How patch p splits: returns the pieces and sets *nv to the vertices they add; quads split
 * into an *m x *k grid, triangles into d^2 similar triangles (through a fan for larger
 * polygons, which are kept whole when no side exceeds L).  Counts past INT32_MAX mean
 * "too many". */
static int64_t plan(const ulam_scene *s, int64_t p, double L, int64_t *m, int64_t *k, int64_t *nv)
{
    const int32_t *v = s->vidx + s->start[p];
    int64_t n = s->start[p + 1] - s->start[p];
    const double *x = s->vert;
    if (n == 4) {
        *m = divisions(x + 3 * v[0], x + 3 * v[1], x + 3 * v[3], x + 3 * v[2], L);
        *k = divisions(x + 3 * v[0], x + 3 * v[3], x + 3 * v[1], x + 3 * v[2], L);
        *nv = (*m + 1) * (*k + 1);
        return *m * *k;
    }
    if (n > 4) {
        double N[3], longest;
        ulam__polygon_normal(x, v, n, N, &longest);
        if (longest <= L) {
            *nv = n;
            return 1;
        }
    }
    int64_t total = 0;
    *nv = 0;
    for (int64_t t = 1; t + 1 < n && total <= INT32_MAX; t++) {
        int64_t d = tri_divisions(x + 3 * v[0], x + 3 * v[t], x + 3 * v[t + 1], L);
        total += d * d;
        *nv += (d + 1) * (d + 2) / 2;
    }
    return total;
}

/* Split quad v into an m x k bilinear grid. */
static void split_quad(builder *b, const ulam_scene *s, const int32_t *v, int64_t m, int64_t k)
{
    const double *P[4];
    for (int i = 0; i < 4; i++) P[i] = s->vert + 3 * v[i];
    int32_t first = (int32_t)b->nv;
    for (int64_t j = 0; j <= k; j++)
        for (int64_t i = 0; i <= m; i++) {
            double u = (double)i / (double)m, w = (double)j / (double)k, x[3];
            for (int d = 0; d < 3; d++)
                x[d] = (1 - u) * (1 - w) * P[0][d] + u * (1 - w) * P[1][d] + u * w * P[2][d] + (1 - u) * w * P[3][d];
            add_vertex(b, x);
        }
    for (int64_t j = 0; j < k; j++)
        for (int64_t i = 0; i < m; i++) {
            int32_t a = first + (int32_t)(j * (m + 1) + i);
            int32_t q[4] = {a, a + 1, a + 1 + (int32_t)(m + 1), a + (int32_t)(m + 1)};
            add_patch(b, s, q, 4);
        }
}

/* Split triangle (A, B, C) into m^2 similar triangles. */
static void split_triangle(builder *b, const ulam_scene *s, const double *A, const double *B, const double *C,
                           int64_t m)
{
    int32_t first = (int32_t)b->nv;
    for (int64_t j = 0; j <= m; j++)
        for (int64_t i = 0; i + j <= m; i++) {
            double x[3];
            for (int d = 0; d < 3; d++)
                x[d] = A[d] + ((double)i / (double)m) * (B[d] - A[d]) + ((double)j / (double)m) * (C[d] - A[d]);
            add_vertex(b, x);
        }
    /* row j starts at offset j*(m+1) - j*(j-1)/2 */
#define AT(i, j) (first + (int32_t)((j) * (m + 1) - (j) * ((j) - 1) / 2 + (i)))
    for (int64_t j = 0; j < m; j++)
        for (int64_t i = 0; i + j < m; i++) {
            int32_t t[3] = {AT(i, j), AT(i + 1, j), AT(i, j + 1)};
            add_patch(b, s, t, 3);
            if (i + j + 1 < m) {
                int32_t u[3] = {AT(i + 1, j), AT(i + 1, j + 1), AT(i, j + 1)};
                add_patch(b, s, u, 3);
            }
        }
#undef AT
}

/* The bytes of a scene's arrays for np patches, nv vertices and nidx vertex indices
 * (ulam__scene_alloc's). */
static double scene_bytes(double np, double nv, double nidx)
{
    return np * (double)(sizeof(int64_t) + 10 * sizeof(double) + sizeof(int64_t) + sizeof(int32_t)) +
           3.0 * sizeof(double) * nv + sizeof(int32_t) * nidx;
}

/* What ulam_scene_subdivide(s, max_side) would make, counted without making it: *patches,
 * *vertices, *triangles (the ray tracer's) and *bytes of the new scene's arrays (any may be
 * NULL), as doubles so that a count past what can be built is still told; ULAM_EOVERFLOW when
 * the patches or vertices pass INT32_MAX (ulam_scene_subdivide refuses those). */
int ulam_scene_subdivide_plan(const ulam_scene *s, double max_side, double *patches, double *vertices,
                              double *triangles, double *bytes)
{
    if (!s || !(max_side > 0) || !isfinite(max_side)) return ULAM_EINVAL;
    double np = 0, nv = 0, nidx = 0, tri = 0;
    int64_t m = 1, k = 1, pv;
    for (int64_t p = 0; p < s->npatches; p++) {
        int64_t n = s->start[p + 1] - s->start[p];
        double c = (double)plan(s, p, max_side, &m, &k, &pv);
        np += c, nv += (double)pv;
        nidx += n == 4 ? 4 * c : c == 1 && n > 4 ? (double)n : 3 * c;
        tri += n == 4 ? 2 * c : c == 1 && n > 4 ? (double)(n - 2) : c;
    }
    if (patches) *patches = np;
    if (vertices) *vertices = nv;
    if (triangles) *triangles = tri;
    if (bytes) *bytes = scene_bytes(np, nv, nidx);
    return np > (double)INT32_MAX || nv > (double)INT32_MAX ? ULAM_EOVERFLOW : ULAM_OK;
}

/* Split every patch so no side exceeds max_side. */
int ulam_scene_subdivide(const ulam_scene *s, double max_side, ulam_scene **out)
{
    if (!s || !out || !(max_side > 0) || !isfinite(max_side)) return ULAM_EINVAL;
    *out = NULL;
    int64_t np = 0, nv = 0, nidx = 0, m = 1, k = 1, pv;
    for (int64_t p = 0; p < s->npatches; p++) {
        int64_t n = s->start[p + 1] - s->start[p], c = plan(s, p, max_side, &m, &k, &pv);
        if (c > (int64_t)INT32_MAX - np || pv > (int64_t)INT32_MAX - nv) return ULAM_EOVERFLOW;
        np += c;
        nv += pv;
        nidx += n == 4 ? 4 * c : c == 1 && n > 4 ? n : 3 * c;
    }
    ulam_scene *o = ulam__scene_alloc(np, nv, nidx, s->ngroups);
    if (!o) return ULAM_ENOMEM;
    if (ulam__scene_copy_groups(o, s)) return ULAM_ENOMEM; /* o freed */
    o->ngroups = s->ngroups;
    o->nfaces = s->nfaces;
    builder b = {.o = o};
    o->start[0] = 0;
    for (int64_t p = 0; p < s->npatches; p++) {
        const int32_t *v = s->vidx + s->start[p];
        int64_t n = s->start[p + 1] - s->start[p], c = plan(s, p, max_side, &m, &k, &pv);
        b.src = p;
        if (n == 4) {
            split_quad(&b, s, v, m, k);
        } else if (c == 1 && n > 4) { /* kept whole */
            for (int64_t a = 0; a < n; a++) add_vertex(&b, s->vert + 3 * v[a]);
            add_patch(&b, s, NULL, n);
        } else {
            for (int64_t t = 1; t + 1 < n; t++) {
                const double *A = s->vert + 3 * v[0], *B = s->vert + 3 * v[t], *C = s->vert + 3 * v[t + 1];
                split_triangle(&b, s, A, B, C, tri_divisions(A, B, C, max_side));
            }
        }
    }
    o->nverts = b.nv;
    ulam__scene_geometry(o);
    *out = o;
    return ULAM_OK;
}

/* Twice the area of triangle (a, b, c). */
static double tri_area2(const double *a, const double *b, const double *c)
{
    double e1[3], e2[3], x[3];
    ulam__sub3(b, a, e1);
    ulam__sub3(c, a, e2);
    ulam__cross3(e1, e2, x);
    return sqrt(ulam__dot3(x, x));
}

/* The area centroid of polygon vert[idx[0..n)] (its fan triangles' centroids weighted by their
 * areas; its first vertex when the area is 0). */
void ulam__polygon_centroid(const double *vert, const int32_t *idx, int64_t n, double c[3])
{
    const double *A = vert + 3 * idx[0];
    double w = 0.0;
    c[0] = c[1] = c[2] = 0.0;
    for (int64_t t = 1; t + 1 < n; t++) {
        const double *B = vert + 3 * idx[t], *C = vert + 3 * idx[t + 1];
        double a = tri_area2(A, B, C);
        for (int d = 0; d < 3; d++) c[d] += a * (A[d] + B[d] + C[d]) / 3.0;
        w += a;
    }
    for (int d = 0; d < 3; d++) c[d] = w > 0 ? c[d] / w : A[d];
}

/* The area centroid of patch p. */
void ulam_scene_centroid(const ulam_scene *s, int64_t p, double c[3])
{
    ulam__polygon_centroid(s->vert, s->vidx + s->start[p], s->start[p + 1] - s->start[p], c);
}

/* The index of group label, or -1 (rad.h). */
int64_t ulam__scene_group(const ulam_scene *s, const char *label)
{
    for (int64_t i = 0; i < s->ngroups; i++)
        if (!strcmp(s->groups[i], label)) return i;
    return -1;
}

/* The area centroid of the patches labelled label. */
int ulam_scene_label_centroid(const ulam_scene *s, const char *label, double c[3])
{
    if (!s || !label || !c) return ULAM_EINVAL;
    int64_t g = ulam__scene_group(s, label);
    double A = 0.0, m[3];
    c[0] = c[1] = c[2] = 0.0;
    for (int64_t p = 0; g >= 0 && p < s->npatches; p++) {
        if (s->group[p] != g) continue;
        ulam_scene_centroid(s, p, m);
        for (int d = 0; d < 3; d++) c[d] += s->area[p] * m[d];
        A += s->area[p];
    }
    if (!(A > 0)) return ULAM_ENOTFOUND;
    for (int d = 0; d < 3; d++) c[d] /= A;
    return ULAM_OK;
}

/* Nonzero when x lies in patch p: within tol of its plane and inside every edge, tol being
 * rel of the patch's size (rounding, so that a point on a shared edge is in both). */
static int contains_within(const ulam_scene *s, int64_t p, const double x[3], double rel)
{
    const double *n = s->normal + 3 * p;
    const int32_t *v = s->vidx + s->start[p];
    int64_t m = s->start[p + 1] - s->start[p];
    double tol = rel * sqrt(s->area[p]), d[3];
    ulam__sub3(x, s->vert + 3 * v[0], d);
    if (fabs(ulam__dot3(d, n)) > tol) return 0;
    for (int64_t k = 0; k < m; k++) {
        const double *a = s->vert + 3 * v[k], *b = s->vert + 3 * v[(k + 1) % m];
        double e[3], w[3], c[3];
        ulam__sub3(b, a, e);
        ulam__sub3(x, a, w);
        ulam__cross3(e, w, c);
        if (ulam__dot3(c, n) < -tol * sqrt(ulam__dot3(e, e))) return 0;
    }
    return 1;
}

/* Nonzero when x lies in patch p to 10^-9 of its size. */
static int contains(const ulam_scene *s, int64_t p, const double x[3])
{
    return contains_within(s, p, x, 1e-9);
}

/* The lowest-numbered patch that x lies in to rel of the patch's size, or -1. */
int64_t ulam_scene_locate(const ulam_scene *s, const double x[3], double rel)
{
    for (int64_t p = 0; s && p < s->npatches; p++)
        if (contains_within(s, p, x, rel)) return p;
    return -1;
}

/* The patch of group label containing the group's area centroid, else the nearest by centroid. */
int ulam_scene_find(const ulam_scene *s, const char *label, int64_t *patch)
{
    if (!s || !label || !patch) return ULAM_EINVAL;
    double c[3], m[3], e[3], best = INFINITY;
    int status = ulam_scene_label_centroid(s, label, c);
    if (status) return status;
    int64_t g = ulam__scene_group(s, label);
    for (int64_t p = 0; p < s->npatches; p++)
        if (s->group[p] == g && contains(s, p, c)) {
            *patch = p;
            return ULAM_OK;
        }
    for (int64_t p = 0; p < s->npatches; p++) {
        if (s->group[p] != g) continue;
        ulam_scene_centroid(s, p, m);
        ulam__sub3(m, c, e);
        if (ulam__dot3(e, e) < best) best = ulam__dot3(e, e), *patch = p;
    }
    return ULAM_OK;
}

/* The share of a quad's area in its first fan triangle (1 for triangles). */
double ulam__first_share(const ulam_scene *s, int64_t p)
{
    const int32_t *v = s->vidx + s->start[p];
    if (s->start[p + 1] - s->start[p] != 4) return 1.0;
    const double *A = s->vert + 3 * v[0];
    return tri_area2(A, s->vert + 3 * v[1], s->vert + 3 * v[2]) / (2.0 * s->area[p]);
}

/* A uniform point of patch p; share is ulam__first_share(s, p). */
void ulam__patch_point(const ulam_scene *s, int64_t p, double share, ulam_rng *r, double pt[3])
{
    const int32_t *v = s->vidx + s->start[p];
    int64_t n = s->start[p + 1] - s->start[p], t = 1;
    const double *A = s->vert + 3 * v[0];
    if (n == 4) {
        t = ulam__rng_uniform(r) < share ? 1 : 2;
    } else if (n > 4) { /* pick a fan triangle in proportion to its area */
        double u = ulam__rng_uniform(r) * 2.0 * s->area[p], acc = 0.0;
        for (t = 1; t + 2 < n; t++) {
            acc += tri_area2(A, s->vert + 3 * v[t], s->vert + 3 * v[t + 1]);
            if (u < acc) break;
        }
    }
    const double *B = s->vert + 3 * v[t], *C = s->vert + 3 * v[t + 1];
    double a = ulam__rng_uniform(r), b = ulam__rng_uniform(r);
    if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b; /* fold the parallelogram onto the triangle */
    for (int d = 0; d < 3; d++) pt[d] = A[d] + a * (B[d] - A[d]) + b * (C[d] - A[d]);
}

/* A cosine-distributed direction about n (Malley's method: a uniform disc point, drawn by
 * rejection from the square (no trigonometry), lifted to the hemisphere). */
void ulam__cosine_dir(const double n[3], ulam_rng *r, double d[3])
{
    double t[3], b[3];
    /* an orthonormal frame (Duff et al., "Building an orthonormal basis, revisited", 2017) */
    double sign = n[2] >= 0 ? 1.0 : -1.0, a = -1.0 / (sign + n[2]), c = n[0] * n[1] * a;
    t[0] = 1.0 + sign * n[0] * n[0] * a, t[1] = sign * c, t[2] = -sign * n[0];
    b[0] = c, b[1] = sign + n[1] * n[1] * a, b[2] = -n[1];
    double x, y, rr;
    do {
        x = 2.0 * ulam__rng_uniform(r) - 1.0;
        y = 2.0 * ulam__rng_uniform(r) - 1.0;
        rr = x * x + y * y;
    } while (rr >= 1.0);
    double z = sqrt(1.0 - rr);
    for (int k = 0; k < 3; k++) d[k] = x * t[k] + y * b[k] + z * n[k];
}
