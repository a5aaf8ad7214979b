/* Edge lists as graph users hold them (SNAP, networkx's write_edgelist, igraph's "edgelist"):
 * one edge "u v" or "u v w" a line, fields separated by blanks, tabs or one comma; a line that
 * starts with '#' or '%' (after blanks) is a comment, a blank line is skipped; gzip-compressed
 * files are read through zlib.  Node ids are non-negative integers used as written: when some id
 * is 0 the ids are 0-based (n = largest id + 1), else 1-based (n = largest id).  The result is
 * the adjacency matrix A (A_uv = the summed weights of the edges u -> v, 1 an unweighted edge):
 * the same CSR a Matrix Market file of it gives. */
#include "internal.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <zlib.h>

enum { LINE_MAX_BYTES = 4096 };

/* True when s ends with suffix (case-insensitive). */
static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && !strcasecmp(s + n - k, suffix);
}

/* See ulam.h. */
int ulam_edgelist_is_file(const char *path)
{
    if (!path || ends_with(path, ".mtx") || ends_with(path, ".mtx.gz") || ends_with(path, ".mm") ||
        ends_with(path, ".mm.gz") || ends_with(path, ".ulam") || ends_with(path, ".ulamcache"))
        return 0;
    struct stat st;
    if (!stat(path, &st) && S_ISREG(st.st_mode) && st.st_size > 0) { /* the content decides (a pipe's is not read) */
        if (ulam_system_is_file(path)) return 0; /* a prepared system */
        gzFile z = gzopen(path, "rb");
        if (!z) return 0;
        char head[3] = "";
        int got = gzread(z, head, 2);
        gzclose(z);
        return got > 0 && strncmp(head, "%%", 2); /* no Matrix Market banner */
    }
    static const char *const named[] = {".txt", ".tsv", ".csv", ".edges", ".el", ".edgelist"};
    char base[4096];
    snprintf(base, sizeof base, "%s", path);
    if (ends_with(base, ".gz")) base[strlen(base) - 3] = '\0';
    for (size_t k = 0; k < sizeof named / sizeof named[0]; k++) /* a pipe is not peeked at: its name decides */
        if (ends_with(base, named[k])) return 1;
    return 0;
}

/* Parse a node id at *p (digits, at most 2^31 - 2) into *v, moving *p past it; 0 on failure. */
static int scan_id(const char **p, int64_t *v)
{
    const char *s = *p;
    int64_t x = 0;
    if (*s < '0' || *s > '9') return 0;
    while (*s >= '0' && *s <= '9') {
        x = x * 10 + (*s++ - '0');
        if (x > (int64_t)INT32_MAX - 1) return 0;
    }
    *v = x, *p = s;
    return 1;
}

/* Skip one separator run (blanks and tabs, with at most one comma among them); 0 if none. */
static int skip_sep(const char **p)
{
    const char *s = *p;
    int comma = 0;
    while (*s == ' ' || *s == '\t' || (*s == ',' && !comma)) comma |= *s++ == ',';
    int moved = s != *p;
    *p = s;
    return moved;
}

/* Growing edge arrays. */
typedef struct {
    int32_t *u, *v;
    double *w;
    int64_t len, cap;
} edges;

/* Grow *p (of elements of size sz) to cap elements; 0 on failure (*p kept). */
static int grow(void **p, size_t sz, int64_t cap)
{
    void *q = realloc(*p, (size_t)cap * sz);
    if (q) *p = q;
    return q != NULL;
}

/* Append an edge; ULAM_OK or ULAM_ENOMEM. */
static int edges_push(edges *e, int64_t u, int64_t v, double w)
{
    if (e->len == e->cap) {
        int64_t cap = e->cap < 1024 ? 1024 : e->cap + e->cap / 2;
        if (!grow((void **)&e->u, sizeof *e->u, cap) || !grow((void **)&e->v, sizeof *e->v, cap) ||
            !grow((void **)&e->w, sizeof *e->w, cap))
            return ULAM_ENOMEM;
        e->cap = cap;
    }
    e->u[e->len] = (int32_t)u, e->v[e->len] = (int32_t)v, e->w[e->len++] = w;
    return ULAM_OK;
}

/* One line's edge into e (comments and blank lines add nothing); ULAM_OK or a status with err
 * naming the line. */
static int parse_line(const char *s, long line, edges *e, int64_t *lo, int64_t *hi, ulam_error *err)
{
    while (*s == ' ' || *s == '\t') s++;
    if (!strncasecmp(s, "%%MatrixMarket", 14)) /* read as an edge list, its size line would be an edge */
        return ulam__fail(err, ULAM_ESYNTAX, line, -1, "an edge list, got a Matrix Market banner (name the file .mtx)");
    if (!*s || *s == '#' || *s == '%' || *s == '\r' || *s == '\n') return ULAM_OK;
    int64_t u, v;
    double w = 1.0;
    const char *p = s;
    int ok = scan_id(&p, &u) && skip_sep(&p) && scan_id(&p, &v);
    if (ok && skip_sep(&p) && *p && *p != '\r' && *p != '\n' && *p != '#') { /* a weight */
        char *end;
        errno = 0;
        w = strtod(p, &end);
        ok = end != p;
        p = end;
        if (ok && !(isfinite(w) && w >= 0.0))
            return ulam__fail(err, ULAM_ERANGE, line, -1, "an edge weight that is finite and >= 0, got '%.40s'", s);
        skip_sep(&p);
    }
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') p++;
    if (!ok || (*p && *p != '#'))
        return ulam__fail(err, ULAM_ESYNTAX, line, -1,
                          "an edge 'u v' or 'u v weight' (node ids: integers from 0 to 2147483646; separated by "
                          "blanks, tabs or a comma), got '%.60s'", s);
    if (u < *lo) *lo = u;
    if (v < *lo) *lo = v;
    if (u > *hi) *hi = u;
    if (v > *hi) *hi = v;
    return w > 0.0 && edges_push(e, u, v, w) ? ulam__fail(err, ULAM_ENOMEM, line, -1, "memory for the edges") : ULAM_OK;
}

/* See ulam.h. */
int ulam_edgelist_read(const char *path, ulam_csr **A, int64_t *base, ulam_error *err)
{
    ulam__clear(err);
    if (!path || !A) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a path and an output pointer");
    *A = NULL;
    struct stat st;
    errno = 0;
    gzFile z = !stat(path, &st) && S_ISDIR(st.st_mode) ? NULL : gzopen(path, "rb");
    if (!z && !errno) errno = EISDIR;
    if (!z) return ulam__fail(err, ULAM_EIO, 0, -1, "a readable file (%s)", strerror(errno ? errno : ENOENT));
    enum { CHUNK = 1 << 18 };
    char *buf = malloc(CHUNK + LINE_MAX_BYTES + 1);
    edges e = {0};
    int64_t lo = INT64_MAX, hi = -1;
    long line = 0;
    size_t have = 0; /* bytes of an unfinished line at buf's start */
    int status = buf ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a read buffer");
    for (int got = 1; !status && got > 0;) {
        got = gzread(z, buf + have, CHUNK);
        if (got < 0) break;
        size_t end = have + (size_t)got, at = 0;
        if (got == 0 && have) buf[end++] = '\n'; /* the last line has no newline */
        for (char *nl; !status && (nl = memchr(buf + at, '\n', end - at));) {
            *nl = '\0';
            line++;
            if (memchr(buf + at, '\0', (size_t)(nl - (buf + at))))
                status = ulam__fail(err, ULAM_ESYNTAX, line, -1, "a text line with no NUL byte (the file is binary or damaged)");
            else
                status = parse_line(buf + at, line, &e, &lo, &hi, err);
            at = (size_t)(nl - buf) + 1;
        }
        have = end - at;
        if (!status && have > LINE_MAX_BYTES)
            status = ulam__fail(err, ULAM_ESYNTAX, line + 1, -1, "a line of at most %d bytes", LINE_MAX_BYTES);
        memmove(buf, buf + at, have);
    }
    int zerr = Z_OK;
    const char *zmsg = gzerror(z, &zerr);
    if (!status && zerr != Z_OK && zerr != Z_STREAM_END)
        status = ulam__fail(err, zerr == Z_ERRNO ? ULAM_EIO : ULAM_ESYNTAX, line, -1, "a readable, intact file (%s)",
                            zerr == Z_ERRNO ? strerror(errno) : zmsg);
    gzclose(z);
    free(buf);
    if (!status && e.len == 0)
        status = ulam__fail(err, ULAM_EEMPTY, line, -1, "an edge list with at least one edge 'u v' (read %ld lines)", line);
    if (!status && hi + 1 - (lo == 0 ? 0 : 1) > ULAM_MM_DIM_CAP(e.len)) /* as a Matrix Market size line */
        status = ulam__fail(err, ULAM_EOVERFLOW, 0, -1, "node ids up to %lld for %lld edges (the largest is %lld: "
                            "every node costs memory and time in each pass; renumber the ids 0..n-1)",
                            (long long)ULAM_MM_DIM_CAP(e.len), (long long)e.len, (long long)hi);
    if (!status) {
        int64_t b = lo == 0 ? 0 : 1, n = hi + 1 - b;
        if (b)
            for (int64_t k = 0; k < e.len; k++) e.u[k]--, e.v[k]--;
        status = ulam_csr_from_triplets(n, n, e.len, e.u, e.v, e.w, A);
        if (status) ulam__fail(err, status, 0, -1, "memory for the adjacency matrix (%lld nodes, %lld edges)",
                               (long long)n, (long long)e.len);
        if (base) *base = b;
    }
    free(e.u), free(e.v), free(e.w);
    return status;
}
