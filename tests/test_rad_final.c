/* Final gathering over a shooting pilot (ulam_rad_final, mode "final"): its intervals against
 * LAPACK on the open box (80 patches) counted over seeds, its answer independent of threads, and
 * its errors.  Fixed seeds. */
#include "testutil.h"
#include "ulam_radiosity.h"
#include "ulam_radiosity_run.h"

#include <string.h>

/* Gauss-Legendre nodes and weights on [0, 1] (n points; Newton on P_n). */
static void gauss01(int n, double *x, double *w)
{
    for (int i = 0; i < n; i++) {
        double z = cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1;
        for (int it = 0; it < 100; it++) {
            double p0 = 1, p1 = z;
            for (int k = 2; k <= n; k++) {
                double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
                p0 = p1, p1 = p2;
            }
            dp = n * (z * p1 - p0) / (z * z - 1);
            double dz = p1 / dp;
            z -= dz;
            if (fabs(dz) < 1e-15) break;
        }
        x[i] = 0.5 * (1 - z), w[i] = 1 / ((1 - z * z) * dp * dp);
    }
}

/* Lambert's contour integral: the form factor from the point x (unit normal n) to the polygon
 * v[0..3] wholly in front of it. */
static double point_to_quad(const double x[3], const double n[3], double v[4][3])
{
    double sum = 0;
    for (int k = 0; k < 4; k++) {
        double a[3], b[3], c[3];
        for (int d = 0; d < 3; d++) a[d] = v[k][d] - x[d], b[d] = v[(k + 1) % 4][d] - x[d];
        c[0] = a[1] * b[2] - a[2] * b[1], c[1] = a[2] * b[0] - a[0] * b[2], c[2] = a[0] * b[1] - a[1] * b[0];
        double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        if (lc == 0) continue;
        double cosb = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
        sum += acos(fmax(-1.0, fmin(1.0, cosb))) * (n[0] * c[0] + n[1] * c[1] + n[2] * c[2]) / lc;
    }
    return fabs(sum) / (2 * M_PI);
}

/* The open box, its tracer and its exact reference: every pair of its unit squares sees the
 * other whole (no occluder), so F_ij is the mean over i of Lambert's point-to-square factor
 * (24 x 24 Gauss-Legendre points), and B = E + rho F B by Jacobi iteration (rho 0.6: 200 sweeps
 * reach 1e-40).  Its F rows match 10^6 cosine rays a patch to their binomial error. */
typedef struct {
    char dir[64], path[96];
    ulam_scene *s;
    ulam_tracer *t;
    double *ref;
} box;

/* A corridor open at the top: x in [0, 10], y in [0, 2], z in [0, 2] in unit cells (the floor, the
 * walls z = 0, z = 2, x = 0, x = 10: 68 patches, reflectance 0.6), the lamp (Ke 10) the x = 0 end
 * wall's upper cell at z in [0, 1]: the brightest patches sit at that end, and the far end sees
 * them at small form factors. */
static void write_corridor(char dir[64], char path[96])
{
    test_open_box_sized(dir, path, 10, 2, 2, 3, 1, 0);
}

static box box_open_scene(int corridor)
{
    box b;
    if (corridor) write_corridor(b.dir, b.path);
    else test_open_box(b.dir, b.path);
    assert_int_equal(ulam_scene_read_obj(b.path, &b.s, NULL), ULAM_OK);
    assert_int_equal(ulam_tracer_alloc(b.s, &b.t, NULL), ULAM_OK);
    const ulam_scene *s = b.s;
    int64_t n = s->npatches;
    enum { Q = 24 };
    double gx[Q], gw[Q], *F = calloc((size_t)(n * n), sizeof *F), *x = calloc(3 * (size_t)n, sizeof *x);
    b.ref = malloc(3 * (size_t)n * sizeof *b.ref);
    assert_non_null(F), assert_non_null(x), assert_non_null(b.ref);
    gauss01(Q, gx, gw);
    for (int64_t i = 0; i < n; i++) {
        const double *o = s->vert + 3 * s->vidx[s->start[i]], *p1 = s->vert + 3 * s->vidx[s->start[i] + 1],
                     *p3 = s->vert + 3 * s->vidx[s->start[i] + 3];
        for (int64_t j = 0; j < n; j++) {
            if (fabs(s->normal[3 * i] * s->normal[3 * j] + s->normal[3 * i + 1] * s->normal[3 * j + 1] +
                     s->normal[3 * i + 2] * s->normal[3 * j + 2] - 1) < 1e-9)
                continue; /* the same face */
            double v[4][3];
            for (int k = 0; k < 4; k++)
                for (int d = 0; d < 3; d++) v[k][d] = s->vert[3 * s->vidx[s->start[j] + k] + d];
            double f = 0;
            for (int a = 0; a < Q; a++)
                for (int c = 0; c < Q; c++) {
                    double pt[3];
                    for (int d = 0; d < 3; d++) pt[d] = o[d] + gx[a] * (p1[d] - o[d]) + gx[c] * (p3[d] - o[d]);
                    f += gw[a] * gw[c] * point_to_quad(pt, s->normal + 3 * i, v);
                }
            F[i * n + j] = f;
        }
    }
    for (int it = 0; it < 200; it++) {
        for (int64_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) {
                double h = 0;
                for (int64_t j = 0; j < n; j++) h += F[i * n + j] * x[3 * j + c];
                b.ref[3 * i + c] = s->emit[3 * i + c] + s->rho[3 * i + c] * h;
            }
        memcpy(x, b.ref, 3 * (size_t)n * sizeof *x);
    }
    free(F), free(x);
    return b;
}

static box box_open(void)
{
    return box_open_scene(0);
}

static void box_close(box *b)
{
    free(b->ref);
    ulam_tracer_free(b->t);
    ulam_scene_free(b->s);
    test_scene_rm(b->dir);
}

/* One final gather on the box: rel_err E (0: walks samples a patch), pilot particles, seed. */
static void run(const box *b, double E, int64_t walks, int64_t pilot, uint64_t seed, int threads, double *B, double *se,
                double *half, ulam_rad_final_info *in)
{
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.rel_err = E, o.stop.max_walks = walks, o.exec.seed = seed, o.exec.threads = threads;
    ulam_error err;
    int st = ulam_rad_final(b->t, &o, pilot, 1.0, B, se, half, in, &err);
    if (st) print_error("%s\n", err.msg);
    assert_int_equal(st, ULAM_OK);
}

/* Coverage of the 95% intervals (B -+ half) against the exact solution over the box's 80
 * patches and 20 seeds, under rel_err 0.1 (the default pilot) and at a fixed 256 samples a patch
 * (a small pilot, 4096 particles: its noise matters).  Each run's patches share its pilot, so
 * misses come in bunches; at most 5% of the 1600 may miss (the intervals hold 95% each, and the
 * sequence's part is conservative).  The central-limit interval 1.96 se, which the first version
 * printed, missed 171 and 168 of 1600 here (var z 1.57, 1.54: the pilot's few bright patches
 * next to the lamp make the scores skewed).  Under rel_err every patch meets it. */
static void test_final_coverage(void **state)
{
    (void)state;
    box b = box_open();
    int64_t n = b.s->npatches;
    double *B = malloc(3 * (size_t)n * sizeof *B), *se = malloc(3 * (size_t)n * sizeof *se),
           *half = malloc(3 * (size_t)n * sizeof *half);
    assert_non_null(B), assert_non_null(se), assert_non_null(half);
    for (int mode = 0; mode < 2; mode++) {
        double E = mode ? 0.0 : 0.1;
        int miss = 0, clt = 0, total = 0, met = 0;
        double samples = 0, width = 0;
        for (uint64_t seed = 0; seed < 20; seed++) {
            if (!test_case(100L * mode + (long)seed)) continue;
            ulam_rad_final_info in;
            run(&b, E, E > 0 ? 0 : 256, E > 0 ? 0 : 4096, 300 + seed, 2, B, se, half, &in);
            samples += (double)in.samples, met += in.met;
            for (int64_t p = 0; p < n; p++) {
                double d = fabs(B[3 * p] - b.ref[3 * p]);
                miss += !(d <= half[3 * p]), clt += !(d <= ULAM_Z95 * se[3 * p]), total++;
                width += half[3 * p] / (ULAM_Z95 * se[3 * p]);
                if (E > 0) assert_true(half[3 * p] <= E * B[3 * p]);
            }
        }
        test_case_done();
        print_message("final %s: %d of %d intervals miss (1.96 se: %d); half-width %.2f x 1.96 se; %.0f samples a "
                      "patch; rule met %d of 20\n", E > 0 ? "rel-err 0.1" : "256 samples, pilot 4096", miss, total,
                      clt, width / total, samples / total, met);
        if (!test_case_all()) continue;
        assert_true(miss <= 80);
        if (E > 0) assert_int_equal(met, 20);
    }
    free(B), free(se), free(half);
    box_close(&b);
}

/* The corridor (write_corridor): coverage of the 95% intervals against the exact solution over its
 * 68 patches and 20 seeds at 256 samples a patch, and their width: half-width over 1.96 se, the
 * mean over the patches and seeds, and over the far half (x > 5).  The first version's certified
 * range held the pilot's largest mean reflected radiosity (the patches beside the lamp) at every
 * patch: 10.69 times 1.96 se, 13.60 at the far half (measured; 0 of 1360 missed).  Each patch now
 * clips the brightest pilot patches where their form-factor bound makes that cheap (final_cap):
 * 6.46 and 5.20, 0 of 1360 missed.  Bounds: 8 and 7; the misses at most 5%. */
static void test_final_corridor(void **state)
{
    (void)state;
    box b = box_open_scene(1);
    int64_t n = b.s->npatches;
    double *B = malloc(3 * (size_t)n * sizeof *B), *se = malloc(3 * (size_t)n * sizeof *se),
           *half = malloc(3 * (size_t)n * sizeof *half);
    assert_non_null(B), assert_non_null(se), assert_non_null(half);
    int miss = 0, clt = 0, total = 0;
    double width = 0, far = 0;
    int nfar = 0;
    for (uint64_t seed = 0; seed < 20; seed++) {
        if (!test_case((long)seed)) continue;
        ulam_rad_final_info in;
        run(&b, 0.0, 256, 0, 500 + seed, 2, B, se, half, &in);
        for (int64_t p = 0; p < n; p++) {
            double d = fabs(B[3 * p] - b.ref[3 * p]), w = half[3 * p] / (ULAM_Z95 * se[3 * p]);
            double cx = 0;
            for (int k = 0; k < 4; k++) cx += b.s->vert[3 * b.s->vidx[b.s->start[p] + k]] / 4;
            miss += !(d <= half[3 * p]), clt += !(d <= ULAM_Z95 * se[3 * p]), total++, width += w;
            if (cx > 5) far += w, nfar++;
        }
    }
    test_case_done();
    print_message("final corridor, 256 samples: %d of %d intervals miss (1.96 se: %d); half-width %.2f x 1.96 se "
                  "(x > 5: %.2f)\n", miss, total, clt, width / total, nfar ? far / nfar : 0.0);
    if (test_case_all()) {
        assert_true(miss <= total / 20);
        assert_true(width / total <= 8.0);
        assert_true(far / nfar <= 7.0);
    }
    free(B), free(se), free(half);
    box_close(&b);
}

/* One `ulam radiosity CORRIDOR --mode final --patches LIST` run through the run object (as the
 * CLI makes it): E (0: samples a patch), seed; its --out rows parsed into row[k] = {patch, R,
 * R_half} (at most max); the row count, and the rule's state into *met. */
static int run_chosen(const box *b, const char *list, double E, int64_t samples, uint64_t seed, double (*row)[3], int max,
                      int *met)
{
    ulam_rad_run_opts o = ulam_rad_run_defaults();
    o.scene = b->path, o.patches = list, o.final = 1, o.est = 0, o.o.mode = ULAM_FORWARD;
    o.o.stop.rel_err = E, o.o.stop.max_walks = samples, o.o.exec.seed = seed, o.o.exec.threads = 2;
    o.started = ulam_now(), o.json = 1; /* the summary's rule, from the JSON */
    ulam_rad_run *r = NULL;
    int interrupted = 1;
    assert_int_equal(ulam_rad_run_alloc(&o, &r), ULAM_OK);
    assert_int_equal(ulam_rad_run_solve(r, &interrupted), ULAM_OK);
    assert_false(interrupted);
    FILE *f = tmpfile(), *j = tmpfile();
    assert_non_null(f), assert_non_null(j);
    assert_int_equal(ulam_rad_run_write(r, ULAM_RAD_RUN_CSV, f), ULAM_OK);
    rewind(f);
    char line[1024];
    assert_non_null(fgets(line, sizeof line, f));
    assert_string_equal(line, "patch,label,face,x,y,z,area,R,G,B,R_se,G_se,B_se,R_half,G_half,B_half\n");
    int n = 0;
    while (fgets(line, sizeof line, f)) {
        double v[16];
        char *t = strtok(line, ",");
        for (int k = 0; k < 16; k++, t = strtok(NULL, ",")) v[k] = k == 1 ? 0 : t ? atof(t) : NAN; /* the label "" */
        assert_true(n < max);
        row[n][0] = v[0], row[n][1] = v[7], row[n][2] = v[13], n++;
    }
    ulam_rad_run_print(r, j);
    rewind(j);
    char js[4096];
    size_t len = fread(js, 1, sizeof js - 1, j);
    js[len] = 0;
    char want[128];
    snprintf(want, sizeof want, "\"chosen\": {\"patches\": \"%s\", \"count\": %d}", list, n);
    assert_non_null(strstr(js, want));
    snprintf(want, sizeof want, "\"scene_rule\": {\"met\": true, \"lit\": %d, \"lit_met\": %d", n, n);
    *met = strstr(js, want) != NULL;
    fclose(f), fclose(j);
    ulam_rad_run_free(r);
    return n;
}

/* --patches on the corridor (write_corridor): its floor, patches 1-20 (the work plane, y = 0),
 * chosen by range and gathered alone.  Coverage of the printed 95% intervals (the rows' R -+ R_half)
 * against the exact solution over the 20 floor patches and 20 seeds at 256 samples a patch (each
 * run's patches share its pilot: at most 5% of the 400 may miss); only the chosen rows come out.
 * Under --rel-err 0.1 the corridor's far floor stops short (the pilot's part alone takes 0.9 of
 * the target there, final_met: 12 of 20 met, seed 9, said NOT met); the open box's floor (1-16)
 * meets it, every row within 0.1 B and covering the exact answer. */
static void test_final_chosen(void **state)
{
    (void)state;
    box b = box_open_scene(1);
    double row[68][3];
    int miss = 0, total = 0, met = 0;
    double width = 0;
    for (int p = 0; p < 20; p++) assert_true(fabs(b.s->normal[3 * p + 1] - 1) < 1e-12); /* the floor faces up */
    for (uint64_t seed = 0; seed < 20; seed++) {
        if (!test_case((long)seed)) continue;
        int n = run_chosen(&b, "1-20", 0.0, 256, 700 + seed, row, 68, &met);
        assert_int_equal(n, 20);
        for (int k = 0; k < n; k++) {
            int64_t p = (int64_t)row[k][0] - 1;
            assert_int_equal(p, k);
            double d = fabs(row[k][1] - b.ref[3 * p]);
            miss += !(d <= row[k][2]), total++, width += row[k][2] / b.ref[3 * p];
        }
    }
    test_case_done();
    print_message("final --patches 1-20 (the corridor's floor), 256 samples: %d of %d intervals miss; half-width / B "
                  "%.3f (mean)\n", miss, total, total ? width / total : 0.0);
    if (test_case_all()) assert_true(miss <= total / 20);
    box_close(&b);
    b = box_open();
    int n = run_chosen(&b, "1-16", 0.1, 0, 9, row, 68, &met);
    assert_int_equal(n, 16);
    assert_true(met);
    for (int k = 0; k < n; k++) {
        assert_int_equal((int64_t)row[k][0], k + 1);
        assert_true(row[k][2] <= 0.1 * row[k][1]);
        assert_true(fabs(row[k][1] - b.ref[3 * k]) <= row[k][2]);
    }
    box_close(&b);
}

/* The same bits at 1 and 2 threads, and on a subset (ulam_rad_final_some); a stop before the
 * gather leaves NaN and says so; the errors. */
static void test_final_threads_and_errors(void **state)
{
    (void)state;
    box b = box_open();
    int64_t n = b.s->npatches;
    double *B1 = malloc(6 * (size_t)n * sizeof *B1), *B2 = B1 + 3 * n, *se = malloc(6 * (size_t)n * sizeof *se),
           *half = se + 3 * n;
    assert_non_null(B1), assert_non_null(se);
    ulam_rad_final_info in;
    run(&b, 0.0, 128, 0, 7, 1, B1, se, half, &in);
    run(&b, 0.0, 128, 0, 7, 2, B2, se, half, &in);
    assert_memory_equal(B1, B2, 3 * (size_t)n * sizeof *B1);
    assert_int_equal(in.gathered, n);
    assert_int_equal(in.scene.lit, n);
    assert_int_equal(in.scene.unreached, 0);
    assert_true(in.rays == 2 * in.samples);
    /* ulam_rad_final_some on the even patches: their bits as the whole run's, the others NaN and
       out of the rule */
    unsigned char *want = malloc((size_t)n);
    assert_non_null(want);
    for (int64_t p = 0; p < n; p++) want[p] = p % 2 == 0;
    ulam_rad_opts q = ulam_rad_defaults();
    q.stop.rel_err = 0.0, q.stop.max_walks = 128, q.exec.seed = 7, q.exec.threads = 2;
    assert_int_equal(ulam_rad_final_some(b.t, &q, 0, 1.0, want, B2, se, half, &in, NULL), ULAM_OK);
    for (int64_t p = 0; p < n; p++)
        if (want[p]) assert_memory_equal(B1 + 3 * p, B2 + 3 * p, 3 * sizeof *B1);
        else assert_true(isnan(B2[3 * p]));
    assert_int_equal(in.gathered, n / 2);
    assert_int_equal(in.scene.lit, n / 2);
    assert_int_equal(in.scene.unreached, 0);
    free(want);
    ulam_rad_opts o = ulam_rad_defaults();
    volatile int stop = 1;
    o.stop.rel_err = 0.1, o.stop.interrupt = &stop, o.exec.threads = 2;
    assert_int_equal(ulam_rad_final(b.t, &o, 4096, 1.0, B1, se, half, &in, NULL), ULAM_OK);
    assert_true(in.interrupted);
    assert_true(isnan(B1[0]) && in.gathered == 0 && !in.met && in.scene.unreached == n);
    o.stop.interrupt = NULL;
    assert_int_equal(ulam_rad_final(b.t, &o, 4096, 0.0, B1, se, half, &in, NULL), ULAM_EINVAL);
    assert_int_equal(ulam_rad_final(b.t, &o, -1, 1.0, B1, se, half, &in, NULL), ULAM_EINVAL);
    assert_int_equal(ulam_rad_final(b.t, &o, 4096, 1.0, NULL, se, half, &in, NULL), ULAM_EINVAL);
    free(B1), free(se);
    box_close(&b);
}

/* The modes by name: a row each, found and named. */
static void test_final_modes(void **state)
{
    (void)state;
    const char *names[] = {"gather", "shoot", "final"}, *summary = NULL;
    const int modes[] = {ULAM_ADJOINT, ULAM_FORWARD, ULAM_RAD_FINAL};
    for (int k = 0; k < 3; k++) {
        assert_int_equal(ulam_rad_mode_find(names[k]), modes[k]);
        assert_string_equal(ulam_rad_mode_name(modes[k], &summary), names[k]);
        assert_non_null(summary);
    }
    assert_int_equal(ulam_rad_mode_find("jacobi"), -1);
    assert_int_equal(ulam_rad_mode_find(NULL), -1);
    assert_null(ulam_rad_mode_name(7, NULL));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_final_modes),
        cmocka_unit_test(test_final_threads_and_errors),
        cmocka_unit_test(test_final_coverage),
        cmocka_unit_test(test_final_corridor),
        cmocka_unit_test(test_final_chosen),
    };
    return test_run(tests);
}
