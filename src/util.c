/* Errors, allocation, clock and atomic output files. */
#include "internal.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static const char *const messages[ULAM_NSTATUS] = {
    [ULAM_OK] = "success",
    [ULAM_EINVAL] = "invalid argument",
    [ULAM_ENOMEM] = "out of memory",
    [ULAM_EIO] = "cannot open, read or write file",
    [ULAM_EEMPTY] = "empty input",
    [ULAM_EBANNER] = "not the kind of file expected (a missing or malformed banner or magic)",
    [ULAM_EUNSUPPORTED] = "unsupported kind of data",
    [ULAM_ESIZELINE] = "missing or malformed size line",
    [ULAM_EOVERFLOW] = "sizes too large",
    [ULAM_ETOOFEW] = "fewer entries than declared",
    [ULAM_ETOOMANY] = "more entries than declared",
    [ULAM_EINDEX] = "index out of range",
    [ULAM_ESYNTAX] = "malformed entry",
    [ULAM_ENONFINITE] = "non-finite value",
    [ULAM_ENOTSQUARE] = "matrix is not square",
    [ULAM_EDIM] = "dimensions do not agree",
    [ULAM_EZERODIAG] = "zero on the diagonal",
    [ULAM_ESINGULAR] = "singular system",
    [ULAM_EMEMLIMIT] = "exceeds the memory limit",
    [ULAM_ENOCONV] = "iteration did not converge",
    [ULAM_EUNDEFINED] = "estimator undefined for this system",
    [ULAM_EGEOMETRY] = "degenerate, non-planar or non-convex face",
    [ULAM_ENOTFOUND] = "not defined",
    [ULAM_ERANGE] = "value out of range",
    [ULAM_EDEVICE] = "ray-casting device failed",
    [ULAM_EDIVERGE] = "walks not certified to converge",
    [ULAM_EINFVAR] = "variance not certified finite",
    [ULAM_ESTALL] = "the residual stopped decreasing",
};

/* A short English description of a status code. */
const char *ulam_strerror(int status)
{
    if (status < 0 || status >= ULAM_NSTATUS || !messages[status]) return "unknown status";
    return messages[status];
}

/* Record a failure in err and return status. */
int ulam__fail(ulam_error *err, int status, long line, int64_t index, const char *fmt, ...)
{
    if (!err) return status;
    err->status = status;
    err->line = line;
    err->index = index;
    err->file[0] = '\0';
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    return status;
}

/* Reset err to "no error". */
void ulam__clear(ulam_error *err)
{
    if (!err) return;
    err->status = ULAM_OK;
    err->line = 0;
    err->index = -1;
    err->msg[0] = '\0';
    err->file[0] = '\0';
}

/* malloc of n items of size sz, NULL on overflow. */
void *ulam__malloc(size_t n, size_t sz)
{
    if (sz && n > SIZE_MAX / sz) return NULL;
    size_t bytes = n * sz;
    return malloc(bytes ? bytes : 1);
}

/* calloc of n items of size sz. */
void *ulam__calloc(size_t n, size_t sz)
{
    return calloc(n ? n : 1, sz ? sz : 1);
}

/* Make room for need items in the growable array at *pp of capacity *cap (doubling from 16). */
int ulam__grow(void *pp, int64_t *cap, int64_t need, size_t sz)
{
    if (need <= *cap) return ULAM_OK;
    void *p; /* the pointer is read and written by memcpy: pp points at a T *, not a void * */
    memcpy(&p, pp, sizeof p);
    int64_t c = *cap ? *cap : 16;
    while (c < need) {
        if (c > INT64_MAX / 2) return ULAM_ENOMEM;
        c *= 2;
    }
    if ((uint64_t)c > SIZE_MAX / sz) return ULAM_ENOMEM;
    void *q = realloc(p, (size_t)c * sz);
    if (!q) return ULAM_ENOMEM;
    memcpy(pp, &q, sizeof q);
    *cap = c;
    return ULAM_OK;
}

/* Aligned memory for a big array, 2 MiB pages asked for where it is large: a 4 KiB page's first
 * touch costs ~15 us on a virtual machine (64 MiB: 250 ms against 14 ms in 2 MiB pages), a walk
 * or a sweep reading it at random misses the TLB less, and a malloc'd block's unaligned head
 * would stay in 4 KiB pages. */
void *ulam__alloc_big(size_t n, size_t sz)
{
    if (sz && n > SIZE_MAX / sz) return NULL;
    size_t bytes = n * sz, align = bytes >= ((size_t)2 << 20) ? (size_t)2 << 20 : 64;
    if (bytes > (size_t)PTRDIFF_MAX - align) return NULL; /* no object is larger (the allocator refuses it too) */
    size_t size = (bytes + align - 1) / align * align;
    void *p = aligned_alloc(align, size ? size : align);
#ifdef MADV_HUGEPAGE
    if (p && align > 64) madvise(p, size, MADV_HUGEPAGE); /* advice only: failure is harmless */
#endif
    return p;
}

/* Monotonic wall clock in seconds. */
double ulam_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* This process's peak resident memory so far, in KiB: VmHWM of /proc/self/status, the high-water
 * mark of this program's own memory, because getrusage's ru_maxrss keeps, across an exec, the peak
 * of the process it was forked from (a benchmark's 119 MiB showed as a query's peak; mpirun's
 * launcher forks each rank); ru_maxrss only where /proc cannot be read; -1 when neither can. */
double ulam__peak_rss_kib(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    double kb = -1;
    while (f && kb < 0 && fgets(line, sizeof line, f))
        if (sscanf(line, "VmHWM: %lf", &kb) != 1) kb = -1;
    if (f) fclose(f);
    struct rusage ru;
    return kb >= 0 ? kb : getrusage(RUSAGE_SELF, &ru) ? -1.0 : (double)ru.ru_maxrss;
}

/* Open a temporary file beside path. */
int ulam_outfile_open(ulam_outfile *o, const char *path)
{
    memset(o, 0, sizeof *o);
    size_t len = strlen(path);
    o->path = ulam__malloc(len + 1, 1);
    o->tmp = ulam__malloc(len + 16, 1);
    if (!o->path || !o->tmp) {
        ulam_outfile_abort(o);
        return ULAM_ENOMEM;
    }
    memcpy(o->path, path, len + 1);
    snprintf(o->tmp, len + 16, "%s.tmp.XXXXXX", path);
    int fd = mkstemp(o->tmp);
    if (fd < 0) {
        o->tmp[0] = '\0';
        ulam_outfile_abort(o);
        return ULAM_EIO;
    }
    mode_t mask = umask(0);
    umask(mask);
    (void)fchmod(fd, 0666 & ~mask); /* mkstemp makes 0600; give the usual permissions */
    o->f = fdopen(fd, "w");
    if (!o->f) {
        close(fd);
        ulam_outfile_abort(o);
        return ULAM_EIO;
    }
    return ULAM_OK;
}

/* Flush and close o's temporary file; 0, or errno's value for the failure (EIO when a buffered
 * write failed earlier and the retry did not say why). */
static int outfile_close(ulam_outfile *o)
{
    int e0 = errno; /* a failed fprintf's reason, when nothing has set errno since */
    errno = 0;
    int e = fflush(o->f) != 0 ? errno : 0;
    if (!e && ferror(o->f)) e = e0 ? e0 : EIO;
    if (fclose(o->f) != 0 && !e) e = errno ? errno : EIO;
    o->f = NULL;
    return e;
}

/* Flush, close and rename into place; errno says why on ULAM_EIO. */
int ulam_outfile_commit(ulam_outfile *o)
{
    return ulam_outfile_commit_all(o, 1);
}

/* Flush and close all k files, then rename each into place only when every one closed cleanly;
 * else remove every temporary file.  errno says why on ULAM_EIO. */
int ulam_outfile_commit_all(ulam_outfile *o, int k)
{
    if (!o || k < 1) return ULAM_EINVAL;
    int e = 0;
    for (int j = 0; j < k; j++) {
        if (!o[j].f) e = e ? e : EINVAL;
        else if (!e) e = outfile_close(&o[j]);
    }
    for (int j = 0; j < k && !e; j++) {
        if (rename(o[j].tmp, o[j].path) != 0) e = errno;
        else o[j].tmp[0] = '\0';
    }
    for (int j = 0; j < k; j++) ulam_outfile_abort(&o[j]); /* closes and removes what is left */
    errno = e;
    return e == EINVAL ? ULAM_EINVAL : e ? ULAM_EIO : ULAM_OK;
}

/* Close and remove the temporary file. */
void ulam_outfile_abort(ulam_outfile *o)
{
    if (o->f) fclose(o->f);
    if (o->tmp && o->tmp[0]) remove(o->tmp);
    free(o->tmp);
    free(o->path);
    memset(o, 0, sizeof *o);
}

/* Threads a run uses. */
int ulam__threads(int requested)
{
#ifdef _OPENMP
    return requested > 0 ? requested : omp_get_max_threads();
#else
    (void)requested;
    return 1;
#endif
}

/* The calling thread's number in its OpenMP team. */
int ulam__thread_num(void)
{
#ifdef _OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

/* The power of 2 that brings b's largest |entry| into [0.5, 1) when it lies outside
 * [2^-256, 2^256], else 0. */
int ulam__b_exponent(const double *b, int64_t n)
{
    double m = 0.0;
    for (int64_t i = 0; i < n; i++) m = fmax(m, fabs(b[i]));
    if (!(m > 0) || !isfinite(m) || (m <= 0x1p256 && m >= 0x1p-256)) return 0;
    int e;
    frexp(m, &e);
    return e;
}

/* A copy of b times 2^-e (NULL on failure). */
double *ulam__b_scaled(const double *b, int64_t n, int e)
{
    double *c = ulam__malloc((size_t)n, sizeof *c);
    for (int64_t i = 0; c && i < n; i++) c[i] = ldexp(b[i], -e);
    return c;
}
