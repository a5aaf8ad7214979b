/* Shooting's whole-scene rule (ulam_rad_solver_whole, issue 40 point 5): --mode shoot --rel-err E
 * stopped when patch 1 met E, whatever the rest of the room.  The scene, written here: an open box
 * of 4 x 4 x 4 unit patches (80, no ceiling), reflectance 0.6, a floor patch the lamp, patch 1 the
 * wall patch facing it (among the brightest), and a closed unit block on a floor patch, which no
 * light can reach.  The rule of patch 1 leaves dim patches far past E (measured: the worst relative
 * standard error 0.15 at E = 0.025, 2 of 84 lit patches within E); the whole-scene rule meets E on every lit patch, names the
 * floor patch under the block, and its answers agree with the direct solve (counted over seeds). */
#include "testutil.h"
#include "ulam_radiosity.h"

enum { L = 4 };

/* Quad a b c d (counter-clockwise seen from the lit side) with material m. */
static void quad(FILE *f, int *nv, const char *m, const double q[4][3])
{
    for (int k = 0; k < 4; k++) fprintf(f, "v %g %g %g\n", q[k][0], q[k][1], q[k][2]);
    fprintf(f, "usemtl %s\nf %d %d %d %d\n", m, *nv + 1, *nv + 2, *nv + 3, *nv + 4);
    *nv += 4;
}

/* The floor patch under the block (0-based): written after the 64 walls, cell (2, 1). */
static const int64_t under = 64 + 2 * L + 1;

/* Write the scene; path gets the OBJ. */
static void write_scene(char dir[64], char path[96])
{
    FILE *f = test_scene_open(dir, path, "newmtl white\nKd 0.6 0.6 0.6\nnewmtl lamp\nKd 0.5 0.5 0.5\nKe 10 10 10\n");
    int nv = 0;
    for (int i = 0; i < L; i++) /* z = L wall first: patch 1 is (1, 0) on it, 1.5 from the lamp */
        for (int j = 0; j < L; j++) {
            double x0 = (i + 1) % L, y = j; /* (1, 0) first */
            quad(f, &nv, "white", (const double[4][3]){{x0, y, L}, {x0, y + 1, L}, {x0 + 1, y + 1, L}, {x0 + 1, y, L}});
        }
    for (int i = 0; i < L; i++)
        for (int j = 0; j < L; j++) {
            quad(f, &nv, "white", (const double[4][3]){{i, j, 0}, {i + 1, j, 0}, {i + 1, j + 1, 0}, {i, j + 1, 0}});
            quad(f, &nv, "white", (const double[4][3]){{0, j, i}, {0, j + 1, i}, {0, j + 1, i + 1}, {0, j, i + 1}});
            quad(f, &nv, "white", (const double[4][3]){{L, j, i}, {L, j, i + 1}, {L, j + 1, i + 1}, {L, j + 1, i}});
        }
    for (int i = 0; i < L; i++)
        for (int k = 0; k < L; k++)
            quad(f, &nv, i == 1 && k == 3 ? "lamp" : "white",
                 (const double[4][3]){{i, 0, k}, {i, 0, k + 1}, {i + 1, 0, k + 1}, {i + 1, 0, k}});
    /* the block on floor cell (2, 1): x in [a, b], z in [c, d]; its top and four sides, facing out */
    double a = 2, b = 3, c = 1, d = 2, h = 1;
    quad(f, &nv, "white", (const double[4][3]){{a, h, c}, {a, h, d}, {b, h, d}, {b, h, c}});
    quad(f, &nv, "white", (const double[4][3]){{a, 0, c}, {a, 0, d}, {a, h, d}, {a, h, c}});
    quad(f, &nv, "white", (const double[4][3]){{b, 0, c}, {b, h, c}, {b, h, d}, {b, 0, d}});
    quad(f, &nv, "white", (const double[4][3]){{a, 0, d}, {b, 0, d}, {b, h, d}, {a, h, d}});
    quad(f, &nv, "white", (const double[4][3]){{a, 0, c}, {a, h, c}, {b, h, c}, {b, 0, c}});
    fclose(f);
}

/* Shoot on t to rel_err E with seed (whole: the whole-scene rule at share 1); B, se (3 per patch)
 * and the scene's state. */
static int64_t shoot(const ulam_tracer *t, double E, uint64_t seed, int whole, double *B, double *se,
                     ulam_rad_scene_rule *q, int64_t *unreached)
{
    ulam_rad_opts o = ulam_rad_defaults();
    o.mode = ULAM_FORWARD, o.estimator = ULAM_RAD_COLLISION, o.stop.rel_err = E, o.stop.max_walks = 50000000;
    o.exec.seed = seed, o.exec.threads = 2;
    ulam_rad_solver *s = NULL;
    assert_int_equal(ulam_rad_solver_alloc(t, &o, &s, NULL), ULAM_OK);
    if (whole) assert_int_equal(ulam_rad_solver_whole(s, 1.0), ULAM_OK);
    while (!ulam_rad_solver_done(s)) assert_int_equal(ulam_rad_solver_iterate(s), ULAM_OK);
    ulam_rad_result r;
    ulam_rad_solver_result(s, &r);
    assert_true(r.rel_err_met);
    assert_int_equal(ulam_rad_solver_vectors(s, B, se), ULAM_OK);
    assert_int_equal(ulam_rad_solver_scene(s, q, unreached, 4), ULAM_OK);
    ulam_rad_solver_free(s);
    return r.walks;
}

/* The largest relative standard error over the lit patches (B > 0). */
static double worst_rel(int64_t n, const double *B, const double *se)
{
    double w = 0.0;
    for (int64_t i = 0; i < 3 * n; i++)
        if (B[i] > 0) w = fmax(w, se[i] / B[i]);
    return w;
}

/* Patch 1's rule leaves the room short of E; the whole-scene rule does not, names the patch under
 * the block, and agrees with the direct solve within 1.96 combined standard errors on at least 92%
 * of the lit patches' (grey: one channel) over 4 seeds (expected 95%). */
static void test_whole_scene(void **state)
{
    (void)state;
    char dir[64], path[96];
    write_scene(dir, path);
    ulam_scene *s = NULL;
    ulam_error err;
    assert_int_equal(ulam_scene_read_obj(path, &s, &err), ULAM_OK);
    test_scene_rm(dir);
    ulam_tracer *t = NULL;
    assert_int_equal(ulam_tracer_alloc(s, &t, NULL), ULAM_OK);
    int64_t n = s->npatches, unreached[4];
    assert_int_equal(n, 85);
    double *B = malloc(3 * n * sizeof *B), *se = malloc(3 * n * sizeof *se), *Bd = malloc(3 * n * sizeof *Bd);
    double *sed = malloc(3 * n * sizeof *sed);
    const double E = 0.025;
    ulam_rad_scene_rule q;
    /* the reported case: the rule of patch 1 */
    int64_t w1 = shoot(t, E, 1, 0, B, se, &q, unreached);
    print_message("patch 1's rule: %lld walks, worst relative se %.4f, %lld of %lld lit patches met\n", (long long)w1,
                  worst_rel(n, B, se), (long long)q.met, (long long)q.lit);
    assert_true(worst_rel(n, B, se) > 2 * E && q.met < q.lit);
    /* the reference: the direct solve on F of 1e5 rays a patch, with its error bars */
    ulam_csr *F = NULL;
    assert_int_equal(ulam_ff_estimate(t, 100000, 7, 2, &F, NULL), ULAM_OK);
    assert_int_equal(ulam_rad_direct(s, F, (size_t)1 << 30, Bd, NULL, NULL), ULAM_OK);
    assert_int_equal(ulam_rad_direct_errors(s, F, 100000, Bd, (size_t)1 << 30, sed, NULL), ULAM_OK);
    int64_t in = 0, all = 0;
    for (uint64_t seed = 1; seed <= 4; seed++) {
        int64_t w = shoot(t, E, seed, 1, B, se, &q, unreached);
        print_message("whole scene, seed %llu: %lld walks, worst relative se %.4f (half-width %.3f), %lld of %lld lit "
                      "met, %lld unreached (patch %lld)\n", (unsigned long long)seed, (long long)w, worst_rel(n, B, se),
                      q.worst_half, (long long)q.met, (long long)q.lit, (long long)q.unreached,
                      (long long)unreached[0] + 1);
        assert_true(worst_rel(n, B, se) <= E && q.worst_se <= E);
        assert_int_equal(q.met, q.lit);
        assert_int_equal(q.lit, n - 1);
        assert_int_equal(q.unreached, 1);
        assert_int_equal(unreached[0], under);
        assert_true(B[3 * under] == 0.0);
        for (int64_t p = 0; p < n; p++) {
            if (p == under || s->emit[3 * p] > 0) continue;
            double z = (B[3 * p] - Bd[3 * p]) / sqrt(se[3 * p] * se[3 * p] + sed[3 * p] * sed[3 * p]);
            in += fabs(z) < 1.96, all++;
        }
    }
    print_message("direct solve within 1.96 sigma: %lld of %lld\n", (long long)in, (long long)all);
    assert_true(in >= 0.92 * all);
    ulam_csr_free(F);
    free(B), free(se), free(Bd), free(sed);
    ulam_tracer_free(t), ulam_scene_free(s);
}

/* The whole-scene rule is shooting's: gathering and bad shares are refused. */
static void test_whole_refused(void **state)
{
    (void)state;
    char dir[64], path[96];
    write_scene(dir, path);
    ulam_scene *s = NULL;
    assert_int_equal(ulam_scene_read_obj(path, &s, NULL), ULAM_OK);
    test_scene_rm(dir);
    ulam_tracer *t = NULL;
    assert_int_equal(ulam_tracer_alloc(s, &t, NULL), ULAM_OK);
    ulam_rad_opts o = ulam_rad_defaults();
    ulam_rad_solver *g = NULL, *f = NULL;
    assert_int_equal(ulam_rad_solver_alloc(t, &o, &g, NULL), ULAM_OK);
    assert_int_equal(ulam_rad_solver_whole(g, 1.0), ULAM_EINVAL);
    o.mode = ULAM_FORWARD, o.estimator = ULAM_RAD_COLLISION;
    assert_int_equal(ulam_rad_solver_alloc(t, &o, &f, NULL), ULAM_OK);
    assert_int_equal(ulam_rad_solver_whole(f, 0.0), ULAM_EINVAL);
    assert_int_equal(ulam_rad_solver_whole(f, 1.5), ULAM_EINVAL);
    assert_int_equal(ulam_rad_solver_whole(f, NAN), ULAM_EINVAL);
    assert_int_equal(ulam_rad_solver_whole(f, 0.5), ULAM_OK);
    ulam_rad_scene_rule q;
    assert_int_equal(ulam_rad_solver_scene(g, &q, NULL, 0), ULAM_EINVAL);
    assert_int_equal(ulam_rad_solver_scene(f, &q, NULL, 1), ULAM_EINVAL);
    ulam_rad_solver_free(g), ulam_rad_solver_free(f);
    ulam_tracer_free(t), ulam_scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_whole_scene), cmocka_unit_test(test_whole_refused)};
    return test_run(tests);
}
