/* One query costs what its walks cost (issue 17): whole-process `ulam solve --index I
 * --rel-err 0.01 --threads 2` from a prepared file, at n = 10^6 and 10^7, on the random family
 * (8 a row at uniform columns, rows summing to 0.9, a column drawn twice summed as a parse
 * sums it: tests/bench/gen.h) and on screened
 * diffusion (5-point grid, M_ii = 0.1, 0.2 to each neighbour), against SciPy in memory on the
 * same matrix (CG to 10^-3 for the symmetric screened family, BiCGSTAB to 10^-3 for the
 * random one, which is not symmetric; python3-scipy, said when absent).  With a second ulam
 * binary (a build of the commit before the prepared format), its run from its own --cache
 * copies (written here in its format, tagged for a stub source file) is the 'before' row.
 * The prepared file is written by the library (what `ulam prepare` writes, without the text
 * parse), so its page-cache pages are warm: the runs are not cold-cache runs.  Each run is
 * repeated 3 times and the median whole-process time reported with its phases and its CPU
 * time (user + system: on a machine shared with other work the wall time waits for a core).
 * Issue 29's targets (the 'fixed' row: the same query with --walks fixed to what the rule used):
 * whole process <= 2x fixed, peak RSS <= 64 MiB at 10^7, whole-process CPU <= 0.02x SciPy's CPU
 * (SciPy column: CPU seconds of the solve alone, time.process_time, with one OpenBLAS thread).  Two queries: 'auto', the
 * default command line (--method auto: the choice's pilots, then its run; its 'fixed' row pins the
 * chosen mode, estimator, continuation and exponent with --method walks), and 'walks'
 * (--method walks: adjoint collision walks).  The first line names the machine, its cores, the
 * load and the date; each system's summary line the load when it ran (CPU seconds, not wall
 * time, are the figures to compare on a shared machine).
 * usage: bench_prepared path/to/ulam [path/to/old/ulam] [max n]
 *        bench_prepared --write-only PATH N [random] (the screened system of N states, for readme.sh;
 *        the random family's with 'random') */
#include <math.h>
#include <sys/stat.h>
#include <time.h>

#include "gen.h"

/* One run's figures. */
typedef struct {
    double load, guards, setup, walks, whole, cpu, rss, rows, estimate, stderr_;
    int rc;
} figures;

/* The string value of key in JSON text (its first occurrence) into out (empty when absent). */
static void json_string(const char *text, const char *key, char *out, size_t cap)
{
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\": \"", key);
    const char *p = strstr(text, pat);
    size_t k = 0;
    if (p)
        for (p += strlen(pat); *p && *p != '"' && k + 1 < cap; p++) out[k++] = *p;
    out[k] = '\0';
}

/* The load average over the last minute. */
static double load1(void)
{
    double l = NAN;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f && fscanf(f, "%lf", &l) != 1) l = NAN;
    if (f) fclose(f);
    return l;
}

/* Run argv 3 times; the run of median whole-process time. */
static char bench_last_output[1 << 16]; /* the last run's stdout */

static figures median_run(char *const argv[])
{
    char *out = bench_last_output;
    figures f[3];
    for (int k = 0; k < 3; k++) {
        f[k].rc = bench_run(argv, out, sizeof bench_last_output, 1, &f[k].whole, &f[k].cpu, &f[k].rss);
        f[k].load = bench_json_number(out, "load_seconds"), f[k].guards = bench_json_number(out, "guard_seconds");
        f[k].setup = bench_json_number(out, "kernel_seconds"), f[k].walks = bench_json_number(out, "seconds");
        f[k].rows = bench_json_number(out, "kernel_rows"), f[k].estimate = bench_json_number(out, "estimate");
        f[k].stderr_ = bench_json_number(out, "stderr");
        f[k].rss = bench_json_number(out, "peak_rss_mib"); /* the run's own (VmHWM): rusage's counts this process */
    }
    for (int a = 0; a < 3; a++)
        for (int b = a + 1; b < 3; b++)
            if (f[b].whole < f[a].whole) {
                figures t = f[a];
                f[a] = f[b], f[b] = t;
            }
    return f[1];
}

/* Print one run's row (a failed run: its exit status, and *rc set). */
static void print_row(const char *fname, int64_t n, const char *name, const figures *f, double sp_s, double xI, int *rc)
{
    if (f->rc) {
        printf("%-9s %9lld %9s %-11s run failed (exit %d)\n", fname, (long long)n, "", name, f->rc);
        *rc = 1;
        return;
    }
    printf("%-9s %9lld %9s %-11s %8.3f %8.3f %8.4f %8.4f %8.3f %8.3f %9.0f %9.0f %8.3f %9.3f %7.2f\n", fname, (long long)n,
           "", name, f->load, f->guards, f->setup, f->walks, f->whole, f->cpu, f->rss, f->rows, sp_s, f->whole / sp_s,
           fabs(f->estimate - xI) / f->stderr_);
}

/* Write a cache in the format before the prepared one: magic, a byte-order word, nrows, ncols,
 * nnz, the source's tag, then the arrays (native order). */
static int old_cache(const char *path, const char magic[8], const int64_t dims[3], const uint64_t tag[2],
                     const void *const parts[3], const size_t bytes[3])
{
    FILE *f = fopen(path, "wb");
    uint64_t head[6] = {0x0102030405060708u, (uint64_t)dims[0], (uint64_t)dims[1], (uint64_t)dims[2], tag[0], tag[1]};
    int ok = f && fwrite(magic, 1, 8, f) == 8 && fwrite(head, sizeof head, 1, f) == 1;
    for (int k = 0; k < 3 && ok; k++) ok = !bytes[k] || fwrite(parts[k], 1, bytes[k], f) == bytes[k];
    if (f && fclose(f)) ok = 0;
    return ok ? 0 : -1;
}

/* A stub source file at path and the tag the old CLI computes for it (size, mtime in ns). */
static int stub(const char *path, uint64_t tag[2])
{
    FILE *f = fopen(path, "w");
    if (!f || fputs("%%MatrixMarket stub: the cache beside it holds the data\n", f) < 0 || fclose(f)) return -1;
    struct stat st;
    if (stat(path, &st)) return -1;
    tag[0] = (uint64_t)st.st_size;
    tag[1] = (uint64_t)st.st_mtim.tv_sec * 1000000000u + (uint64_t)st.st_mtim.tv_nsec;
    return 0;
}

/* SciPy's solve of (I - M) x = b in memory from the prepared file (arrays read before timing). */
static const char *const scipy_script =
    "import sys, time, numpy as np, scipy.sparse as sp, scipy.sparse.linalg as la\n"
    "path, kind, I = sys.argv[1], sys.argv[2], int(sys.argv[3])\n"
    "h = np.fromfile(path, dtype='<u8', count=128)\n"
    "n, nnz = int(h[3]), int(h[5])\n"
    "rp = np.fromfile(path, dtype='<i8', count=n + 1, offset=int(h[6]))\n"
    "ci = np.fromfile(path, dtype='<i4', count=nnz, offset=int(h[7]))\n"
    "va = np.fromfile(path, dtype='<f8', count=nnz, offset=int(h[8]))\n"
    "b = np.fromfile(path, dtype='<f8', count=n, offset=int(h[9]))\n"
    "A = (sp.identity(n, format='csr') - sp.csr_matrix((va, ci, rp), shape=(n, n))).tocsr()\n"
    "A.sum_duplicates()\n"
    "t0 = time.process_time()\n"
    "solver = la.cg if kind == 'cg' else la.bicgstab\n"
    "try:\n"
    "    x, info = solver(A, b, rtol=1e-3, atol=0.0)\n"
    "except TypeError:\n"
    "    x, info = solver(A, b, tol=1e-3, atol=0.0)\n"
    "t = time.process_time() - t0\n"
    "print(t, info, x[I])\n";

/* The Debian python3 with SciPy, or NULL. */
static const char *scipy_python(void)
{
    static const char *const cands[] = {"/usr/bin/python3", "/usr/local/bin/python3"};
    for (int k = 0; k < 2; k++) {
        char cmd[256];
        snprintf(cmd, sizeof cmd, "%s -c 'import scipy' >/dev/null 2>&1", cands[k]);
        if (access(cands[k], X_OK) == 0 && system(cmd) == 0) return cands[k];
    }
    return NULL;
}

/* Run SciPy on the prepared file: seconds, x_I; 0 on success. */
static int scipy_run(const char *py, const char *dir, const char *sysf, int symmetric, int64_t I, double *sec,
                     double *xI)
{
    char script[256], cmd[1024], line[256];
    snprintf(script, sizeof script, "%s/solve.py", dir);
    FILE *f = fopen(script, "w");
    if (!f || fputs(scipy_script, f) < 0 || fclose(f)) return -1;
    /* one OpenBLAS thread: process_time counts every thread, and an idle OpenBLAS thread spins
       (10^7 random: 12.8 s of CPU with the default threads, 10.8 s with one) */
    snprintf(cmd, sizeof cmd, "OPENBLAS_NUM_THREADS=1 %s %s %s %s %lld", py, script, sysf, symmetric ? "cg" : "bicgstab",
             (long long)I);
    FILE *p = popen(cmd, "r");
    int info = -1, ok = p && fgets(line, sizeof line, p) && sscanf(line, "%lf %d %lf", sec, &info, xI) == 3;
    if (p) pclose(p);
    return ok && info == 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_prepared path/to/ulam [path/to/old/ulam] [max n]\n");
        return 2;
    }
    if (!strcmp(argv[1], "--write-only") && (argc == 4 || argc == 5)) { /* a system of n states at argv[2] */
        int random = argc == 5 && !strcmp(argv[4], "random");
        int64_t L = (int64_t)llround(sqrt(atof(argv[3]))), n = random ? (int64_t)llround(atof(argv[3])) : L * L;
        ulam_csr *M = random ? bench_canonical(bench_random_csr(n)) : bench_screened_csr(L);
        double *b = bench_random_rhs(n);
        ulam_certificate cert;
        if (!M || !b || ulam_certificate_compute(M, 0.0, NULL, &cert, NULL)) return 1;
        ulam_system_desc d = {.M = M, .b = b, .n = n, .cert = &cert};
        return ulam_system_write(argv[2], &d) ? 1 : 0;
    }
    const char *old = argc > 2 && argv[2][0] ? argv[2] : NULL;
    double max_n = argc > 3 ? atof(argv[3]) : 1e7;
    const char *py = scipy_python();
    char dir[] = "/tmp/ulam_bench_preparedXXXXXX";
    if (!mkdtemp(dir)) return 1;
    char host[256] = "?", model[256] = "?", line[512];
    gethostname(host, sizeof host);
    FILE *ci = fopen("/proc/cpuinfo", "r");
    while (ci && fgets(line, sizeof line, ci))
        if (!strncmp(line, "model name", 10) && strchr(line, ':')) {
            snprintf(model, sizeof model, "%s", strchr(line, ':') + 2);
            model[strcspn(model, "\n")] = '\0';
            break;
        }
    if (ci) fclose(ci);
    time_t now = time(NULL);
    char date[64];
    strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", gmtime(&now));
    printf("machine %s, %ld cores (%s), load %.2f, %s\n", host, sysconf(_SC_NPROCESSORS_ONLN), model, load1(), date);
    printf("whole-process 'ulam solve --index n/2+1 --rel-err 0.01 --threads 2' (median of 3, warm page cache);\n"
           "auto: the default (--method auto), walks: --method walks; fixed: the same with --walks fixed to what it used\n");
    if (!py) printf("SciPy is absent (Debian python3-scipy): no SciPy column\n");
    if (!old) printf("no old ulam given: no 'before' rows\n");
    printf("%-9s %9s %9s %-11s %8s %8s %8s %8s %8s %8s %9s %9s %8s %9s %7s\n", "family", "n", "nnz", "path", "load s",
           "guards s", "set-up s", "walks s", "whole s", "CPU s", "peak MiB", "rows", "SciPy CPU", "whole/SP", "|dx|/se");
    int rc = 0;
    for (int fam = 0; fam < 2 && !rc; fam++)
        for (int e = 6; e <= 7 && !rc; e++) {
            int64_t n = fam ? (int64_t)llround(sqrt(pow(10, e))) : (int64_t)llround(pow(10, e)), L = n;
            if (fam) n = L * L;
            if ((double)n > max_n * 1.001) continue;
            ulam_csr *M = fam ? bench_screened_csr(L) : bench_canonical(bench_random_csr(n));
            double *b = bench_random_rhs(n);
            if (!M || !b) return 1;
            ulam_certificate cert;
            double t0 = ulam_now();
            if (ulam_certificate_compute(M, 0.0, NULL, &cert, NULL)) return 1;
            double tcert = ulam_now() - t0;
            char sysf[256], mpath[256], bpath[256], cpath[300], idx[32];
            snprintf(sysf, sizeof sysf, "%s/system.ulam", dir);
            snprintf(idx, sizeof idx, "%lld", (long long)n / 2 + 1);
            ulam_system_desc d = {.M = M, .b = b, .n = n, .cert = &cert};
            t0 = ulam_now();
            if (ulam_system_write(sysf, &d)) return 1;
            double twrite = ulam_now() - t0;
            const char *fname = fam ? "screened" : "random";
            printf("%-9s %9lld %9lld prepare: certificate %.2f s, file written in %.2f s (%.0f MiB)\n", fname,
                   (long long)n, (long long)ulam_csr_nnz(M), tcert, twrite,
                   (bench_csr_bytes(M) + 8.0 * (double)n) / 1048576.0);
            figures before = {.rc = -2};
            if (old) {
                uint64_t tm[2], tb[2];
                snprintf(mpath, sizeof mpath, "%s/M.mtx", dir);
                snprintf(bpath, sizeof bpath, "%s/b.mtx", dir);
                int64_t dm[3] = {n, n, ulam_csr_nnz(M)}, dv[3] = {n, 1, n};
                const void *pm[3] = {M->rowptr, M->colidx, M->val}, *pv[3] = {b, NULL, NULL};
                size_t bm[3] = {((size_t)n + 1) * 8, (size_t)dm[2] * 4, (size_t)dm[2] * 8}, bv[3] = {(size_t)n * 8, 0, 0};
                int ok = !stub(mpath, tm) && !stub(bpath, tb);
                snprintf(cpath, sizeof cpath, "%s.ulamcache", mpath);
                ok = ok && !old_cache(cpath, "ulamCSR1", dm, tm, pm, bm);
                snprintf(cpath, sizeof cpath, "%s.ulamcache", bpath);
                ok = ok && !old_cache(cpath, "ulamVEC1", dv, tb, pv, bv);
                before.rc = ok ? -3 : -1;
            }
            ulam_csr_free(M); /* before the runs: a child's peak RSS counts what this process holds */
            free(b);
            if (before.rc == -3) {
                char *args[] = {(char *)old, "solve", mpath, "--rhs", bpath, "--index", idx, "--rel-err", "0.01",
                                "--threads", "2", "--json", "--cache", NULL};
                before = median_run(args);
            }
            double sp_s = NAN, xI = NAN;
            if (py && scipy_run(py, dir, sysf, fam, n / 2, &sp_s, &xI)) sp_s = NAN;
            if (before.rc != -2) print_row(fname, n, "before", &before, sp_s, xI, &rc);
            for (int qk = 0; qk < 2; qk++) { /* auto (the default), then --method walks */
                const char *method = qk ? "walks" : "auto";
                char *args[] = {argv[1], "solve", sysf, "--method", (char *)method, "--index", idx, "--rel-err", "0.01",
                                "--threads", "2", "--json", NULL};
                figures after = median_run(args);
                /* the same query with the walk count fixed to what the rule used, the chosen walks pinned */
                char walks[32], mode[32], est[32], alpha[32], cont[32] = "analog";
                snprintf(walks, sizeof walks, "%.0f", bench_json_number(bench_last_output, "walks"));
                json_string(bench_last_output, "mode", mode, sizeof mode);
                json_string(bench_last_output, "estimator", est, sizeof est);
                snprintf(alpha, sizeof alpha, "%.17g", bench_json_number(bench_last_output, "kernel_alpha"));
                const char *cands = strstr(bench_last_output, "\"candidates\": [");
                int chosen = (int)bench_json_number(bench_last_output, "chosen");
                for (int c = 0; cands && c <= chosen; c++) cands = strstr(cands + 1, "{\"mode\": ");
                double q = cands ? bench_json_number(cands, "continue") : NAN; /* null (analog): atof gives 0 */
                if (q > 0) snprintf(cont, sizeof cont, "%.17g", q);
                char *fixed_args[] = {argv[1], "solve", sysf, "--method", "walks", "--mode", mode, "--estimator", est,
                                      "--continue", cont, "--kernel-exponent", alpha, "--index", idx, "--walks", walks,
                                      "--threads", "2", "--json", NULL};
                figures fixed = after.rc || !mode[0] || !est[0] ? (figures){.rc = -1} : median_run(fixed_args);
                char name[32];
                print_row(fname, n, method, &after, sp_s, xI, &rc);
                snprintf(name, sizeof name, "%s fixed", method);
                print_row(fname, n, name, &fixed, sp_s, xI, &rc);
                if (!after.rc && !fixed.rc)
                    printf("%-9s %9lld   %s (%s %s, %s walks) / fixed: whole %.2fx, CPU %.2fx; peak RSS %.1f MiB (fixed %.1f); "
                           "CPU / SciPy CPU %.4f; load %.2f\n", fname, (long long)n, method, mode, est, walks,
                           after.whole / fixed.whole, after.cpu / fixed.cpu, after.rss, fixed.rss, after.cpu / sp_s, load1());
            }
            char cmd[400];
            snprintf(cmd, sizeof cmd, "rm -f %s/*", dir);
            if (system(cmd)) rc = 1;
        }
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd)) rc = 1;
    return rc;
}
