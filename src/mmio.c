/* Matrix Market input and output (https://math.nist.gov/MatrixMarket/formats.html).
 *
 * Reading is streamed through a growing buffer; integers are scanned by hand and reals
 * with strtod, so a file parses at hundreds of MB/s.  Duplicated coordinates are summed (a
 * file may hold more entries than rows x columns, as SciPy reads it), explicit zeros dropped,
 * symmetric and skew-symmetric files expanded to full storage.  A comment line may be indented;
 * a NUL byte in a line is refused (a binary or damaged file).  A gzip-compressed file is read
 * through zlib when opened by its path, and named as such when given as an open FILE. */
#include "mmio.h"
#include "defaults.h"
#include "csr.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

enum { FMT_COORD, FMT_ARRAY };
enum { FLD_REAL, FLD_INTEGER, FLD_PATTERN };
enum { SYM_GENERAL, SYM_SYMMETRIC, SYM_SKEW };

/* The longest line read (a Matrix Market line holds a few numbers; a comment rarely more than a
 * screen): past it the input is refused, never buffered whole (5 GB of zeros with no newline). */
enum { MM_LINE_MAX = 1 << 20 };

/* A buffered line reader that counts lines. */
typedef struct {
    FILE *f;
    char *buf;
    size_t cap, len, pos;
    long line;
    int eof;
    int toolong;       /* the failure was a line past MM_LINE_MAX, not a NUL byte */
    int64_t size;      /* bytes from the start position to the end of a regular file, or -1 */
    int64_t read_total; /* bytes fread so far */
} reader;

typedef struct {
    int format, field, symmetry;
    int64_t m, n, nnz; /* nnz: declared entries (m*n for array) */
} mm_header;

/* Growing triplet arrays. */
typedef struct {
    int32_t *i, *j;
    double *x;
    int64_t len, cap;
} triplets;

/* Open a reader over f. */
static int reader_init(reader *r, FILE *f)
{
    memset(r, 0, sizeof *r);
    r->f = f;
    r->cap = 1 << 16;
    r->buf = malloc(r->cap);
    r->size = -1;
    struct stat st;
    if (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode)) {
        long at = ftell(f);
        r->size = (int64_t)st.st_size - (at > 0 ? at : 0);
    }
    return r->buf ? ULAM_OK : ULAM_ENOMEM;
}

/* Refill the buffer, growing it when a line does not fit. */
static int reader_fill(reader *r)
{
    memmove(r->buf, r->buf + r->pos, r->len - r->pos);
    r->len -= r->pos;
    r->pos = 0;
    if (r->cap - r->len < 2) {
        if (r->cap > SIZE_MAX / 2) return ULAM_ENOMEM;
        char *nb = realloc(r->buf, r->cap * 2);
        if (!nb) return ULAM_ENOMEM;
        r->buf = nb;
        r->cap *= 2;
    } else if (r->cap < (1u << 20) && r->read_total > 0) {
        char *nb = realloc(r->buf, 1u << 20); /* big reads once the header is past */
        if (nb) {
            r->buf = nb;
            r->cap = 1u << 20;
        }
    }
    size_t got = fread(r->buf + r->len, 1, r->cap - r->len - 1, r->f);
    r->len += got;
    r->read_total += (int64_t)got;
    if (got == 0) {
        if (ferror(r->f)) return ULAM_EIO;
        r->eof = 1;
    }
    return ULAM_OK;
}

/* The next line, NUL-terminated without its newline (or CR LF); NULL at end of input. */
static char *reader_next(reader *r, int *status)
{
    *status = ULAM_OK;
    for (;;) {
        char *start = r->buf + r->pos;
        char *nl = memchr(start, '\n', r->len - r->pos);
        if (nl || (r->eof && r->pos < r->len)) {
            char *end = nl ? nl : r->buf + r->len;
            int nul = memchr(start, '\0', (size_t)(end - start)) != NULL;
            *end = '\0';
            if (end > start && end[-1] == '\r') end[-1] = '\0';
            r->pos = (size_t)(end - r->buf) + (nl ? 1 : 0);
            r->line++;
            if (nul) { /* the text would end at the NUL: a value cut short is not read as another */
                *status = ULAM_ESYNTAX;
                return NULL;
            }
            return start;
        }
        if (r->eof) return NULL;
        /* a line not yet ended: a NUL in it, or more than MM_LINE_MAX bytes, is refused before reading on */
        if (memchr(start, '\0', r->len - r->pos) || (r->toolong = r->len - r->pos > MM_LINE_MAX)) {
            r->line++;
            *status = ULAM_ESYNTAX;
            return NULL;
        }
        if ((*status = reader_fill(r)) != ULAM_OK) return NULL;
    }
}

/* A failure of reader_next (status) at the reader's line, with err filled. */
static int read_failure(const reader *r, int status, ulam_error *err)
{
    if (status == ULAM_ESYNTAX && r->toolong)
        return ulam__fail(err, status, r->line, -1, "a text line of at most %d bytes (this one is longer: the file is "
                                                    "binary or damaged)", MM_LINE_MAX);
    if (status == ULAM_ESYNTAX)
        return ulam__fail(err, status, r->line, -1, "a text line with no NUL byte (the file is binary or damaged)");
    return ulam__fail(err, status, r->line, -1, status == ULAM_ENOMEM ? "memory for a line" : "a readable file");
}

/* Bytes of input not yet handed out as lines, or -1 when unknown (a pipe). */
static int64_t reader_bytes_left(const reader *r)
{
    return r->size < 0 ? -1 : r->size - r->read_total + (int64_t)(r->len - r->pos);
}

/* Skip blanks and tabs. */
static const char *skip_ws(const char *p)
{
    while (*p == ' ' || *p == '\t') p++;
    return p;
}

/* True when p holds only blanks up to the end of the line. */
static int at_end(const char *p)
{
    return *skip_ws(p) == '\0';
}

/* Scan a decimal integer (optional sign); 0 on success, -1 if none, 1 on overflow. */
static int scan_int(const char **pp, int64_t *v)
{
    const char *p = skip_ws(*pp);
    int neg = 0;
    if (*p == '+' || *p == '-') neg = *p++ == '-';
    if (*p < '0' || *p > '9') return -1;
    uint64_t acc = 0;
    int over = 0;
    for (; *p >= '0' && *p <= '9'; p++) {
        if (acc > (UINT64_MAX - 9) / 10) over = 1;
        else acc = acc * 10 + (uint64_t)(*p - '0');
    }
    if (*p && *p != ' ' && *p != '\t') return -1; /* "12abc" or "1.5" is not an integer */
    *pp = p;
    if (over || acc > (uint64_t)INT64_MAX) return 1;
    *v = neg ? -(int64_t)acc : (int64_t)acc;
    return 0;
}

/* Scan a real number (ulam_strtod); 0 on success, -1 if malformed, 2 if NaN or infinite. */
static int scan_real(const char **pp, double *v)
{
    const char *p = skip_ws(*pp);
    char *end;
    errno = 0;
    double x = ulam_strtod(p, &end);
    if (end == p || (*end && *end != ' ' && *end != '\t')) return -1;
    *pp = end;
    *v = x;
    return isfinite(x) ? 0 : 2;
}

/* Case-insensitive match of the next word; advances past it. */
static int next_word(const char **pp, const char *word)
{
    const char *p = skip_ws(*pp);
    size_t n = strlen(word);
    if (strncasecmp(p, word, n) != 0 || (p[n] && p[n] != ' ' && p[n] != '\t')) return 0;
    *pp = p + n;
    return 1;
}

/* Pick which of the words comes next; -1 if none. */
static int pick_word(const char **pp, const char *const *words, int nwords)
{
    for (int k = 0; k < nwords; k++)
        if (next_word(pp, words[k])) return k;
    return -1;
}

/* The next word, for messages (up to 31 characters). */
static void peek_word(const char *p, char out[32])
{
    p = skip_ws(p);
    size_t k = 0;
    while (p[k] && p[k] != ' ' && p[k] != '\t' && k < 31) {
        out[k] = p[k];
        k++;
    }
    out[k] = '\0';
}

/* Parse the banner line into h. */
static int parse_banner(reader *r, const char *name, const char *line, mm_header *h,
                        ulam_error *err)
{
    static const char *const formats[] = {"coordinate", "array"};
    static const char *const fields[] = {"real", "integer", "pattern", "double"};
    static const char *const symms[] = {"general", "symmetric", "skew-symmetric"};
    char word[32];
    const char *p = line;
    if (strncasecmp(p, "%%MatrixMarket", 14) != 0 || (p[14] != ' ' && p[14] != '\t'))
        return ulam__fail(err, ULAM_EBANNER, r->line, -1,
                          "a first line starting with '%%%%MatrixMarket matrix' in %s", name);
    p += 14;
    if (!next_word(&p, "matrix")) {
        peek_word(p, word);
        return ulam__fail(err, ULAM_EBANNER, r->line, -1,
                          "object 'matrix' in the banner, found '%s'", word);
    }
    if ((h->format = pick_word(&p, formats, 2)) < 0) {
        peek_word(p, word);
        return ulam__fail(err, ULAM_EBANNER, r->line, -1,
                          "format 'coordinate' or 'array' in the banner, found '%s'", word);
    }
    if ((h->field = pick_word(&p, fields, 4)) < 0) {
        peek_word(p, word);
        int known = !strcasecmp(word, "complex");
        return ulam__fail(err, known ? ULAM_EUNSUPPORTED : ULAM_EBANNER, r->line, -1,
                          "field 'real', 'integer' or 'pattern'%s, found '%s'",
                          known ? " (complex matrices are not supported)" : "", word);
    }
    if (h->field == 3) h->field = FLD_REAL;
    if ((h->symmetry = pick_word(&p, symms, 3)) < 0) {
        peek_word(p, word);
        int known = !strcasecmp(word, "hermitian");
        return ulam__fail(err, known ? ULAM_EUNSUPPORTED : ULAM_EBANNER, r->line, -1,
                          "symmetry 'general', 'symmetric' or 'skew-symmetric'%s, found '%s'",
                          known ? " (hermitian needs complex values)" : "", word);
    }
    if (!at_end(p))
        return ulam__fail(err, ULAM_EBANNER, r->line, -1,
                          "nothing after the symmetry word in the banner");
    if (h->format == FMT_ARRAY && h->field == FLD_PATTERN)
        return ulam__fail(err, ULAM_EBANNER, r->line, -1,
                          "a real or integer field: 'array pattern' is not a Matrix Market kind");
    if (h->format == FMT_ARRAY && h->symmetry != SYM_GENERAL)
        return ulam__fail(err, ULAM_EUNSUPPORTED, r->line, -1,
                          "'array general': symmetric dense arrays are not supported");
    return ULAM_OK;
}

/* The next line that is neither blank nor a comment; NULL at end of input. */
static char *next_data_line(reader *r, int *status)
{
    char *line;
    while ((line = reader_next(r, status)) != NULL)
        if (*skip_ws(line) != '%' && !at_end(line)) return line; /* a comment may be indented */
    return NULL;
}

/* Read the banner, comments and size line; check the sizes before anything is allocated. */
static int read_header(reader *r, const char *name, mm_header *h, ulam_error *err)
{
    int status = r->len < 2 ? reader_fill(r) : ULAM_OK;
    if (!status && r->len < 2 && !r->eof) status = reader_fill(r);
    if (!status && r->len >= 2 && (unsigned char)r->buf[0] == 0x1f && (unsigned char)r->buf[1] == 0x8b)
        return ulam__fail(err, ULAM_EUNSUPPORTED, 1, -1, "a Matrix Market text file: %s is gzip-compressed (open it "
                          "by its path, which reads it through zlib, or gunzip it)", name);
    char *line = status ? NULL : reader_next(r, &status);
    if (status) return read_failure(r, status, err);
    if (!line)
        return ulam__fail(err, ULAM_EEMPTY, 1, -1,
                          "a '%%%%MatrixMarket' banner, found an empty file");
    if ((status = parse_banner(r, name, line, h, err)) != ULAM_OK) return status;
    line = next_data_line(r, &status);
    if (status) return read_failure(r, status, err);
    if (!line)
        return ulam__fail(err, ULAM_ESIZELINE, r->line + 1, -1,
                          "a size line after the banner, found end of file");
    const char *p = line;
    int64_t v[3] = {0, 0, 0};
    int want = h->format == FMT_COORD ? 3 : 2;
    for (int k = 0; k < want; k++) {
        int s = scan_int(&p, &v[k]);
        if (s < 0)
            return ulam__fail(err, ULAM_ESIZELINE, r->line, -1,
                              "a size line of %d integers (%s)", want,
                              want == 3 ? "rows columns entries" : "rows columns");
        if (s > 0 || v[k] > (k < 2 ? (int64_t)ULAM_MAX_DIM : INT64_MAX / 32))
            return ulam__fail(err, ULAM_EOVERFLOW, r->line, -1,
                              "%s at most %lld", k < 2 ? "dimensions" : "an entry count",
                              (long long)(k < 2 ? ULAM_MAX_DIM : INT64_MAX / 32));
    }
    if (!at_end(p))
        return ulam__fail(err, ULAM_ESIZELINE, r->line, -1,
                          "exactly %d integers on the size line", want);
    if (v[0] < 1 || v[1] < 1 || v[2] < 0)
        return ulam__fail(err, ULAM_ESIZELINE, r->line, -1,
                          "positive dimensions and a nonnegative entry count");
    h->m = v[0];
    h->n = v[1];
    h->nnz = h->format == FMT_COORD ? v[2] : v[0] * v[1];
    if (h->symmetry != SYM_GENERAL && h->m != h->n)
        return ulam__fail(err, ULAM_ENOTSQUARE, r->line, -1,
                          "a square matrix for a symmetric file, got %lld x %lld",
                          (long long)h->m, (long long)h->n);
    /* Dimensions the entries justify (ULAM_MM_DIM_CAP): every row and column costs memory and
     * time in whatever reads M next (a pass, a radius, a transpose), so a short file must not
     * declare millions of them.  A vector (n = 1) is held dense anyway: its cap is higher. */
    int64_t dim_cap = h->n == 1 ? ((int64_t)1 << 24) + 64 * h->nnz : ULAM_MM_DIM_CAP(h->nnz); /* no overflow */
    if (h->format == FMT_COORD && (h->m > dim_cap || h->n > dim_cap))
        return ulam__fail(err, ULAM_EOVERFLOW, r->line, -1,
                          "dimensions at most %s + 64 x entries = %lld (a size line of %lld x %lld with "
                          "%lld entries declares mostly empty rows, which cost memory and time in every pass)",
                          h->n == 1 ? "2^24" : "2^16", (long long)dim_cap, (long long)h->m, (long long)h->n,
                          (long long)h->nnz);
    int64_t left = reader_bytes_left(r);
    int min_bytes = h->format == FMT_ARRAY ? 2 : (h->field == FLD_PATTERN ? 4 : 6);
    if (left >= 0 && h->nnz > left / min_bytes + 1)
        return ulam__fail(err, ULAM_ETOOFEW, r->line, -1,
                          "%lld entries as the size line says, but the rest of the file "
                          "(%lld bytes) can hold at most %lld",
                          (long long)h->nnz, (long long)left, (long long)(left / min_bytes + 1));
    return ULAM_OK;
}

/* Free triplet arrays. */
static void triplets_free(triplets *t)
{
    free(t->i);
    free(t->j);
    free(t->x);
    memset(t, 0, sizeof *t);
}

/* Make room for one more triplet. */
static int triplets_push(triplets *t, int32_t i, int32_t j, double x)
{
    if (t->len == t->cap) {
        int64_t cap = t->cap < 16 ? 16 : t->cap + t->cap / 2;
        int32_t *ni = realloc(t->i, (size_t)cap * sizeof *ni);
        if (ni) t->i = ni;
        int32_t *nj = realloc(t->j, (size_t)cap * sizeof *nj);
        if (nj) t->j = nj;
        double *nx = realloc(t->x, (size_t)cap * sizeof *nx);
        if (nx) t->x = nx;
        if (!ni || !nj || !nx) return ULAM_ENOMEM;
        t->cap = cap;
    }
    t->i[t->len] = i;
    t->j[t->len] = j;
    t->x[t->len++] = x;
    return ULAM_OK;
}

/* Reserve room for the triplets the size line announces, but at most 2^20 up front: a hostile
 * size line must not make the reader allocate what the file does not hold (more entries grow
 * the arrays by doubling). */
static int triplets_reserve(triplets *t, int64_t cap)
{
    if (cap > ((int64_t)1 << 20)) cap = (int64_t)1 << 20;
    if (cap < 1) cap = 1;
    t->i = ulam__malloc((size_t)cap, sizeof *t->i);
    t->j = ulam__malloc((size_t)cap, sizeof *t->j);
    t->x = ulam__malloc((size_t)cap, sizeof *t->x);
    t->cap = cap;
    return t->i && t->j && t->x ? ULAM_OK : ULAM_ENOMEM;
}

/* Parse one index field: 1..limit. */
static int parse_index(long line, const char **p, int64_t limit, const char *what, int64_t *out,
                       ulam_error *err)
{
    int s = scan_int(p, out);
    if (s < 0)
        return ulam__fail(err, ULAM_ESYNTAX, line, -1, "an integer %s index", what);
    if (s > 0 || *out < 1 || *out > limit)
        return ulam__fail(err, ULAM_EINDEX, line, -1, "a %s index between 1 and %lld", what,
                          (long long)limit);
    return ULAM_OK;
}

/* Parse one value field according to the header's field. */
static int parse_value(long line, const char **p, const mm_header *h, double *x, ulam_error *err)
{
    if (h->field == FLD_PATTERN) {
        *x = 1.0;
        return ULAM_OK;
    }
    if (h->field == FLD_INTEGER) {
        int64_t v;
        int s = scan_int(p, &v);
        if (s < 0) return ulam__fail(err, ULAM_ESYNTAX, line, -1, "an integer value");
        if (s > 0) return ulam__fail(err, ULAM_EOVERFLOW, line, -1, "a 64-bit integer value");
        *x = (double)v;
        return ULAM_OK;
    }
    int s = scan_real(p, x);
    if (s < 0) return ulam__fail(err, ULAM_ESYNTAX, line, -1, "a real value");
    if (s > 0)
        return ulam__fail(err, ULAM_ENONFINITE, line, -1, "a finite real value (no NaN or Inf)");
    return ULAM_OK;
}

/* Parse one coordinate entry line into (i, j, x), 1-based indices. */
static int parse_coord(long line, const char *text, const mm_header *h, int64_t *i, int64_t *j,
                       double *x, ulam_error *err)
{
    const char *p = text;
    int status;
    if ((status = parse_index(line, &p, h->m, "row", i, err))) return status;
    if ((status = parse_index(line, &p, h->n, "column", j, err))) return status;
    if ((status = parse_value(line, &p, h, x, err))) return status;
    if (!at_end(p))
        return ulam__fail(err, ULAM_ESYNTAX, line, -1, "%s on an entry line",
                          h->field == FLD_PATTERN ? "two indices only" : "two indices and a value only");
    if (h->symmetry == SYM_SKEW && *i == *j)
        return ulam__fail(err, ULAM_EINDEX, line, -1,
                          "no diagonal entries in a skew-symmetric file");
    return ULAM_OK;
}

/* Add an entry and, for symmetric kinds, its mirror; zeros are dropped. */
static int add_entry(triplets *t, const mm_header *h, int64_t i, int64_t j, double x)
{
    if (x == 0.0) return ULAM_OK;
    int status = triplets_push(t, (int32_t)(i - 1), (int32_t)(j - 1), x);
    if (status || h->symmetry == SYM_GENERAL || i == j) return status;
    return triplets_push(t, (int32_t)(j - 1), (int32_t)(i - 1), h->symmetry == SYM_SKEW ? -x : x);
}

/* Read every entry after the header into t, checking the count. */
static int read_entries(reader *r, const mm_header *h, triplets *t, ulam_error *err)
{
    int status = triplets_reserve(t, h->nnz);
    if (status) return ulam__fail(err, status, r->line, -1, "memory for %lld entries", (long long)h->nnz);
    char *line;
    int64_t k = 0;
    for (; (line = next_data_line(r, &status)) != NULL; k++) {
        if (k == h->nnz)
            return ulam__fail(err, ULAM_ETOOMANY, r->line, -1,
                              "%lld entries as the size line says, found more", (long long)h->nnz);
        int64_t i, j;
        double x;
        if (h->format == FMT_COORD) {
            if ((status = parse_coord(r->line, line, h, &i, &j, &x, err))) return status;
        } else {
            const char *p = line;
            if ((status = parse_value(r->line, &p, h, &x, err))) return status;
            if (!at_end(p))
                return ulam__fail(err, ULAM_ESYNTAX, r->line, -1, "one value per line in an array");
            i = k % h->m + 1;
            j = k / h->m + 1;
        }
        if ((status = add_entry(t, h, i, j, x)))
            return ulam__fail(err, status, r->line, -1, "memory for the entries");
    }
    if (status) return read_failure(r, status, err);
    if (k < h->nnz)
        return ulam__fail(err, ULAM_ETOOFEW, r->line, -1,
                          "%lld entries as the size line says, found %lld before the end of file",
                          (long long)h->nnz, (long long)k);
    return ULAM_OK;
}

/* Read header and entries of f into triplets. */
static int read_all(FILE *f, const char *name, mm_header *h, triplets *t, ulam_error *err)
{
    reader r;
    memset(t, 0, sizeof *t);
    memset(h, 0, sizeof *h);
    if (reader_init(&r, f)) {
        free(r.buf);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a read buffer");
    }
    int status = read_header(&r, name, h, err);
    if (!status) status = read_entries(&r, h, t, err);
    free(r.buf);
    if (status) triplets_free(t);
    return status;
}

/* A byte range [pos, end) of a file read by pread through a growing buffer, line by line. */
typedef struct {
    int fd;
    int64_t pos, end;
    char *buf;
    size_t cap, len, at;
    int failed; /* 1 a malformed line or a read error, 2 no memory */
    int toolong, nul; /* the malformed line: past MM_LINE_MAX, or holding a NUL byte */
} span;

/* The next line of the span, NUL-terminated without its newline (or CR LF), as reader_next
 * gives it; NULL at the end (or on failure: s->failed). */
static char *span_next(span *s)
{
    for (;;) {
        char *start = s->buf + s->at;
        char *nl = memchr(start, '\n', s->len - s->at);
        if (nl || (s->pos == s->end && s->at < s->len)) {
            char *e = nl ? nl : s->buf + s->len;
            if (memchr(start, '\0', (size_t)(e - start))) return s->failed = s->nul = 1, NULL; /* the sequential reader locates it */
            *e = '\0';
            if (e > start && e[-1] == '\r') e[-1] = '\0';
            s->at = (size_t)(e - s->buf) + (nl ? 1 : 0);
            return start;
        }
        if (s->pos == s->end) return NULL;
        if ((s->toolong = s->len - s->at > MM_LINE_MAX) || memchr(start, '\0', s->len - s->at))
            return s->failed = 1, s->nul = !s->toolong, NULL; /* the sequential reader locates it, never buffering past MM_LINE_MAX */
        memmove(s->buf, start, s->len - s->at);
        s->len -= s->at, s->at = 0;
        if (s->cap - s->len < 2) {
            char *nb = s->cap < SIZE_MAX / 2 ? realloc(s->buf, s->cap * 2) : NULL;
            if (!nb) return s->failed = 2, NULL;
            s->buf = nb, s->cap *= 2;
        }
        size_t want = s->cap - s->len - 1;
        if ((int64_t)want > s->end - s->pos) want = (size_t)(s->end - s->pos);
        ssize_t got = pread(s->fd, s->buf + s->len, want, (off_t)s->pos);
        if (got <= 0) return s->failed = 1, NULL;
        s->pos += got, s->len += (size_t)got;
    }
}

/* One chunk of the entries: a byte range starting at a line, and the entries parsed from it
 * (rows, columns, values, in file order). */
typedef struct {
    int64_t from, to;
    int32_t *row, *col;
    double *val;
    int64_t len, cap;
    int sorted, zeros, bad, nomem;
} chunk;

enum { CHUNK_BUF = 1 << 20 };

/* The first line start at or after byte at (at > from: the byte after a newline), or end. */
static int64_t line_start(int fd, int64_t at, int64_t end)
{
    char b[4096];
    for (at--; at < end;) {
        ssize_t got = pread(fd, b, sizeof b, (off_t)at);
        if (got <= 0) return end;
        char *nl = memchr(b, '\n', (size_t)got);
        if (nl) return at + (nl - b) + 1 < end ? at + (nl - b) + 1 : end;
        at += got;
    }
    return end;
}

/* Room for one more entry in chunk c. */
static int chunk_grow(chunk *c)
{
    if (c->len < c->cap) return ULAM_OK;
    int64_t cap = c->cap, need = c->len + 1 + c->len / 2;
    if (ulam__grow(&c->row, &cap, need, sizeof *c->row)) return ULAM_ENOMEM;
    cap = c->cap;
    if (ulam__grow(&c->col, &cap, need, sizeof *c->col)) return ULAM_ENOMEM;
    cap = c->cap;
    if (ulam__grow(&c->val, &cap, need, sizeof *c->val)) return ULAM_ENOMEM;
    c->cap = cap;
    return ULAM_OK;
}

/* Free chunk c's entries. */
static void chunk_free(chunk *c)
{
    free(c->row), free(c->col), free(c->val);
    c->row = c->col = NULL, c->val = NULL;
}

/* Parse chunk c's entries, noting whether its rows rise and whether it holds zeros.  Any
 * failure (a malformed line) marks it bad: the sequential reader then finds and locates the
 * error. */
static void parse_chunk(int fd, const mm_header *h, chunk *c)
{
    span s = {.fd = fd, .pos = c->from, .end = c->to, .cap = CHUNK_BUF};
    s.buf = malloc(s.cap);
    c->sorted = 1;
    int32_t prev = -1;
    char *line;
    while (s.buf && !c->bad && (line = span_next(&s)) != NULL) {
        if (*skip_ws(line) == '%' || at_end(line)) continue;
        int64_t i, j;
        double x;
        if (parse_coord(0, line, h, &i, &j, &x, NULL)) {
            c->bad = 1;
            break;
        }
        if (chunk_grow(c)) {
            c->bad = c->nomem = 1;
            break;
        }
        c->row[c->len] = (int32_t)(i - 1), c->col[c->len] = (int32_t)(j - 1), c->val[c->len++] = x;
        c->sorted &= (int32_t)(i - 1) >= prev;
        prev = (int32_t)(i - 1);
        c->zeros |= x == 0.0;
    }
    if (!s.buf || s.failed == 2) c->bad = c->nomem = 1;
    if (s.failed) c->bad = 1;
    free(s.buf);
}

/* The entries of a regular file of coordinate general kind, in parallel: chunks split at line
 * starts are parsed by `threads` threads, then moved in file order into the CSR arrays (each
 * chunk freed as it is moved, so the peak is about the entries once) without the zeros, which
 * the sequential reader never stores.  Rows that rise through the file (as written by most
 * tools) need no reordering: rowptr is counted as the rows go by; otherwise the triplets are
 * sorted as the sequential reader sorts them.  ULAM_OK with *out, ULAM_ENOMEM, or -1 when
 * anything disagrees (the caller then reads sequentially from where the header ended, which
 * finds and locates every error). */
static int read_entries_parallel(int fd, int64_t data, int64_t end, const mm_header *h, int threads,
                                 ulam_csr **out)
{
    int64_t bytes = end - data;
    int nc = threads * 8;
    if (bytes < (int64_t)nc * 65536) nc = bytes / 65536 > 0 ? (int)(bytes / 65536) : 1;
    chunk *c = calloc((size_t)nc, sizeof *c);
    if (!c) return ULAM_ENOMEM;
    for (int k = 0; k < nc; k++) {
        c[k].from = k ? c[k - 1].to : data;
        c[k].to = k == nc - 1 ? end : line_start(fd, data + bytes / nc * (k + 1), end);
        if (c[k].to < c[k].from) c[k].to = c[k].from;
        c[k].cap = 0;
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int k = 0; k < nc; k++) parse_chunk(fd, h, &c[k]);
    int64_t total = 0;
    int bad = 0, nomem = 0, sorted = 1;
    int32_t prev = -1;
    for (int k = 0; k < nc; k++) {
        total += c[k].len, bad |= c[k].bad, nomem |= c[k].nomem;
        if (!c[k].len) continue;
        sorted &= c[k].sorted && c[k].row[0] >= prev;
        prev = c[k].row[c[k].len - 1];
    }
    ulam_csr *A = !bad && total == h->nnz ? ulam_csr_alloc(h->m, h->n, total) : NULL;
    int32_t *ti = A && !sorted ? ulam__alloc_big((size_t)total, sizeof *ti) : NULL;
    int status = nomem || (A && !sorted && !ti) || (!A && !bad && total == h->nnz) ? ULAM_ENOMEM : A ? ULAM_OK : -1;
    int64_t nz = 0;
    for (int k = 0; k < nc; k++) {
        for (int64_t q = 0; !status && q < c[k].len; q++) {
            if (c[k].zeros && c[k].val[q] == 0.0) continue;
            if (sorted) A->rowptr[c[k].row[q] + 1]++;
            else ti[nz] = c[k].row[q];
            A->colidx[nz] = c[k].col[q], A->val[nz++] = c[k].val[q];
        }
        chunk_free(&c[k]);
    }
    free(c);
    if (!status && sorted) {
        for (int64_t i = 0; i < h->m; i++) A->rowptr[i + 1] += A->rowptr[i];
        status = ulam__csr_canonicalize(A, threads);
    } else if (!status) {
        ulam_csr *B = NULL;
        status = ulam_csr_from_triplets(h->m, h->n, nz, ti, A->colidx, A->val, &B);
        ulam_csr_free(A);
        A = B;
    }
    free(ti);
    if (status) {
        ulam_csr_free(A);
        return status;
    }
    *out = A;
    return ULAM_OK;
}

/* The header of a coordinate Matrix Market file opened at fd (named name), checked as the
 * sequential reader checks it, for reading its entries by byte ranges (ulam__mm_read_range). */
int ulam__mm_coord_header(int fd, const char *name, ulam__mm_coord *c, ulam_error *err)
{
    unsigned char magic[2] = {0, 0};
    if (pread(fd, magic, 2, 0) == 2 && magic[0] == 0x1f && magic[1] == 0x8b)
        return ulam__fail(err, ULAM_EUNSUPPORTED, 1, -1, "an uncompressed Matrix Market file (each rank reads a byte "
                                                         "range of it): gunzip %s", name);
    int fd2 = dup(fd);
    FILE *f = fd2 < 0 ? NULL : fdopen(fd2, "rb");
    if (!f) {
        if (fd2 >= 0) close(fd2);
        return ulam__fail(err, ULAM_EIO, 0, -1, "a readable file");
    }
    mm_header h = {0};
    reader r;
    int status = reader_init(&r, f) ? ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a read buffer")
                                    : read_header(&r, name, &h, err);
    if (!status && h.format != FMT_COORD)
        status = ulam__fail(err, ULAM_EUNSUPPORTED, 1, -1, "a coordinate Matrix Market file on a partition (a dense "
                                                           "array: prepare it with ulam prepare)");
    if (!status && h.m != h.n)
        status = ulam__fail(err, ULAM_ENOTSQUARE, r.line, -1, "a square matrix, got %lld x %lld", (long long)h.m,
                            (long long)h.n);
    if (!status && r.size < 0) status = ulam__fail(err, ULAM_EIO, 0, -1, "a regular file (each rank reads a byte range)");
    if (!status) {
        *c = (ulam__mm_coord){.n = h.n, .nnz = h.nnz, .field = h.field, .symmetry = h.symmetry, .lines = r.line};
        c->data = r.read_total - (int64_t)(r.len - r.pos); /* the byte after the size line */
        c->end = r.size;
    }
    free(r.buf);
    fclose(f);
    return status;
}

/* The first line start at or after byte at of a coordinate file's entries (c->end when none). */
int64_t ulam__mm_line_start(int fd, const ulam__mm_coord *c, int64_t at)
{
    return at <= c->data ? c->data : line_start(fd, at, c->end);
}

/* Add an entry and its mirror to a growing array (zeros dropped, as add_entry does). */
static int range_add(ulam__mm_entry **e, int64_t *len, int64_t *cap, const mm_header *h, int64_t i, int64_t j, double x)
{
    if (x == 0.0) return ULAM_OK;
    if (ulam__grow(e, cap, *len + 2, sizeof **e)) return ULAM_ENOMEM;
    (*e)[(*len)++] = (ulam__mm_entry){(int32_t)(i - 1), (int32_t)(j - 1), x};
    if (h->symmetry != SYM_GENERAL && i != j)
        (*e)[(*len)++] = (ulam__mm_entry){(int32_t)(j - 1), (int32_t)(i - 1), h->symmetry == SYM_SKEW ? -x : x};
    return ULAM_OK;
}

/* The entries of lines [from, to) of a coordinate file (from a line start), in file order with
 * their mirrors and without zeros, into *e (malloc'd, *len of them); *lines the lines read and
 * *entries the entry lines.  Errors are located at the line counted from `from` (1 its first); more
 * than limit entry lines fail there as the sequential reader's "found more" does. */
int ulam__mm_read_range(int fd, const ulam__mm_coord *c, int64_t from, int64_t to, int64_t limit, ulam__mm_entry **e,
                        int64_t *len, int64_t *entries, long *lines, ulam_error *err)
{
    mm_header h = {.format = FMT_COORD, .field = c->field, .symmetry = c->symmetry, .m = c->n, .n = c->n, .nnz = c->nnz};
    span s = {.fd = fd, .pos = from, .end = to, .cap = CHUNK_BUF};
    int64_t cap = 0;
    int status = ULAM_OK;
    *e = NULL, *len = 0, *entries = 0, *lines = 0;
    s.buf = malloc(s.cap);
    char *line;
    while (s.buf && !status && (line = span_next(&s)) != NULL) {
        ++*lines;
        if (*skip_ws(line) == '%' || at_end(line)) continue;
        if (*entries == limit) {
            status = ulam__fail(err, ULAM_ETOOMANY, *lines, -1, "%lld entries as the size line says, found more",
                                (long long)c->nnz);
            break;
        }
        int64_t i, j;
        double x;
        if ((status = parse_coord(*lines, line, &h, &i, &j, &x, err))) break;
        ++*entries;
        if ((status = range_add(e, len, &cap, &h, i, j, x))) ulam__fail(err, status, *lines, -1, "memory for the entries");
    }
    if (status) {
    } else if (!s.buf || s.failed == 2) status = ulam__fail(err, ULAM_ENOMEM, *lines + 1, -1, "memory for a line");
    else if (s.failed && s.toolong)
        status = ulam__fail(err, ULAM_ESYNTAX, *lines + 1, -1, "a text line of at most %d bytes (this one is longer: "
                                                               "the file is binary or damaged)", MM_LINE_MAX);
    else if (s.failed && s.nul)
        status = ulam__fail(err, ULAM_ESYNTAX, *lines + 1, -1, "a text line with no NUL byte (the file is binary or damaged)");
    else if (s.failed) status = ulam__fail(err, ULAM_EIO, *lines + 1, -1, "a readable file");
    free(s.buf);
    return status;
}

/* The reader's defaults. */
ulam_mm_opts ulam__mm_defaults(void)
{
    return (ulam_mm_opts){.threads = 0};
}

/* Read a sparse matrix from f with options o (NULL: the defaults). */
static int read_matrix(FILE *f, const char *name, const ulam_mm_opts *o, ulam_csr **A, ulam_error *err)
{
    ulam__clear(err);
    if (!f || !A) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a file and an output pointer");
    *A = NULL;
    ulam_mm_opts opts = o ? *o : ulam_mm_defaults();
    name = name ? name : "input";
    int threads = ulam__threads(opts.threads), fd = fileno(f);
    long start = ftell(f);
    mm_header h = {0};
    triplets t = {0};
    reader r;
    if (reader_init(&r, f)) {
        free(r.buf);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a read buffer");
    }
    int status = read_header(&r, name, &h, err);
    if (!status && threads > 1 && fd >= 0 && start >= 0 && r.size >= 0 && h.format == FMT_COORD &&
        h.symmetry == SYM_GENERAL && h.nnz > 0) {
        int64_t data = start + r.read_total - (int64_t)(r.len - r.pos); /* the byte after the size line */
        int st = read_entries_parallel(fd, data, start + r.size, &h, threads, A);
        if (st != -1) {
            free(r.buf);
            return st ? ulam__fail(err, st, 0, -1, "memory for %lld entries", (long long)h.nnz) : ULAM_OK;
        }
    }
    if (!status) status = read_entries(&r, &h, &t, err);
    free(r.buf);
    if (!status) {
        status = ulam_csr_from_triplets(h.m, h.n, t.len, t.i, t.j, t.x, A);
        if (status) ulam__fail(err, status, 0, -1, "memory to build the sparse matrix");
    }
    triplets_free(&t);
    return status;
}

/* Read a sparse matrix from f. */
int ulam__mm_read_matrix_file(FILE *f, const char *name, ulam_csr **A, ulam_error *err)
{
    return ulam_mm_read_matrix_opts(f, name, NULL, A, err);
}

/* Open path for reading, recording a failure in err (a directory opens, then reads as junk). */
static FILE *open_input(const char *path, ulam_error *err)
{
    FILE *f = path ? fopen(path, "rb") : NULL;
    struct stat st;
    if (f && !fstat(fileno(f), &st) && S_ISDIR(st.st_mode)) {
        fclose(f);
        errno = EISDIR, f = NULL;
    }
    if (!f) ulam__fail(err, ULAM_EIO, 0, -1, "a readable file (%s)", path ? strerror(errno) : "no path");
    return f;
}

/* *f itself, or when it starts with the gzip magic, a temporary file holding its bytes
 * decompressed through zlib (the original closed): ULAM_OK, or the status with err filled
 * (*f NULL). */
static int gunzipped(FILE **f, const char *path, ulam_error *err)
{
    struct stat st;
    if (fstat(fileno(*f), &st) || !S_ISREG(st.st_mode)) { /* a pipe: peek one byte, never rewind */
        int c = getc(*f);
        if (c == EOF) return ferror(*f) ? ulam__fail(err, ULAM_EIO, 0, -1, "a readable file (%s)", strerror(errno)) : ULAM_OK;
        ungetc(c, *f);
        if (c == 0x1f) /* zlib reads the descriptor, past what stdio has buffered: only a file can be gunzipped */
            return ulam__fail(err, ULAM_EUNSUPPORTED, 1, -1, "a Matrix Market text stream: %s looks gzip-compressed "
                                                              "(decompress it into the pipe: zcat FILE.gz)", path);
        return ULAM_OK;
    }
    unsigned char m[2];
    size_t got = fread(m, 1, 2, *f);
    rewind(*f);
    if (got < 2 || m[0] != 0x1f || m[1] != 0x8b) return ULAM_OK;
    int fd = dup(fileno(*f));
    fclose(*f);
    *f = NULL;
    gzFile z = fd >= 0 ? gzdopen(fd, "rb") : NULL;
    FILE *t = z ? tmpfile() : NULL;
    enum { CHUNK = 1 << 18 };
    char *buf = t ? malloc(CHUNK) : NULL, why[96] = "";
    int n = 0, ok = buf != NULL, zerr = 0;
    while (ok && (n = gzread(z, buf, CHUNK)) > 0) ok = fwrite(buf, 1, (size_t)n, t) == (size_t)n;
    if (z) {
        const char *msg = gzerror(z, &zerr); /* a stream cut short ends with Z_BUF_ERROR, not n < 0 */
        if (n < 0 || zerr == Z_BUF_ERROR || zerr == Z_DATA_ERROR) n = -1, snprintf(why, sizeof why, "%s", msg);
    }
    free(buf);
    if (z) gzclose(z);
    else if (fd >= 0) close(fd);
    if (!ok || n < 0 || !t || fflush(t)) {
        if (t) fclose(t);
        return n < 0 ? ulam__fail(err, ULAM_ESYNTAX, 0, -1, "an intact gzip stream (%s is gzip-compressed: %s)", path, why)
                     : ulam__fail(err, ULAM_EIO, 0, -1, "room to decompress %s (gzip-compressed)", path);
    }
    rewind(t);
    *f = t;
    return ULAM_OK;
}

/* Read a sparse matrix from path. */
int ulam_mm_read_matrix(const char *path, ulam_csr **A, ulam_error *err)
{
    ulam__clear(err);
    if (A) *A = NULL;
    FILE *f = open_input(path, err);
    if (!f) return ULAM_EIO;
    int gz = gunzipped(&f, path, err);
    if (gz) return gz;
    int status = ulam__mm_read_matrix_file(f, path, A, err);
    fclose(f);
    return status;
}

/* Read a dense n x 1 vector from f. */
static int read_vector_file(FILE *f, const char *name, double **x, int64_t *n, ulam_error *err)
{
    ulam__clear(err);
    if (!f || !x || !n) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a file and output pointers");
    *x = NULL;
    *n = 0;
    mm_header h;
    triplets t;
    int status = read_all(f, name ? name : "input", &h, &t, err);
    if (status) return status;
    if (h.n != 1) {
        triplets_free(&t);
        return ulam__fail(err, ULAM_EDIM, 0, -1, "a column vector (n x 1), got %lld x %lld",
                          (long long)h.m, (long long)h.n);
    }
    double *v = ulam__calloc((size_t)h.m, sizeof *v);
    if (!v) {
        triplets_free(&t);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld values", (long long)h.m);
    }
    for (int64_t k = 0; k < t.len; k++) v[t.i[k]] += t.x[k];
    triplets_free(&t);
    *x = v;
    *n = h.m;
    return ULAM_OK;
}

/* Read a dense vector from path. */
int ulam_mm_read_vector(const char *path, double **x, int64_t *n, ulam_error *err)
{
    ulam__clear(err);
    if (x) *x = NULL;
    FILE *f = open_input(path, err);
    if (!f) return ULAM_EIO;
    int gz = gunzipped(&f, path, err);
    if (gz) return gz;
    int status = read_vector_file(f, path, x, n, err);
    fclose(f);
    return status;
}

/* Write the optional one-line comment. */
static void write_comment(FILE *f, const char *comment)
{
    if (!comment) return;
    fputc('%', f);
    fputc(' ', f);
    for (const char *c = comment; *c && *c != '\n'; c++) fputc(*c, f);
    fputc('\n', f);
}

/* Write A as coordinate real general, atomically. */
int ulam_mm_write_matrix(const char *path, const ulam_csr *A, const char *comment)
{
    if (!path || !A) return ULAM_EINVAL;
    ulam_outfile o;
    int status = ulam_outfile_open(&o, path);
    if (status) return status;
    fprintf(o.f, "%%%%MatrixMarket matrix coordinate real general\n");
    write_comment(o.f, comment);
    fprintf(o.f, "%lld %lld %lld\n", (long long)A->nrows, (long long)A->ncols,
            (long long)ulam_csr_nnz(A));
    for (int64_t i = 0; i < A->nrows; i++)
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            fprintf(o.f, "%lld %d %.17g\n", (long long)i + 1, A->colidx[k] + 1, A->val[k]);
    return ulam_outfile_commit(&o);
}

/* Write x as array real general n x 1 to f; non-finite values are refused. */
int ulam_mm_write_vector_file(FILE *f, const double *x, int64_t n, const char *comment)
{
    if (!f || !x || n < 1) return ULAM_EINVAL;
    for (int64_t k = 0; k < n; k++)
        if (!isfinite(x[k])) return ULAM_ENONFINITE;
    fprintf(f, "%%%%MatrixMarket matrix array real general\n");
    write_comment(f, comment);
    fprintf(f, "%lld 1\n", (long long)n);
    for (int64_t k = 0; k < n; k++) fprintf(f, "%.17g\n", x[k]);
    return ferror(f) ? ULAM_EIO : ULAM_OK;
}

/* Write x as array real general n x 1, atomically; non-finite values are refused. */
int ulam_mm_write_vector(const char *path, const double *x, int64_t n, const char *comment)
{
    if (!path || !x || n < 1) return ULAM_EINVAL;
    for (int64_t k = 0; k < n; k++)
        if (!isfinite(x[k])) return ULAM_ENONFINITE;
    ulam_outfile o;
    int status = ulam_outfile_open(&o, path);
    if (status) return status;
    ulam_mm_write_vector_file(o.f, x, n, comment);
    return ulam_outfile_commit(&o);
}

/* Read a sparse matrix from f with options o (NULL: the defaults). */
int ulam_mm_read_matrix_opts(FILE *f, const char *name, const ulam_mm_opts *o, ulam_csr **A, ulam_error *err)
{
    return read_matrix(f, name, o, A, err);
}
