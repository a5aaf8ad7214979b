/* Adaptive, importance-driven subdivision (Hanrahan, Salzman & Aupperle 1991; Smits, Arvo &
 * Salesin 1992): refine a patch where the continuous surface's radiosity varies across it and
 * where the view's importance is high, instead of splitting every patch alike.  A patch's
 * variation comes from point queries (point.c, no mesh in their answers) at its quadrature
 * points (the area centroid and half way to each vertex, as mesh.c's patch mesh error) and at
 * the nodes on its boundary (its vertices and the midpoints its finer neighbours put on its
 * edges: a shadow reaching into a patch between its interior points shows there, the radiosity
 * being continuous across the edge): the weighted RMS about their mean, each point's own noise
 * removed (E[d_k^2] = true d_k^2 + var d_k), scaled to the area's RMS of a linear field
 * (linear_spread), is its mesh error e_p, what one value per patch cannot show.  The mesh's error is
 * max_c sum_p Y_p e_pc / sum_p Y_p mean_pc (Y the importance: the share of the picture, or of
 * the area, that rests on the patch; mean_p the reflected radiosity B - E, the emission being
 * exact on every mesh), relative to the importance-weighted reflected radiosity.  Each
 * round splits the patches of largest Y_p e_p until the rest would meet the target, and
 * measures their children. */
#include "rad.h"

#include <stdlib.h>
#include <string.h>

enum { MAX_ROUNDS = 64, MAX_POINTS = ULAM_RAD_MESH_POINTS };

/* A mesh being refined: polygons over a growing vertex array, the live ones its patches. */
typedef struct {
    double *vert;
    int64_t nv, capv;
    int32_t *idx;
    int64_t nidx, capi;
    int64_t *first, *len, *src; /* per polygon: its vertices idx[first, first + len), its source patch */
    double *Y, *mean, *e;       /* importance; 3 each: mean radiosity over its points, mesh error */
    double *pb, *ps2;           /* MAX_POINTS x 3 each: its interior points' B and their variances */
    char *live, *known;
    int64_t np, capp, nlive;
    int32_t *nu;            /* nodes measured: (vertex nu + 1, source patch ns) -> B nb, variance ns2 (3 each); */
    int64_t *ns, ncap, ncount; /* nu 0 empty */
    double *nb, *ns2;
    double *bx;                  /* half the length of the boundary segment after each node */
    int64_t capb;
    uint64_t *key; /* edge (lo << 32 | hi) + 1 -> its midpoint vertex; 0 empty */
    int32_t *mid;
    int64_t hcap, hcount;
} mesh;

/* Grow *p (n used, *cap room, size bytes each) to hold need; 0 or ULAM_ENOMEM. */
static int grow(void **p, int64_t *cap, int64_t need, size_t size)
{
    if (need <= *cap) return 0;
    int64_t c = *cap ? *cap : 64;
    while (c < need) c *= 2;
    void *q = realloc(*p, (size_t)c * size);
    if (!q) return ULAM_ENOMEM;
    *p = q, *cap = c;
    return 0;
}

/* Resize *p to n elements of size bytes; 0 or ULAM_ENOMEM (*p kept). */
static int resize(void **p, int64_t n, size_t size)
{
    void *q = realloc(*p, (size_t)n * size);
    if (!q) return ULAM_ENOMEM;
    *p = q;
    return 0;
}

/* Room for `more` polygons, every per-polygon array to one capacity; 0 or ULAM_ENOMEM. */
static int grow_polys(mesh *m, int64_t more)
{
    int64_t need = m->np + more, c = m->capp ? m->capp : 64;
    if (need <= m->capp) return 0;
    while (c < need) c *= 2;
    int st = resize((void **)&m->first, c, sizeof *m->first) | resize((void **)&m->len, c, sizeof *m->len);
    st |= resize((void **)&m->src, c, sizeof *m->src) | resize((void **)&m->Y, c, sizeof *m->Y);
    st |= resize((void **)&m->live, c, 1) | resize((void **)&m->known, c, 1);
    st |= resize((void **)&m->mean, 3 * c, sizeof *m->mean) | resize((void **)&m->e, 3 * c, sizeof *m->e);
    st |= resize((void **)&m->pb, 3 * MAX_POINTS * c, sizeof *m->pb);
    st |= resize((void **)&m->ps2, 3 * MAX_POINTS * c, sizeof *m->ps2);
    if (st) return ULAM_ENOMEM;
    m->capp = c;
    return 0;
}

/* Free the mesh's arrays. */
static void mesh_free(mesh *m)
{
    free(m->vert), free(m->idx), free(m->first), free(m->len), free(m->src), free(m->Y), free(m->mean);
    free(m->e), free(m->live), free(m->known), free(m->key), free(m->mid), free(m->pb), free(m->ps2);
    free(m->nu), free(m->ns), free(m->nb), free(m->ns2), free(m->bx);
}

/* A new vertex at x; its index, or -1 without memory. */
static int32_t add_vertex(mesh *m, const double x[3])
{
    if (m->nv >= INT32_MAX || grow((void **)&m->vert, &m->capv, 3 * (m->nv + 1), sizeof *m->vert)) return -1;
    memcpy(m->vert + 3 * m->nv, x, 3 * sizeof *x);
    return (int32_t)m->nv++;
}

/* The slot of edge key k in the midpoint table. */
static int64_t slot(const mesh *m, uint64_t k)
{
    uint64_t h = k * 0x9E3779B97F4A7C15ull;
    int64_t i = (int64_t)(h >> 20) & (m->hcap - 1);
    while (m->key[i] && m->key[i] != k) i = (i + 1) & (m->hcap - 1);
    return i;
}

/* The midpoint vertex of edge (a, b) if a split made it, else -1. */
static int32_t find_midpoint(const mesh *m, int32_t a, int32_t b)
{
    if (!m->hcap) return -1;
    uint64_t lo = (uint64_t)(a < b ? a : b), hi = (uint64_t)(a < b ? b : a), k = (lo << 32 | hi) + 1;
    int64_t i = slot(m, k);
    return m->key[i] ? m->mid[i] : -1;
}

/* The midpoint vertex of edge (a, b), shared with the neighbour across it; -1 without memory. */
static int32_t midpoint(mesh *m, int32_t a, int32_t b)
{
    if (2 * (m->hcount + 1) > m->hcap) { /* rehash at half full */
        int64_t oc = m->hcap, nc = oc ? 2 * oc : 1024;
        uint64_t *ok = m->key;
        int32_t *om = m->mid;
        m->key = calloc((size_t)nc, sizeof *m->key), m->mid = malloc((size_t)nc * sizeof *m->mid);
        if (!m->key || !m->mid) {
            free(m->key), free(m->mid);
            m->key = ok, m->mid = om;
            return -1;
        }
        m->hcap = nc;
        for (int64_t i = 0; i < oc; i++)
            if (ok[i]) {
                int64_t j = slot(m, ok[i]);
                m->key[j] = ok[i], m->mid[j] = om[i];
            }
        free(ok), free(om);
    }
    uint64_t lo = (uint64_t)(a < b ? a : b), hi = (uint64_t)(a < b ? b : a), k = (lo << 32 | hi) + 1;
    int64_t i = slot(m, k);
    if (m->key[i]) return m->mid[i];
    double x[3];
    for (int d = 0; d < 3; d++) x[d] = 0.5 * (m->vert[3 * a + d] + m->vert[3 * b + d]);
    int32_t v = add_vertex(m, x);
    if (v < 0) return -1;
    m->key[i] = k, m->mid[i] = v, m->hcount++;
    return v;
}

/* Twice the area of polygon v[0..n) of m. */
static double area2(const mesh *m, const int32_t *v, int64_t n)
{
    double N[3], longest;
    ulam__polygon_normal(m->vert, v, n, N, &longest);
    return sqrt(ulam__dot3(N, N));
}

/* Append a live, unmeasured polygon v[0..n) from source src of importance Y; 0 or ULAM_ENOMEM. */
static int add_poly(mesh *m, const int32_t *v, int64_t n, int64_t src, double Y)
{
    if (grow_polys(m, 1) || grow((void **)&m->idx, &m->capi, m->nidx + n, sizeof *m->idx)) return ULAM_ENOMEM;
    memcpy(m->idx + m->nidx, v, (size_t)n * sizeof *v);
    int64_t i = m->np++;
    m->first[i] = m->nidx, m->len[i] = n, m->src[i] = src, m->Y[i] = Y, m->live[i] = 1, m->known[i] = 0;
    m->nidx += n, m->nlive++;
    return 0;
}

/* The children polygon i splits into. */
static int64_t children(const mesh *m, int64_t i)
{
    return m->len[i] <= 4 ? 4 : m->len[i] - 2;
}

/* Split polygon i: a triangle or quad into 4 at its edge midpoints (a quad's centre its
 * vertices' mean), a larger polygon into its fan; children share i's importance by area. */
static int split(mesh *m, int64_t i)
{
    int64_t n = m->len[i];
    int32_t v[4], c[4][4];
    if (n > 4) { /* the fan keeps the vertices: n - 2 triangles */
        int32_t *w = ulam__malloc((size_t)n, sizeof *w);
        if (!w) return ULAM_ENOMEM;
        memcpy(w, m->idx + m->first[i], (size_t)n * sizeof *w); /* add_poly may move m->idx */
        double a = area2(m, w, n);
        for (int64_t t = 1; t + 1 < n; t++) {
            int32_t tri[3] = {w[0], w[t], w[t + 1]};
            if (add_poly(m, tri, 3, m->src[i], a > 0 ? m->Y[i] * area2(m, tri, 3) / a : 0.0)) {
                free(w);
                return ULAM_ENOMEM;
            }
        }
        free(w);
        m->live[i] = 0, m->nlive--;
        return 0;
    }
    memcpy(v, m->idx + m->first[i], (size_t)n * sizeof *v);
    int32_t h[4];
    for (int64_t k = 0; k < n; k++)
        if ((h[k] = midpoint(m, v[k], v[(k + 1) % n])) < 0) return ULAM_ENOMEM;
    int64_t nc = 4, cl = n;
    if (n == 3) {
        int32_t t[4][3] = {{v[0], h[0], h[2]}, {h[0], v[1], h[1]}, {h[2], h[1], v[2]}, {h[0], h[1], h[2]}};
        for (int k = 0; k < 4; k++) memcpy(c[k], t[k], sizeof t[k]);
    } else {
        double x[3];
        for (int d = 0; d < 3; d++)
            x[d] = 0.25 * (m->vert[3 * v[0] + d] + m->vert[3 * v[1] + d] + m->vert[3 * v[2] + d] + m->vert[3 * v[3] + d]);
        int32_t o = add_vertex(m, x);
        if (o < 0) return ULAM_ENOMEM;
        int32_t q[4][4] = {{v[0], h[0], o, h[3]}, {h[0], v[1], h[1], o}, {o, h[1], v[2], h[2]}, {h[3], o, h[2], v[3]}};
        for (int k = 0; k < 4; k++) memcpy(c[k], q[k], sizeof q[k]);
    }
    double a = area2(m, v, n);
    for (int64_t k = 0; k < nc; k++)
        if (add_poly(m, c[k], cl, m->src[i], a > 0 ? m->Y[i] * area2(m, c[k], cl) / a : 0.0)) return ULAM_ENOMEM;
    m->live[i] = 0, m->nlive--;
    return 0;
}

/* The area's spread of a linear field over polygon v[0..n) against that of K points x with
 * weights w (summing to 1): int |x - g|^2 dA / A over sum_k w_k |x_k - xbar|^2, the ratio of the
 * traces of the two second moments, exact where the two are proportional (triangles and
 * parallelograms, the points an affine image of a symmetric set: the centroid, half way to each
 * vertex, the vertices).  The centroid and half-way points alone see 1/1.29 of a linear field's
 * RMS on a square. */
static double linear_spread(const double *vert, const int32_t *v, int64_t n, const double *x, const double *w, int64_t K)
{
    double g[3], xm[3] = {0, 0, 0}, area = 0.0, mom = 0.0, q = 0.0;
    ulam__polygon_centroid(vert, v, n, g);
    for (int64_t k = 1; k + 1 < n; k++) { /* fan triangles: A (|t - g|^2 + sum_j |v_j - t|^2 / 12) */
        const double *a = vert + 3 * v[0], *b = vert + 3 * v[k], *c = vert + 3 * v[k + 1];
        double e1[3], e2[3], cr[3], t[3], d[3];
        ulam__sub3(b, a, e1), ulam__sub3(c, a, e2), ulam__cross3(e1, e2, cr);
        double A = 0.5 * sqrt(ulam__dot3(cr, cr)), s = 0.0;
        for (int j = 0; j < 3; j++) t[j] = (a[j] + b[j] + c[j]) / 3.0;
        const double *u[3] = {a, b, c};
        for (int j = 0; j < 3; j++) ulam__sub3(u[j], t, d), s += ulam__dot3(d, d);
        ulam__sub3(t, g, d);
        area += A, mom += A * (ulam__dot3(d, d) + s / 12.0);
    }
    for (int64_t k = 0; k < K; k++)
        for (int j = 0; j < 3; j++) xm[j] += w[k] * x[3 * k + j];
    for (int64_t k = 0; k < K; k++) {
        double d[3];
        ulam__sub3(x + 3 * k, xm, d);
        q += w[k] * ulam__dot3(d, d);
    }
    return area > 0 && q > 0 ? mom / area / q : 1.0;
}

/* Quadrature point k of polygon v[0..n) with centroid c: c itself, then half way to vertex k - 1. */
static void interior_point(const double *vert, const int32_t *v, const double c[3], int k, double x[3])
{
    for (int d = 0; d < 3; d++) x[d] = k ? 0.5 * (c[d] + vert[3 * v[k - 1] + d]) : c[d];
}

/* The number of interior quadrature points of an n-gon. */
static int interior_points(int64_t n)
{
    return (int)(1 + (n < MAX_POINTS - 1 ? n : MAX_POINTS - 1));
}

/* One point query at x (seed stream k) into b, s2 (3 each); ULAM_OK with info->interrupted set
 * when the time ran out. */
static int query(const ulam_tracer *t, const ulam_rad_opts *opts, double t0, const double x[3], uint64_t k,
                 double *b, double *s2, ulam_rad_adapt_info *info, ulam_error *err)
{
    ulam_rad_opts o = *opts;
    o.exec.seed = ulam_rng_substream(opts->exec.seed, ULAM_STREAM_POINT, k);
    if (opts->stop.max_seconds > 0 && !((o.stop.max_seconds = opts->stop.max_seconds - (ulam_now() - t0)) > 0)) {
        info->interrupted = 1;
        return ULAM_OK;
    }
    ulam_rad_point pt;
    int st = ulam_rad_point_query(t, &o, x, NULL, &pt, err);
    if (st) return st;
    info->points++, info->walks += pt.run.walks, info->rays += pt.run.rays;
    if (pt.run.interrupted) info->interrupted = 1;
    for (int ch = 0; ch < 3; ch++) b[ch] = pt.radiosity[ch], s2[ch] = pt.radiosity_se[ch] * pt.radiosity_se[ch];
    return ULAM_OK;
}

/* Measure polygon i by point queries at its interior quadrature points (kept for estimate) and
 * their mean (the reflected part, B - E). */
static int measure(mesh *m, int64_t i, const ulam_tracer *t, const ulam_rad_opts *opts, double t0,
                   ulam_rad_adapt_info *info, ulam_error *err)
{
    const int32_t *v = m->idx + m->first[i];
    int64_t n = m->len[i];
    int K = interior_points(n);
    double *b = m->pb + 3 * MAX_POINTS * i, *s2 = m->ps2 + 3 * MAX_POINTS * i, c[3];
    ulam__polygon_centroid(m->vert, v, n, c);
    for (int k = 0; k < K; k++) {
        double x[3];
        interior_point(m->vert, v, c, k, x);
        int st = query(t, opts, t0, x, 16 * (uint64_t)i + (uint64_t)k, b + 3 * k, s2 + 3 * k, info, err);
        if (st || info->interrupted) return st;
    }
    double *E = ulam__tracer_scene(t)->emit + 3 * m->src[i];
    for (int ch = 0; ch < 3; ch++) { /* the emission, constant on the patch, is no part of the error */
        double mean = 0.0;
        for (int k = 0; k < K; k++) mean += b[3 * k + ch] / K;
        m->mean[3 * i + ch] = fmax(0.0, mean - E[ch]);
    }
    m->known[i] = 1;
    return ULAM_OK;
}

/* Append the nodes on edge (a, b) of a polygon, a included, b not: a, and the midpoints the
 * neighbours' splits put on it, in order, each with half the length of the segment after it in
 * m->bx (node NULL: only count them in *nb). */
static void edge_nodes(mesh *m, int32_t a, int32_t b, int64_t *nb, int32_t *node)
{
    int32_t h = find_midpoint(m, a, b);
    if (h >= 0) {
        edge_nodes(m, a, h, nb, node), edge_nodes(m, h, b, nb, node);
        return;
    }
    if (!node) {
        (*nb)++;
        return;
    }
    double d[3];
    ulam__sub3(m->vert + 3 * b, m->vert + 3 * a, d);
    double L = sqrt(ulam__dot3(d, d));
    node[*nb] = a, m->bx[*nb] = 0.5 * L;
    (*nb)++;
}

/* The slot of node (vertex u, source patch src) in the node table. */
static int64_t node_slot(const mesh *m, int32_t u, int64_t src)
{
    uint64_t h = ((uint64_t)u * 0x9E3779B97F4A7C15ull) ^ ((uint64_t)src * 0xC2B2AE3D27D4EB4Full);
    int64_t i = (int64_t)(h >> 20) & (m->ncap - 1);
    while (m->nu[i] && !(m->nu[i] == u + 1 && m->ns[i] == src)) i = (i + 1) & (m->ncap - 1);
    return i;
}

/* Room for one more node (rehash at half full); 0 or ULAM_ENOMEM. */
static int node_room(mesh *m)
{
    if (2 * (m->ncount + 1) <= m->ncap) return 0;
    int64_t oc = m->ncap, nc = oc ? 2 * oc : 1024;
    int32_t *ou = m->nu;
    int64_t *os = m->ns;
    double *ob = m->nb, *o2 = m->ns2;
    m->nu = calloc((size_t)nc, sizeof *m->nu), m->ns = malloc((size_t)nc * sizeof *m->ns);
    m->nb = malloc((size_t)(3 * nc) * sizeof *m->nb), m->ns2 = malloc((size_t)(3 * nc) * sizeof *m->ns2);
    if (!m->nu || !m->ns || !m->nb || !m->ns2) {
        free(m->nu), free(m->ns), free(m->nb), free(m->ns2);
        m->nu = ou, m->ns = os, m->nb = ob, m->ns2 = o2;
        return ULAM_ENOMEM;
    }
    m->ncap = nc;
    for (int64_t i = 0; i < oc; i++)
        if (ou[i]) {
            int64_t j = node_slot(m, ou[i] - 1, os[i]);
            m->nu[j] = ou[i], m->ns[j] = os[i];
            memcpy(m->nb + 3 * j, ob + 3 * i, 3 * sizeof *ob), memcpy(m->ns2 + 3 * j, o2 + 3 * i, 3 * sizeof *o2);
        }
    free(ou), free(os), free(ob), free(o2);
    return 0;
}

/* B at vertex u of polygon i (a hair inside i, on its surface), measured once per vertex and
 * source patch, into b, s2. */
static int vertex_value(mesh *m, int32_t u, int64_t i, const double c[3], const ulam_tracer *t,
                        const ulam_rad_opts *opts, double t0, double b[3], double s2[3],
                        ulam_rad_adapt_info *info, ulam_error *err)
{
    if (node_room(m)) return ULAM_ENOMEM;
    int64_t k = node_slot(m, u, m->src[i]);
    if (!m->nu[k]) {
        double x[3], d[3]; /* 1e-4 scene sizes toward i's centroid: 100 times locate's tolerance, so the
                            * point is on i's surface, not a wall across a concave edge (1e-6 of the way
                            * read the Cornell box's corners dark: its mesh error 0.764 for 0.403) */
        ulam__sub3(c, m->vert + 3 * u, d);
        double len = sqrt(ulam__dot3(d, d)), step = len > 0 ? fmin(1e-4 * ulam__tracer_size(t, NULL), 0.25 * len) / len : 0.0;
        for (int j = 0; j < 3; j++) x[j] = m->vert[3 * u + j] + step * d[j];
        int st = query(t, opts, t0, x, 16 * (uint64_t)u + 15, m->nb + 3 * k, m->ns2 + 3 * k, info, err);
        if (st || info->interrupted) return st;
        m->nu[k] = u + 1, m->ns[k] = m->src[i], m->ncount++;
    }
    memcpy(b, m->nb + 3 * k, 3 * sizeof *b), memcpy(s2, m->ns2 + 3 * k, 3 * sizeof *s2);
    return ULAM_OK;
}

/* Polygon i's mesh error from its interior points and the nodes on its boundary (its vertices
 * and the midpoints its finer neighbours put on its edges: the surface's radiosity is continuous
 * across an edge, so a neighbour's shadow reaching it shows there even where the interior points
 * miss it).  Weights: 2/3 the interior points alike, 1/3 the boundary nodes by the length beside
 * each.  The weighted RMS about the weighted mean, each point's own noise removed
 * (E[S] = S_true + sum_k w_k s_k^2 - sum_k w_k^2 s_k^2) and one standard deviation of that
 * noise's spread more (sqrt(2 sum_k w_k^2 s_k^4), S's SD on a flat field), scaled to the area's
 * RMS of a linear field (linear_spread).  Without that SD, the square root of the positive part
 * read a flat patch's noise as spread: on the sharp shadow the patches whose true RMS is under 1%
 * of their mean (their points' noise about 0.6%) read 1.9 .. 2.4 times their truth, and the
 * mesh error 1.19 .. 1.25 times the true one; with it 1.06 .. 1.13 (tests/test_rad_adapt.c).
 * A spread under the noise reads between 0 and its truth. */
static int estimate(mesh *m, int64_t i, const ulam_tracer *t, const ulam_rad_opts *opts, double t0,
                    ulam_rad_adapt_info *info, ulam_error *err)
{
    int64_t n = m->len[i], nb = 0;
    int st = ULAM_OK;
    for (int64_t e = 0; e < n; e++) edge_nodes(m, m->idx[m->first[i] + e], m->idx[m->first[i] + (e + 1) % n], &nb, NULL);
    int32_t *node = ulam__malloc((size_t)(nb > 0 ? nb : 1), sizeof *node);
    if (!node || grow((void **)&m->bx, &m->capb, nb, sizeof *m->bx)) {
        free(node);
        return ULAM_ENOMEM;
    }
    nb = 0;
    for (int64_t e = 0; e < n; e++) edge_nodes(m, m->idx[m->first[i] + e], m->idx[m->first[i] + (e + 1) % n], &nb, node);
    int K = interior_points(n);
    int64_t N = K + nb;
    double *x = ulam__malloc((size_t)(3 * N), sizeof *x), *w = ulam__malloc((size_t)N, sizeof *w);
    double *b = ulam__malloc((size_t)(3 * N), sizeof *b), *s2 = ulam__malloc((size_t)(3 * N), sizeof *s2);
    if (!st && (!x || !w || !b || !s2)) st = ULAM_ENOMEM;
    const int32_t *v = m->idx + m->first[i];
    double c[3], per = 0.0;
    ulam__polygon_centroid(m->vert, v, n, c);
    for (int k = 0; !st && k < K; k++) {
        interior_point(m->vert, v, c, k, x + 3 * k), w[k] = (nb ? 2.0 / 3.0 : 1.0) / K;
        memcpy(b + 3 * k, m->pb + 3 * (MAX_POINTS * i + k), 3 * sizeof *b);
        memcpy(s2 + 3 * k, m->ps2 + 3 * (MAX_POINTS * i + k), 3 * sizeof *s2);
    }
    for (int64_t j = 0; !st && j < nb; j++) /* each node: half its segment and half the one before */
        w[K + j] = m->bx[j] + m->bx[(j + nb - 1) % nb], per += 2 * m->bx[j];
    for (int64_t j = 0; !st && j < nb && !info->interrupted; j++) {
        w[K + j] = per > 0 ? w[K + j] / per / 3.0 : 1.0 / (3.0 * nb);
        memcpy(x + 3 * (K + j), m->vert + 3 * node[j], 3 * sizeof *x);
        st = vertex_value(m, node[j], i, c, t, opts, t0, b + 3 * (K + j), s2 + 3 * (K + j), info, err);
    }
    if (!st && !info->interrupted) {
        double f2 = linear_spread(m->vert, v, n, x, w, N);
        for (int ch = 0; ch < 3; ch++) {
            double mean = 0.0, S = 0.0, noise = 0.0, tau2 = 0.0;
            for (int64_t k = 0; k < N; k++) mean += w[k] * b[3 * k + ch];
            for (int64_t k = 0; k < N; k++) {
                double d = b[3 * k + ch] - mean;
                S += w[k] * d * d, noise += w[k] * (1.0 - w[k]) * s2[3 * k + ch];
                tau2 += 2.0 * w[k] * w[k] * s2[3 * k + ch] * s2[3 * k + ch];
            }
            noise += sqrt(tau2); /* and one SD of the noise's own spread (see above) */
            m->e[3 * i + ch] = S > noise ? sqrt((S - noise) * f2) : 0.0;
        }
    }
    free(node), free(x), free(w), free(b), free(s2);
    return st;
}

/* The mesh error of the live polygons (max over channels) and each one's share of it in r
 * (max over channels of Y e / sum Y mean). */
static double mesh_error(const mesh *m, double *r)
{
    double num[3] = {0}, den[3] = {0}, worst = 0.0;
    for (int64_t i = 0; i < m->np; i++)
        for (int c = 0; m->live[i] && c < 3; c++) num[c] += m->Y[i] * m->e[3 * i + c], den[c] += m->Y[i] * m->mean[3 * i + c];
    for (int c = 0; c < 3; c++)
        if (den[c] > 0) worst = fmax(worst, num[c] / den[c]);
    for (int64_t i = 0; r && i < m->np; i++) {
        r[i] = 0.0;
        for (int c = 0; m->live[i] && c < 3; c++)
            if (den[c] > 0) r[i] = fmax(r[i], m->Y[i] * m->e[3 * i + c] / den[c]);
    }
    return worst;
}

/* The live polygons of m as a new scene, materials, faces and groups from s. */
static int to_scene(const mesh *m, const ulam_scene *s, ulam_scene **out)
{
    int64_t nidx = 0;
    for (int64_t i = 0; i < m->np; i++)
        if (m->live[i]) nidx += m->len[i];
    ulam_scene *o = ulam__scene_alloc(m->nlive, m->nv, nidx, s->ngroups);
    if (!o) return ULAM_ENOMEM;
    if (ulam__scene_copy_groups(o, s)) return ULAM_ENOMEM; /* o freed */
    o->ngroups = s->ngroups, o->nfaces = s->nfaces;
    memcpy(o->vert, m->vert, (size_t)(3 * m->nv) * sizeof *o->vert);
    int64_t p = 0, k = 0;
    o->start[0] = 0;
    for (int64_t i = 0; i < m->np; i++) {
        if (!m->live[i]) continue;
        int64_t q = m->src[i];
        memcpy(o->vidx + k, m->idx + m->first[i], (size_t)m->len[i] * sizeof *o->vidx);
        k += m->len[i];
        memcpy(o->rho + 3 * p, s->rho + 3 * q, 3 * sizeof *o->rho);
        memcpy(o->emit + 3 * p, s->emit + 3 * q, 3 * sizeof *o->emit);
        o->face[p] = s->face[q], o->group[p] = s->group[q];
        o->start[++p] = k;
    }
    ulam__scene_geometry(o);
    *out = o;
    return ULAM_OK;
}

/* The tracer's scene as the first mesh: a polygon a patch, importance Y (NULL: the area). */
static int mesh_init(mesh *m, const ulam_scene *s, const double *Y)
{
    if (grow((void **)&m->vert, &m->capv, 3 * s->nverts, sizeof *m->vert)) return ULAM_ENOMEM;
    memcpy(m->vert, s->vert, (size_t)(3 * s->nverts) * sizeof *m->vert);
    m->nv = s->nverts;
    double total = 0.0;
    for (int64_t p = 0; p < s->npatches; p++) total += s->area[p];
    for (int64_t p = 0; p < s->npatches; p++)
        if (add_poly(m, s->vidx + s->start[p], s->start[p + 1] - s->start[p], p,
                     Y ? Y[p] : total > 0 ? s->area[p] / total : 0.0))
            return ULAM_ENOMEM;
    return ULAM_OK;
}

/* Undo the last round's splits: polygons np0 and after dropped, the nundo split ones live again. */
static void undo_splits(mesh *m, const int64_t *undo, int64_t nundo, int64_t np0)
{
    for (int64_t i = np0; i < m->np; i++) m->nlive -= m->live[i];
    m->np = np0;
    for (int64_t k = 0; k < nundo; k++) m->live[undo[k]] = 1, m->nlive++;
}

/* Refine the tracer's scene until its importance-weighted mesh error is at most target. */
int ulam_rad_adapt(const ulam_tracer *t, const ulam_rad_opts *opts, const double *importance, double target,
                   int64_t max_patches, ulam_scene **out, ulam_rad_adapt_info *info, ulam_error *err)
{
    ulam__clear(err);
    if (!t || !opts || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer, options and an output");
    if (!(target >= 0) || !isfinite(target)) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a finite target >= 0");
    const ulam_scene *s = ulam__tracer_scene(t);
    if (max_patches < s->npatches)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "max_patches at least the scene's %lld", (long long)s->npatches);
    for (int64_t p = 0; importance && p < s->npatches; p++)
        if (!(importance[p] >= 0) || !isfinite(importance[p]))
            return ulam__fail(err, ULAM_EINVAL, 0, p, "a finite importance >= 0 for patch %lld", (long long)p + 1);
    *out = NULL;
    ulam_rad_adapt_info in = {.patches_in = s->npatches, .target = target};
    double t0 = ulam_now(), total_area = 0.0;
    for (int64_t p = 0; p < s->npatches; p++) total_area += s->area[p];
    mesh m = {0};
    ulam__ranked *sh = NULL;
    int64_t *undo = NULL, nundo = 0, np0 = 0; /* the round's split polygons, and the count before them */
    int status = mesh_init(&m, s, importance);
    in.error0 = in.error = NAN; /* until a mesh is measured whole */
    for (int round = 0; !status; round++) {
        for (int64_t i = 0; i < m.np && !status && !in.interrupted; i++)
            if (m.live[i] && !m.known[i]) status = measure(&m, i, t, opts, t0, &in, err);
        for (int64_t i = 0; i < m.np && !status && !in.interrupted; i++) /* their neighbours' nodes may be new */
            if (m.live[i]) status = estimate(&m, i, t, opts, t0, &in, err);
        if (!status && in.interrupted) { /* undo the round cut short: the mesh made is the one measured */
            undo_splits(&m, undo, nundo, round ? np0 : m.np);
            break;
        }
        if (status) break;
        in.error = mesh_error(&m, NULL);
        if (round == 0) in.error0 = in.error;
        if ((in.met = in.error <= target)) break;
        if (round >= MAX_ROUNDS || !(sh = ulam__malloc((size_t)m.np, sizeof *sh))) {
            in.capped = round >= MAX_ROUNDS;
            if (!in.capped) status = ULAM_ENOMEM;
            break;
        }
        double *r = ulam__malloc((size_t)m.np, sizeof *r), rest = 0.0;
        int64_t *u = realloc(undo, (size_t)m.np * sizeof *undo);
        if (u) undo = u;
        if (!r || !u) {
            free(r);
            status = ULAM_ENOMEM;
            break;
        }
        mesh_error(&m, r);
        int64_t ns = 0, np = m.np, nlive = m.nlive, made = 0;
        for (int64_t i = 0; i < np; i++)
            if (m.live[i]) sh[ns++] = (ulam__ranked){r[i], i}, rest += r[i];
        free(r);
        qsort(sh, (size_t)ns, sizeof *sh, ulam__ranked_desc);
        np0 = m.np, nundo = 0;
        for (int64_t k = 0; k < ns && rest > target && !status && sh[k].r > 0; k++) {
            int64_t i = sh[k].i;
            if (nlive - 1 + children(&m, i) > max_patches) {
                in.capped = 1;
                break;
            }
            if (area2(&m, m.idx + m.first[i], m.len[i]) < 1e-12 * total_area) continue; /* as fine as floats allow */
            status = split(&m, i);
            if (!status) undo[nundo++] = i;
            nlive = m.nlive, rest -= sh[k].r, made++;
        }
        free(sh), sh = NULL;
        in.splits += made, in.rounds += made > 0;
        if (!made) {
            in.capped = 1;
            break;
        }
    }
    if (in.interrupted) in.splits -= nundo, in.rounds -= nundo > 0;
    if (!status) status = to_scene(&m, s, out);
    mesh_free(&m);
    free(sh), free(undo);
    in.patches = *out ? (*out)->npatches : 0;
    in.seconds = ulam_now() - t0;
    if (info) *info = in;
    if (status == ULAM_ENOMEM) return ulam__fail(err, status, 0, -1, "memory for the adaptive mesh");
    return status;
}
