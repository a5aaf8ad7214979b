/* Benchmark: Matrix Market parse speed on a 10^7-nonzero file (1.25 x 10^6 rows of 8, values
 * with 17 significant digits as ulam_mm_write_matrix writes them, rows rising), the reader
 * as it was (one thread, the C library's strtod) side by side with the new one (ulam_strtod,
 * one thread and two), runs interleaved, three each.  The reader as it was is today's sequential
 * reader with strtod in ulam_strtod's place: the benchmark is linked with -Wl,--wrap=ulam_strtod
 * (tests/meson.build), so the library's calls reach __wrap_ulam_strtod below; the public API
 * alone, no private header.  Each parse runs in a child process so
 * its peak RSS is its own; the CSR it builds is the yardstick.  Targets: >= 2x the old MB/s
 * on 2 threads, peak memory <= 2 x the CSR. */
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "gen.h"

double __real_ulam_strtod(const char *s, char **end);
double __wrap_ulam_strtod(const char *s, char **end);

static int libc_strtod;       /* set in the child that reads as the reader did */
static long long libc_calls;  /* its strtod calls: 0 means the wrap missed (a shared libulam) */

/* ulam_strtod as the library calls it here: the C library's strtod when libc_strtod, else itself. */
double __wrap_ulam_strtod(const char *s, char **end)
{
    if (libc_strtod) return libc_calls++, strtod(s, end);
    return __real_ulam_strtod(s, end);
}

/* Parse path with o in a child: seconds into *t, its CPU seconds (user + system, the whole
 * process) into *cpu, peak RSS (MiB) into *rss, CSR MiB into *csr. */
static int parse_child(const char *path, ulam_mm_opts o, int libc, double *t, double *cpu, double *rss, double *csr)
{
    int fd[2];
    if (pipe(fd)) return -1;
    pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        double r[2] = {-1, 0};
        FILE *f = fopen(path, "rb");
        ulam_csr *A = NULL;
        libc_strtod = libc;
        double t0 = ulam_now();
        if (f && ulam_mm_read_matrix_opts(f, path, &o, &A, NULL) == ULAM_OK && (!libc || libc_calls > 0))
            r[0] = ulam_now() - t0, r[1] = bench_csr_bytes(A) / 1048576.0;
        if (write(fd[1], r, sizeof r) != (ssize_t)sizeof r) _exit(1);
        _exit(0);
    }
    close(fd[1]);
    double r[2] = {-1, 0};
    ssize_t got = read(fd[0], r, sizeof r);
    close(fd[0]);
    int status;
    struct rusage ru;
    wait4(pid, &status, 0, &ru);
    *t = r[0], *csr = r[1], *rss = (double)ru.ru_maxrss / 1024.0;
    *cpu = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
           1e-6 * (double)ru.ru_stime.tv_usec;
    return got == (ssize_t)sizeof r && r[0] >= 0 ? 0 : -1;
}

int main(void)
{
    const int64_t n = 1250000, k = 8, nnz = n * k;
    char path[] = "/tmp/ulam_bench_mmioXXXXXX";
    int fd = mkstemp(path);
    if (fd < 0) return 1;
    FILE *f = fdopen(fd, "w");
    ulam_rng r;
    ulam_rng_seed(&r, 1, 0);
    fprintf(f, "%%%%MatrixMarket matrix coordinate real general\n%lld %lld %lld\n", (long long)n,
            (long long)n, (long long)nnz);
    for (int64_t i = 0; i < n; i++)
        for (int64_t q = 0; q < k; q++)
            fprintf(f, "%lld %llu %.17g\n", (long long)i + 1,
                    (unsigned long long)ulam_rng_bounded(&r, (uint64_t)n) + 1, ulam_rng_uniform(&r) / 8);
    fclose(f);
    struct stat st;
    stat(path, &st);
    double mb = (double)st.st_size / 1e6;
    static const char *const names[3] = {"old (1 thread, strtod)", "new, 1 thread", "new, 2 threads"};
    const ulam_mm_opts opts[3] = {{.threads = 1}, {.threads = 1}, {.threads = 2}}; /* the first with libc's strtod */
    double best[3] = {1e30, 1e30, 1e30}, bcpu[3] = {1e30, 1e30, 1e30}, peak[3] = {0}, csr = 0;
    printf("%.1f MB, %lld entries\n%-24s %4s %10s %10s %10s %10s %10s\n", mb, (long long)nnz, "reader", "run", "seconds",
           "MB/s", "CPU s", "peak MiB", "peak/CSR");
    for (int rep = 0; rep < 3; rep++)
        for (int m = 0; m < 3; m++) {
            double t, cpu, rss;
            if (parse_child(path, opts[m], m == 0, &t, &cpu, &rss, &csr)) {
                fprintf(stderr, "read failed%s\n", m == 0 ? " (or the C library's strtod was never called: --wrap=ulam_strtod reaches only a static libulam)" : "");
                remove(path);
                return 1;
            }
            if (t < best[m]) best[m] = t;
            if (cpu < bcpu[m]) bcpu[m] = cpu;
            if (rss > peak[m]) peak[m] = rss;
            printf("%-24s %4d %10.3f %10.1f %10.3f %10.0f %10.2f\n", names[m], rep + 1, t, mb / t, cpu, rss, rss / csr);
        }
    remove(path);
    printf("best MB/s: old %.1f, new 1 thread %.1f (%.2fx), new 2 threads %.1f (%.2fx; target >= 2x: %s); "
           "peak %.2fx the CSR (target <= 2x: %s)\n",
           mb / best[0], mb / best[1], best[0] / best[1], mb / best[2], best[0] / best[2],
           best[0] / best[2] >= 2 ? "met" : "MISSED", peak[2] / csr, peak[2] / csr <= 2 ? "met" : "MISSED");
    printf("best CPU s: old %.3f, new 1 thread %.3f, new 2 threads %.3f (old / new 2 threads %.2fx: the wall ratio on two "
           "free cores is at most this times 2)\n", bcpu[0], bcpu[1], bcpu[2], bcpu[0] / bcpu[2]);
    return 0;
}
