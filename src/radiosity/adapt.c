/* Adaptive, importance-driven subdivision (Hanrahan, Salzman & Aupperle 1991; Smits, Arvo &
 * Salesin 1992): refine a patch where the continuous surface's radiosity varies across it and
 * where the view's importance is high, instead of splitting every patch alike.  A patch's
 * variation comes from point queries (point.c, no mesh in their answers) at its quadrature
 * points (the area centroid and half way to each vertex, as mesh.c's patch mesh error): the
 * RMS about their mean, each point's own noise removed (E[d_k^2] = true d_k^2 + var d_k), scaled
 * to the area's RMS of a linear field (linear_spread: the points alone see 1/1.29 of it on a
 * square), is its mesh error e_p, what one value per patch cannot show.  The mesh's error is
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
    char *live, *known;
    int64_t np, capp, nlive;
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

/* Room for `more` polygons; 0 or ULAM_ENOMEM. */
static int grow_polys(mesh *m, int64_t more)
{
    int64_t need = m->np + more, cap = m->capp, c;
    if (need <= cap) return 0;
    c = cap;
    int st = grow((void **)&m->first, &c, need, sizeof *m->first);
    c = cap, st |= grow((void **)&m->len, &c, need, sizeof *m->len);
    c = cap, st |= grow((void **)&m->src, &c, need, sizeof *m->src);
    c = cap, st |= grow((void **)&m->Y, &c, need, sizeof *m->Y);
    c = cap, st |= grow((void **)&m->live, &c, need, 1);
    c = cap, st |= grow((void **)&m->known, &c, need, 1);
    c = 3 * cap, st |= grow((void **)&m->mean, &c, 3 * need, sizeof *m->mean);
    c = 3 * cap, st |= grow((void **)&m->e, &c, 3 * need, sizeof *m->e);
    if (st) return ULAM_ENOMEM;
    m->capp = c / 3;
    return 0;
}

/* Free the mesh's arrays. */
static void mesh_free(mesh *m)
{
    free(m->vert), free(m->idx), free(m->first), free(m->len), free(m->src), free(m->Y), free(m->mean);
    free(m->e), free(m->live), free(m->known), free(m->key), free(m->mid);
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

/* The area's spread of a linear field over polygon v[0..n) against its K quadrature points' (the
 * centroid and half way to each of the first K - 1 vertices): int |x - g|^2 dA / A over
 * (1 / K) sum_k |x_k - mean|^2, the ratio of the traces of the two second moments, exact for
 * triangles (4/3) and parallelograms (5/3), where the two are proportional.  The points alone
 * see 1/1.29 of a linear field's RMS on a square. */
static double linear_spread(const double *vert, const int32_t *v, int64_t n, int K)
{
    double g[3], x[MAX_POINTS][3], xm[3] = {0, 0, 0}, area = 0.0, mom = 0.0, q = 0.0;
    ulam__polygon_centroid(vert, v, n, g);
    for (int64_t k = 1; k + 1 < n; k++) { /* fan triangles: A (|t - g|^2 + sum_j |v_j - t|^2 / 12) */
        const double *a = vert + 3 * v[0], *b = vert + 3 * v[k], *c = vert + 3 * v[k + 1];
        double e1[3], e2[3], cr[3], t[3], d[3];
        ulam__sub3(b, a, e1), ulam__sub3(c, a, e2), ulam__cross3(e1, e2, cr);
        double A = 0.5 * sqrt(ulam__dot3(cr, cr)), s = 0.0;
        for (int j = 0; j < 3; j++) t[j] = (a[j] + b[j] + c[j]) / 3.0;
        const double *w[3] = {a, b, c};
        for (int j = 0; j < 3; j++) ulam__sub3(w[j], t, d), s += ulam__dot3(d, d);
        ulam__sub3(t, g, d);
        area += A, mom += A * (ulam__dot3(d, d) + s / 12.0);
    }
    for (int k = 0; k < K; k++)
        for (int j = 0; j < 3; j++) x[k][j] = k ? 0.5 * (g[j] + vert[3 * v[k - 1] + j]) : g[j], xm[j] += x[k][j] / K;
    for (int k = 0; k < K; k++) {
        double d[3];
        ulam__sub3(x[k], xm, d);
        q += ulam__dot3(d, d) / K;
    }
    return area > 0 && q > 0 ? mom / area / q : 1.0;
}

/* Measure polygon i by point queries at its quadrature points: its mean (the reflected part,
 * B - E) and mesh error. */
static int measure(mesh *m, int64_t i, const ulam_tracer *t, const ulam_rad_opts *opts, double t0,
                   ulam_rad_adapt_info *info, ulam_error *err)
{
    const int32_t *v = m->idx + m->first[i];
    int64_t n = m->len[i];
    int K = (int)(1 + (n < MAX_POINTS - 1 ? n : MAX_POINTS - 1));
    double b[MAX_POINTS][3], s2[MAX_POINTS][3], c[3];
    ulam__polygon_centroid(m->vert, v, n, c);
    for (int k = 0; k < K; k++) {
        double x[3];
        for (int d = 0; d < 3; d++) x[d] = k ? 0.5 * (c[d] + m->vert[3 * v[k - 1] + d]) : c[d];
        ulam_rad_opts o = *opts;
        o.exec.seed = ulam_rng_substream(opts->exec.seed, ULAM_STREAM_POINT, 16 * (uint64_t)i + (uint64_t)k);
        if (opts->stop.max_seconds > 0 && !((o.stop.max_seconds = opts->stop.max_seconds - (ulam_now() - t0)) > 0)) {
            info->interrupted = 1;
            return ULAM_OK;
        }
        ulam_rad_point pt;
        int st = ulam_rad_point_query(t, &o, x, NULL, &pt, err);
        if (st) return st;
        info->points++, info->walks += pt.run.walks, info->rays += pt.run.rays;
        if (pt.run.interrupted) {
            info->interrupted = 1;
            return ULAM_OK;
        }
        for (int ch = 0; ch < 3; ch++) b[k][ch] = pt.radiosity[ch], s2[k][ch] = pt.radiosity_se[ch] * pt.radiosity_se[ch];
    }
    double f2 = linear_spread(m->vert, v, n, K), *E = ulam__tracer_scene(t)->emit + 3 * m->src[i];
    for (int ch = 0; ch < 3; ch++) {
        double mean = 0.0, sum2 = 0.0, e2 = 0.0;
        for (int k = 0; k < K; k++) mean += b[k][ch] / K, sum2 += s2[k][ch];
        for (int k = 0; k < K; k++) { /* d_k = b_k - mean: var d_k = s_k^2 (1 - 2 / K) + sum_j s_j^2 / K^2 */
            double d = b[k][ch] - mean;
            e2 += (d * d - s2[k][ch] * (1.0 - 2.0 / K) - sum2 / ((double)K * K)) / K;
        }
        /* the reflected part's mean (the emission, constant on the patch, is no part of the
         * error), and the spread scaled to the area's (linear_spread) */
        m->mean[3 * i + ch] = fmax(0.0, mean - E[ch]), m->e[3 * i + ch] = e2 > 0 ? sqrt(e2 * f2) : 0.0;
    }
    m->known[i] = 1;
    return ULAM_OK;
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

/* A polygon and its share of the mesh error. */
typedef struct {
    double r;
    int64_t i;
} share;

/* Largest share first, ties by polygon number. */
static int cmp_share(const void *a, const void *b)
{
    const share *x = a, *y = b;
    if (x->r != y->r) return x->r > y->r ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
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
    share *sh = NULL;
    int status = mesh_init(&m, s, importance);
    for (int round = 0; !status; round++) {
        for (int64_t i = 0; i < m.np && !status && !in.interrupted; i++)
            if (m.live[i] && !m.known[i]) status = measure(&m, i, t, opts, t0, &in, err);
        if (status || in.interrupted) break;
        in.error = mesh_error(&m, NULL);
        if (round == 0) in.error0 = in.error;
        if ((in.met = in.error <= target)) break;
        if (round >= MAX_ROUNDS || !(sh = ulam__malloc((size_t)m.np, sizeof *sh))) {
            in.capped = round >= MAX_ROUNDS;
            if (!in.capped) status = ULAM_ENOMEM;
            break;
        }
        double *r = ulam__malloc((size_t)m.np, sizeof *r), rest = 0.0;
        if (!r) {
            status = ULAM_ENOMEM;
            break;
        }
        mesh_error(&m, r);
        int64_t ns = 0, np = m.np, nlive = m.nlive, made = 0;
        for (int64_t i = 0; i < np; i++)
            if (m.live[i]) sh[ns++] = (share){r[i], i}, rest += r[i];
        free(r);
        qsort(sh, (size_t)ns, sizeof *sh, cmp_share);
        for (int64_t k = 0; k < ns && rest > target && !status && sh[k].r > 0; k++) {
            int64_t i = sh[k].i;
            if (nlive - 1 + children(&m, i) > max_patches) {
                in.capped = 1;
                break;
            }
            if (area2(&m, m.idx + m.first[i], m.len[i]) < 1e-12 * total_area) continue; /* as fine as floats allow */
            status = split(&m, i);
            nlive = m.nlive, rest -= sh[k].r, made++;
        }
        free(sh), sh = NULL;
        in.splits += made, in.rounds++;
        if (!made) {
            in.capped = 1;
            break;
        }
    }
    if (!status) status = to_scene(&m, s, out);
    mesh_free(&m);
    free(sh);
    in.patches = *out ? (*out)->npatches : 0;
    in.seconds = ulam_now() - t0;
    if (info) *info = in;
    if (status == ULAM_ENOMEM) return ulam__fail(err, status, 0, -1, "memory for the adaptive mesh");
    return status;
}
