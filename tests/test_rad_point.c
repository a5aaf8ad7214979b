/* Point queries on the continuous surfaces (src/radiosity/point.c) and sensor grids: the
 * irradiance at a point against Howell's closed forms (a differential planar element to a
 * parallel rectangle and to a rectangle in a perpendicular plane, signed corner sums for
 * points beside the emitter), the furnace (B = E / (1 - rho) at every point and every sensor),
 * 95% intervals counted over 100 seeds with a binomial bound, the options refused, and the
 * grid's points and picture.  Fixed seeds; tolerances from the reported standard errors. */
#include "testutil.h"
#include "ulam_radiosity.h"

#include <string.h>
#include <unistd.h>

/* Howell: element whose normal passes through a corner of a parallel a x b rectangle at c. */
static double howell_parallel(double a, double b, double c)
{
    double A = a / c, B = b / c, sa = sqrt(1 + A * A), sb = sqrt(1 + B * B);
    return (A / sa * atan(B / sa) + B / sb * atan(A / sb)) / (2 * M_PI);
}

/* Howell: element at distance c from the edge of an a (height) x b rectangle in a perpendicular
 * plane, in front of its corner. */
static double howell_perpendicular(double a, double b, double c)
{
    double X = a / b, Y = c / b, r = sqrt(X * X + Y * Y);
    return (atan(1 / Y) - Y / r * atan(1 / r)) / (2 * M_PI);
}

/* The signed corner term of a parallel rectangle reaching u, v from the foot of the normal. */
static double par_corner(double u, double v, double c)
{
    if (u == 0 || v == 0) return 0.0;
    return copysign(1.0, u) * copysign(1.0, v) * howell_parallel(fabs(u), fabs(v), c);
}

/* Form factor from (px, py) facing up to the lamp [x0, x1] x [y0, y1] at height c facing down. */
static double parallel_at(double px, double py, double x0, double x1, double y0, double y1, double c)
{
    return par_corner(x1 - px, y1 - py, c) - par_corner(x0 - px, y1 - py, c) - par_corner(x1 - px, y0 - py, c) +
           par_corner(x0 - px, y0 - py, c);
}

/* Form factor from floor point (px, py) to the unit lamp x in [0, 1], z in [0, 1] at y = 0. */
static double perpendicular_at(double px, double py)
{
    double u1 = 1 - px, u0 = -px;
    double f1 = u1 == 0 ? 0 : copysign(howell_perpendicular(1, fabs(u1), py), u1);
    double f0 = u0 == 0 ? 0 : copysign(howell_perpendicular(1, fabs(u0), py), u0);
    return f1 - f0;
}

/* A scene and its tracer that must build. */
static ulam_tracer *must_load(const char *path, ulam_scene **s)
{
    ulam_error err;
    int st = ulam_scene_read_obj(path, s, &err);
    if (st) print_error("%s:%ld: %s\n", path, err.line, err.msg);
    assert_int_equal(st, ULAM_OK);
    ulam_tracer *t = NULL;
    assert_int_equal(ulam_tracer_alloc(*s, &t, NULL), ULAM_OK);
    return t;
}

/* A tracer on a scene already read. */
static ulam_tracer *must_tracer_of(const ulam_scene *s)
{
    ulam_tracer *t = NULL;
    assert_int_equal(ulam_tracer_alloc(s, &t, NULL), ULAM_OK);
    return t;
}

/* A point query that must run: walks walks (or rel_err), estimator est. */
static ulam_rad_point query(const ulam_tracer *t, const double x[3], const double *n, int est, int64_t walks,
                            double rel_err, uint64_t seed)
{
    ulam_rad_opts o = ulam_rad_defaults();
    o.estimator = est, o.stop.max_walks = walks, o.stop.rel_err = rel_err, o.exec.seed = seed, o.exec.threads = 2;
    ulam_rad_point r;
    ulam_error err;
    int st = ulam_rad_point_query(t, &o, x, n, &r, &err);
    if (st) print_error("%s: %s\n", ulam_strerror(st), err.msg);
    assert_int_equal(st, ULAM_OK);
    return r;
}

/* Every channel of r's irradiance against exact within 4 standard errors (and the error bar
 * small enough for the check to mean something); the radiosity B = E + rho H on a grey floor. */
static void check_point(const ulam_rad_point *r, double exact, double rho, const char *what)
{
    print_message("%s: H %.6f +- %.2g, exact %.6f, z %+.2f (%lld walks, %lld rays)\n", what, r->irradiance[0],
                  r->irradiance_se[0], exact, (r->irradiance[0] - exact) / r->irradiance_se[0],
                  (long long)r->run.walks, (long long)r->run.rays);
    for (int c = 0; c < 3; c++) {
        assert_true(r->irradiance_se[c] > 0 && r->irradiance_se[c] < 0.02 * exact);
        assert_close(r->irradiance[c], exact, 4 * r->irradiance_se[c]);
        if (r->patch >= 0) assert_close(r->radiosity[c], rho * r->irradiance[c], 1e-12);
    }
}

/* Floor points under, inside and beside a parallel lamp, and a sensor in the air. */
static void test_point_parallel(void **state)
{
    (void)state;
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load("tests/data/rad/point_parallel.obj", &s);
    const double pts[6][2] = {{0, 0}, {0.5, 1}, {0.9, 0.1}, {-0.5, 1}, {1.5, -0.5}, {0.5, 2.02}}; /* last: beside an edge */
    for (int k = 0; k < 6; k++) {
        double x[3] = {pts[k][0], pts[k][1], 0}, exact = parallel_at(x[0], x[1], 0, 1, 0, 2, 1);
        for (int est = ULAM_RAD_NEXT_EVENT; est <= ULAM_RAD_COLLISION; est += est == ULAM_RAD_NEXT_EVENT ? 3 : 1) {
            ulam_rad_point r = query(t, x, NULL, est, est == ULAM_RAD_COLLISION ? 200000 : 40000, 0, 10 + (uint64_t)k);
            assert_int_equal(r.patch, 1);
            check_point(&r, exact, 0.5, est == ULAM_RAD_COLLISION ? "parallel, collision" : "parallel, next-event");
        }
    }
    /* a sensor off the surfaces, half way up, facing the lamp: the same law at c = 0.5 */
    double x[3] = {0.25, 0.5, 0.5}, n[3] = {0, 0, 2};
    ulam_rad_point r = query(t, x, n, ULAM_RAD_NEXT_EVENT, 40000, 0, 3);
    assert_int_equal(r.patch, -1);
    assert_true(isnan(r.radiosity[0]));
    check_point(&r, parallel_at(0.25, 0.5, 0, 1, 0, 2, 0.5), 0, "parallel, sensor in the air");
    ulam_tracer_free(t);
    ulam_scene_free(s);
}

/* Floor points in front of a perpendicular lamp, at its corner, beside it, and 0.02 from the
 * edge it stands on (where G / p_L ~ 1 / r^2 and only MIS keeps the variance finite). */
static void test_point_perpendicular(void **state)
{
    (void)state;
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load("tests/data/rad/point_perpendicular.obj", &s);
    const double pts[5][2] = {{0, 0.5}, {0.5, 0.5}, {-0.5, 0.3}, {1.2, 1.5}, {0.5, 0.02}};
    for (int k = 0; k < 5; k++) {
        double x[3] = {pts[k][0], pts[k][1], 0};
        ulam_rad_point r = query(t, x, NULL, ULAM_RAD_NEXT_EVENT, 40000, 0, 20 + (uint64_t)k);
        check_point(&r, perpendicular_at(x[0], x[1]), 0.5, "perpendicular, next-event");
    }
    ulam_tracer_free(t);
    ulam_scene_free(s);
}

/* The furnace: H = B = E / (1 - rho) at points on faces, near an edge and a corner, and for a
 * tilted sensor in the air; walks of several bounces. */
static void test_point_furnace(void **state)
{
    (void)state;
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load("tests/data/rad/furnace_half.obj", &s);
    const double B[3] = {2.0, 1.5, 0.4 / 0.3};
    const double pts[4][3] = {{0.5, 0.5, 0}, {0.01, 0.99, 0}, {1, 0.3, 0.999}, {0.3, 0.2, 0.7}};
    for (int k = 0; k < 4; k++) {
        double n[3] = {1, 2, 3};
        ulam_rad_point r = query(t, pts[k], k == 3 ? n : NULL, ULAM_RAD_NEXT_EVENT, 20000, 0, 40 + (uint64_t)k);
        assert_true(r.run.rays > 3 * r.run.walks); /* several bounces */
        for (int c = 0; c < 3; c++) {
            print_message("furnace point %d %c: H %.5f +- %.2g (exact %.5f)\n", k, "RGB"[c], r.irradiance[c],
                          r.irradiance_se[c], B[c]);
            assert_true(r.irradiance_se[c] < 0.01 * B[c]);
            assert_close(r.irradiance[c], B[c], 4 * r.irradiance_se[c]);
            if (k < 3) assert_close(r.radiosity[c], B[c], 4 * r.radiosity_se[c]);
        }
    }
    ulam_tracer_free(t);
    ulam_scene_free(s);
}

/* 95% intervals over 100 seeds, 200 walks each (small: the variance estimate itself is noisy),
 * at the hard point 0.02 from the perpendicular lamp's edge, and at rel_err 0.05 (a stopping
 * rule) on the parallel lamp: at least 88 of 100 cover (P(Binomial(100, 0.95) < 88) < 0.002). */
static void test_point_coverage(void **state)
{
    (void)state;
    const char *scene[2] = {"tests/data/rad/point_perpendicular.obj", "tests/data/rad/point_parallel.obj"};
    for (int m = 0; m < 2; m++) {
        ulam_scene *s = NULL;
        ulam_tracer *t = must_load(scene[m], &s);
        double x[3] = {0.5, m ? 1.0 : 0.02, 0}, exact = m ? parallel_at(0.5, 1, 0, 1, 0, 2, 1) : perpendicular_at(0.5, 0.02);
        int inside = 0;
        for (uint64_t seed = 0; seed < 100; seed++) {
            ulam_rad_point r = query(t, x, NULL, ULAM_RAD_NEXT_EVENT, m ? 0 : 200, m ? 0.05 : 0, 1000 + seed);
            inside += fabs(r.irradiance[0] - exact) <= 1.96 * r.irradiance_se[0];
        }
        print_message("%s: %d of 100 intervals cover (%s)\n", scene[m], inside, m ? "rel_err 0.05" : "200 walks");
        assert_true(inside >= 88);
        ulam_tracer_free(t);
        ulam_scene_free(s);
    }
}

/* Bad points and options are refused with ULAM_EINVAL and a message. */
static void test_point_refused(void **state)
{
    (void)state;
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load("tests/data/rad/point_parallel.obj", &s);
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.max_walks = 100;
    ulam_rad_solver *sv = NULL;
    ulam_error err;
    double air[3] = {0.5, 0.5, 0.5}, floor_pt[3] = {0.5, 0.5, 0}, down[3] = {0, 0, -1}, zero[3] = {0, 0, 0};
    double bad[3] = {NAN, 0, 0};
    assert_int_equal(ulam_rad_point_alloc(t, &o, air, NULL, &sv, &err), ULAM_EINVAL); /* on no patch, no normal */
    assert_non_null(strstr(err.msg, "normal"));
    assert_int_equal(ulam_rad_point_alloc(t, &o, floor_pt, down, &sv, &err), ULAM_EINVAL); /* not the floor's */
    assert_int_equal(ulam_rad_point_alloc(t, &o, air, zero, &sv, &err), ULAM_EINVAL);
    assert_int_equal(ulam_rad_point_alloc(t, &o, bad, NULL, &sv, &err), ULAM_EINVAL);
    o.estimator = ULAM_RAD_ABSORPTION;
    assert_int_equal(ulam_rad_point_alloc(t, &o, floor_pt, NULL, &sv, &err), ULAM_EINVAL);
    o.estimator = ULAM_RAD_NEXT_EVENT, o.mode = ULAM_FORWARD;
    assert_int_equal(ulam_rad_point_alloc(t, &o, floor_pt, NULL, &sv, &err), ULAM_EINVAL);
    assert_null(sv);
    o.mode = ULAM_ADJOINT;
    assert_int_equal(ulam_rad_point_alloc(t, &o, floor_pt, NULL, &sv, &err), ULAM_OK);
    ulam_rad_point r;
    assert_int_equal(ulam_rad_point_result(sv, &r), ULAM_OK);
    assert_int_equal(r.run.walks, 0);
    sv = ulam_rad_solver_free(sv);
    o.index = 1; /* a patch solver has no point result */
    assert_int_equal(ulam_rad_solver_alloc(t, &o, &sv, &err), ULAM_OK);
    assert_int_equal(ulam_rad_point_result(sv, &r), ULAM_EINVAL);
    ulam_rad_solver_free(sv);
    /* the default estimator of a patch walk is next-event now, and shooting refuses it */
    assert_int_equal(ulam_rad_defaults().estimator, ULAM_RAD_NEXT_EVENT);
    ulam_tracer_free(t);
    ulam_scene_free(s);
}

/* A 4 x 3 grid on the floor under the parallel lamp: every sensor against Howell, each with its
 * own seed (a point's answer does not depend on the grid), and the false-colour picture. */
static void test_grid(void **state)
{
    (void)state;
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load("tests/data/rad/point_parallel.obj", &s);
    ulam_rad_grid g = {.origin = {-1, -0.5, 0}, .u = {3, 0, 0}, .v = {0, 3, 0}, .normal = {0, 0, 1}, .nu = 4, .nv = 3};
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.rel_err = 0.02, o.stop.max_walks = 0, o.exec.seed = 5, o.exec.threads = 2;
    ulam_rad_point pts[12];
    ulam_error err;
    assert_int_equal(ulam_rad_grid_solve(t, &o, &g, pts, &err), ULAM_OK);
    double Y[12];
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 4; i++) {
            const ulam_rad_point *r = &pts[j * 4 + i];
            double x[3];
            ulam_rad_grid_point(&g, i, j, x);
            assert_close(x[0], -1 + 0.75 * (2 * i + 1) / 2.0 * 1.0, 1e-12);
            assert_close(r->x[1], -0.5 + (j + 0.5), 1e-12);
            check_point(r, parallel_at(x[0], x[1], 0, 1, 0, 2, 1), 0.5, "grid");
            assert_true(r->irradiance_se[0] <= 0.02 * r->irradiance[0]);
            Y[j * 4 + i] = r->irradiance[1];
        }
    g.nu = 0;
    assert_int_equal(ulam_rad_grid_solve(t, &o, &g, pts, &err), ULAM_EINVAL);
    g.nu = 4, g.normal[2] = 2;
    assert_int_equal(ulam_rad_grid_solve(t, &o, &g, pts, &err), ULAM_EINVAL);
    int w, h;
    ulam_falsecolour_size(4, 3, 10, 10, &w, &h);
    unsigned char *rgb = malloc((size_t)w * (size_t)h * 3);
    assert_int_equal(ulam_falsecolour(Y, 4, 3, 10, 10, 0, 0.4, rgb), ULAM_OK);
    /* the brightest cell is red-ish, the darkest blue-ish; cell (i, j) at rows from the top */
    int hi = 0, lo = 0;
    for (int k = 1; k < 12; k++) hi = Y[k] > Y[hi] ? k : hi, lo = Y[k] < Y[lo] ? k : lo;
    const unsigned char *ph = rgb + 3 * ((size_t)((2 - hi / 4) * 10 + 5) * (size_t)w + (size_t)(hi % 4) * 10 + 5);
    const unsigned char *pl = rgb + 3 * ((size_t)((2 - lo / 4) * 10 + 5) * (size_t)w + (size_t)(lo % 4) * 10 + 5);
    assert_true(ph[0] > ph[2] && pl[2] > pl[0]);
    assert_int_equal(ulam_falsecolour(Y, 4, 3, 10, 10, 1, 1, rgb), ULAM_EINVAL);
    free(rgb);
    ulam_tracer_free(t);
    ulam_scene_free(s);
}

/* Points asked for by the caller (ulam_rad_points_solve): point k is the point query seeded by
 * ulam_rng_substream(seed, ULAM_STREAM_POINT, k), bit for bit, and within 4 standard errors of
 * Howell on the floor; the illuminance and the grid summary are the luminance-weighted sums (a
 * grey scene: Y = H); a point on no patch without a normal is point k's ULAM_EINVAL. */
static void test_points_solve(void **state)
{
    (void)state;
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load("tests/data/rad/point_parallel.obj", &s);
    double at[3][6] = {{0.25, 0.5, 0, NAN, NAN, NAN}, {1.5, 1.5, 0, NAN, NAN, NAN}, {0.5, 1.0, 0, 0, 0, 1}};
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.rel_err = 0.02, o.stop.max_walks = 0, o.exec.seed = 9, o.exec.threads = 2;
    ulam_rad_point pts[3], one;
    ulam_error err;
    assert_int_equal(ulam_rad_points_solve(t, &o, &at[0][0], 3, pts, &err), ULAM_OK);
    double sum = 0, min = INFINITY;
    for (int k = 0; k < 3; k++) {
        ulam_rad_opts ok = o;
        ok.exec.seed = ulam_rng_substream(9, ULAM_STREAM_POINT, (uint64_t)k);
        assert_int_equal(ulam_rad_point_query(t, &ok, at[k], isnan(at[k][3]) ? NULL : at[k] + 3, &one, &err), ULAM_OK);
        assert_memory_equal(one.irradiance, pts[k].irradiance, sizeof one.irradiance);
        assert_true(one.run.walks == pts[k].run.walks);
        check_point(&pts[k], parallel_at(at[k][0], at[k][1], 0, 1, 0, 2, 1), 0.5, "points");
        double Y, se, lo, hi;
        ulam_rad_illuminance(&pts[k], &Y, &se);
        ulam_rad_illuminance_ci(&pts[k], &lo, &hi);
        const double *w = ulam_rad_luma();
        assert_close(Y, w[0] * pts[k].irradiance[0] + w[1] * pts[k].irradiance[1] + w[2] * pts[k].irradiance[2], 1e-15);
        assert_close(w[0] + w[1] + w[2], 1.0, 1e-12);
        assert_true(lo <= Y && Y <= hi && se > 0);
        sum += Y, min = fmin(min, Y);
    }
    ulam_rad_grid_summary gs;
    assert_int_equal(ulam_rad_grid_stats(pts, 3, &gs), ULAM_OK);
    assert_close(gs.mean, sum / 3, 1e-15);
    assert_close(gs.min, min, 0);
    assert_close(gs.uniformity, min / (sum / 3), 1e-15);
    assert_true(gs.walks == pts[0].run.walks + pts[1].run.walks + pts[2].run.walks && gs.worst > 0 && gs.worst < 0.03);
    assert_int_equal(ulam_rad_grid_stats(pts, 0, &gs), ULAM_EINVAL);
    at[1][0] = at[1][1] = at[1][2] = 100; /* on no patch, and no normal given */
    assert_int_equal(ulam_rad_points_solve(t, &o, &at[0][0], 3, pts, &err), ULAM_EINVAL);
    assert_int_equal(err.index, 1);
    ulam_tracer_free(t);
    ulam_scene_free(s);
}

/* One-sensor grids (the grid's shared solver) over 100 seeds each: every score within the
 * walk's certified range (a score past it leaves the run no interval, so every interval must be
 * finite), and the printed 95% interval (src/stop.c's, on that range) covering the exact
 * irradiance in at least 88 of 100 runs in every channel (P(Binomial(100, 0.95) < 88) < 0.002):
 * the furnace (every face a grey-ish emitter, so walks of many bounces and landings on
 * emitters that reflect) for a tilted sensor in the air at rel_err 0.05, and the black lamp of
 * the parallel scene (one landing a walk) at a fixed 200 walks. */
static void test_grid_interval(void **state)
{
    (void)state;
    const char *scene[2] = {"tests/data/rad/furnace_half.obj", "tests/data/rad/point_parallel.obj"};
    for (int m = 0; m < 2; m++) {
        ulam_scene *s = NULL;
        ulam_tracer *t = must_load(scene[m], &s);
        double nf = 1.0 / sqrt(14.0);
        ulam_rad_grid g = m ? (ulam_rad_grid){.origin = {0.4, 0.9, 0}, .u = {0.2, 0, 0}, .v = {0, 0.2, 0},
                                              .normal = {0, 0, 1}, .nu = 1, .nv = 1}
                            : (ulam_rad_grid){.origin = {0.2, 0.1, 0.7}, .u = {0.2, 0, 0}, .v = {0, 0.2, 0},
                                              .normal = {nf, 2 * nf, 3 * nf}, .nu = 1, .nv = 1};
        double exact[3] = {2.0, 1.5, 0.4 / 0.3};
        if (m) exact[0] = exact[1] = exact[2] = parallel_at(0.5, 1, 0, 1, 0, 2, 1);
        ulam_rad_opts o = ulam_rad_defaults();
        o.stop.rel_err = m ? 0 : 0.05, o.stop.max_walks = m ? 200 : 0, o.exec.threads = 2;
        int inside[3] = {0, 0, 0}, finite = 0;
        int64_t walks = 0;
        for (uint64_t seed = 0; seed < 100; seed++) {
            ulam_rad_point r;
            ulam_error err;
            o.exec.seed = 3000 + seed;
            assert_int_equal(ulam_rad_grid_solve(t, &o, &g, &r, &err), ULAM_OK);
            int ok = 1;
            for (int c = 0; c < 3; c++) {
                ok &= isfinite(r.run.ci95[c][0]) && isfinite(r.run.ci95[c][1]);
                inside[c] += r.run.ci95[c][0] <= exact[c] && exact[c] <= r.run.ci95[c][1];
            }
            finite += ok, walks += r.run.walks;
        }
        print_message("%s: %d of 100 runs within the certified range; the 95%% interval covers %d, %d, %d of 100 "
                      "(%lld walks)\n", scene[m], finite, inside[0], inside[1], inside[2], (long long)walks);
        assert_int_equal(finite, 100);
        for (int c = 0; c < 3; c++) assert_true(inside[c] >= 88);
        ulam_tracer_free(t);
        ulam_scene_free(s);
    }
}

/* The grid's sensors share one solver (ulam__rad_point_restart), yet a sensor's answer is its
 * own: the second sensor of two grids whose first sensors differ reads bit for bit the same. */
static void test_grid_shared_solver(void **state)
{
    (void)state;
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load("tests/data/rad/point_parallel.obj", &s);
    /* cell centres origin + (i + 0.5) / 2 u: both grids' second sensor is at (0.5, 1, 0) */
    ulam_rad_grid a = {.origin = {-0.25, 1, 0}, .u = {1, 0, 0}, .v = {0, 0.1, 0}, .normal = {0, 0, 1}, .nu = 2, .nv = 1};
    ulam_rad_grid b = {.origin = {0.125, 1, 0}, .u = {0.5, 0, 0}, .v = {0, 0.1, 0}, .normal = {0, 0, 1}, .nu = 2, .nv = 1};
    a.origin[1] = b.origin[1] = 0.95;
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.rel_err = 0.03, o.stop.max_walks = 0, o.exec.seed = 11, o.exec.threads = 2;
    ulam_rad_point pa[2], pb[2];
    assert_int_equal(ulam_rad_grid_solve(t, &o, &a, pa, NULL), ULAM_OK);
    assert_int_equal(ulam_rad_grid_solve(t, &o, &b, pb, NULL), ULAM_OK);
    assert_true(pa[0].x[0] != pb[0].x[0] && pa[0].run.walks > 0 && pb[0].run.walks > 0);
    assert_close(pa[1].x[0], 0.5, 1e-12);
    assert_close(pb[1].x[0], 0.5, 1e-12);
    for (int c = 0; c < 3; c++) {
        assert_true(pa[1].irradiance[c] == pb[1].irradiance[c] && pa[1].irradiance_se[c] == pb[1].irradiance_se[c]);
        assert_true(pa[1].run.ci95[c][0] == pb[1].run.ci95[c][0] && pa[1].run.ci95[c][1] == pb[1].run.ci95[c][1]);
    }
    assert_true(pa[1].run.walks == pb[1].run.walks && pa[1].run.rays == pb[1].run.rays);
    check_point(&pa[1], parallel_at(0.5, 1, 0, 1, 0, 2, 1), 0.5, "grid, shared solver");
    ulam_tracer_free(t);
    ulam_scene_free(s);
}

/* A patch solver run to its end with options o. */
static ulam_rad_result run_solver(const ulam_tracer *t, const ulam_rad_opts *o)
{
    ulam_rad_solver *sv = NULL;
    assert_int_equal(ulam_rad_solver_alloc(t, o, &sv, NULL), ULAM_OK);
    while (!ulam_rad_solver_done(sv)) assert_int_equal(ulam_rad_solver_iterate(sv), ULAM_OK);
    ulam_rad_result r;
    ulam_rad_solver_result(sv, &r);
    ulam_rad_solver_free(sv);
    return r;
}

/* A patch query (next-event) at patch p to rel_err or walks. */
static ulam_rad_result patch_query(const ulam_tracer *t, int64_t p, double rel_err, int64_t walks, uint64_t seed)
{
    ulam_rad_opts o = ulam_rad_defaults();
    o.index = p, o.stop.rel_err = rel_err, o.stop.max_walks = walks, o.exec.seed = seed, o.exec.threads = 2;
    return run_solver(t, &o);
}

/* The mesh error flags the Cornell floor asked for at its centre with no subdivision (the
 * patch's one value, the floor's mean, is far from the surface's radiosity at the centroid),
 * and not a patch of a fine mesh away from the blocks' edges. */
static void test_mesh_error_flags(void **state)
{
    (void)state;
    ulam_scene *s = NULL, *fine = NULL;
    ulam_tracer *t = must_load("examples/scenes/cornell_box.obj", &s);
    int64_t p;
    assert_int_equal(ulam_scene_find(s, "floor", &p), ULAM_OK);
    ulam_rad_result pr = patch_query(t, p, 0.01, 0, 1);
    ulam_rad_opts o = ulam_rad_defaults();
    o.index = p, o.stop.rel_err = 0.02, o.stop.max_walks = 0, o.exec.seed = 2, o.exec.threads = 2;
    ulam_rad_mesh m;
    assert_int_equal(ulam_rad_mesh_error(t, &o, pr.radiosity, &m, NULL), ULAM_OK);
    assert_int_equal(m.npoints, 5);
    for (int c = 0; c < 3; c++) {
        double se = sqrt(pr.std_error[c] * pr.std_error[c] + m.point_se[0][c] * m.point_se[0][c]);
        print_message("Cornell floor %c: patch %.5f +- %.2g, surface at the centroid %.5f +- %.2g, mesh error %.4f\n",
                      "RGB"[c], pr.radiosity[c], pr.std_error[c], m.point[0][c], m.point_se[0][c], m.error[c]);
        assert_true(m.point[0][c] - pr.radiosity[c] > 10 * se); /* the centre is brighter than the floor's mean */
        assert_true(m.error[c] > 10 * pr.std_error[c]);         /* dominates */
    }
    /* a back-wall patch of a fine mesh (20 mm): the surface agrees with the patch within its
     * errors and the mesh's own, a few % of B (the points now run to their certified 2%, precise
     * enough to resolve the 2.2% the wall varies across it) */
    assert_int_equal(ulam_scene_subdivide(s, 20.0, &fine), ULAM_OK);
    ulam_tracer *tf = must_tracer_of(fine);
    assert_int_equal(ulam_scene_find(fine, "back_wall", &p), ULAM_OK);
    pr = patch_query(tf, p, 0.01, 0, 3);
    o.index = p;
    assert_int_equal(ulam_rad_mesh_error(tf, &o, pr.radiosity, &m, NULL), ULAM_OK);
    for (int c = 0; c < 3; c++) {
        double se = sqrt(pr.std_error[c] * pr.std_error[c] + m.error_se[c] * m.error_se[c]);
        print_message("fine back wall %c: patch %.5f +- %.2g, mesh error %.4f +- %.2g\n", "RGB"[c], pr.radiosity[c],
                      pr.std_error[c], m.error[c], m.error_se[c]);
        assert_true(m.error[c] < 4 * se + 0.03 * pr.radiosity[c]);
    }
    ulam_tracer_free(tf), ulam_tracer_free(t);
    ulam_scene_free(fine), ulam_scene_free(s);
}

/* Patch averages from a fine uniform mesh converge to the mean of the surface over the coarse
 * patch: the Cornell back wall, its children's patch queries area-weighted at about 8 x 8, against
 * the mean of point queries at 20 x 20 jittered points of the wall (stratified; its variance from
 * neighbouring strata collapsed in pairs, which errs high); the unsubdivided wall's one value
 * is off by many standard errors. */
static void test_mesh_converges(void **state)
{
    (void)state;
    ulam_scene *s = NULL, *fine = NULL;
    ulam_tracer *t = must_load("examples/scenes/cornell_box.obj", &s);
    int64_t P;
    assert_int_equal(ulam_scene_find(s, "back_wall", &P), ULAM_OK);
    /* the surface's mean over P: 400 uniform points, 200 walks each */
    ulam_rng r;
    ulam_rng_seed(&r, 77, 0);
    const double *v = s->vert;
    const int32_t *ix = s->vidx + s->start[P];
    assert_int_equal(s->start[P + 1] - s->start[P], 4);
    double sum = 0, pairs = 0, prev = 0;
    for (int k = 0; k < 400; k++) { /* a jittered point of stratum (k % 20, k / 20) of the (parallelogram) wall */
        double a = (k % 20 + ulam_rng_uniform(&r)) / 20, b = (k / 20 + ulam_rng_uniform(&r)) / 20, x[3];
        for (int d = 0; d < 3; d++)
            x[d] = v[3 * ix[0] + d] + a * (v[3 * ix[1] + d] - v[3 * ix[0] + d]) + b * (v[3 * ix[3] + d] - v[3 * ix[0] + d]);
        ulam_rad_point pt = query(t, x, NULL, ULAM_RAD_NEXT_EVENT, 200, 0, 500 + (uint64_t)k);
        sum += pt.radiosity[0];
        if (k % 2) pairs += (pt.radiosity[0] - prev) * (pt.radiosity[0] - prev);
        prev = pt.radiosity[0];
    }
    double mean = sum / 400, se_mean = sqrt(pairs) / 400;
    ulam_rad_result coarse = patch_query(t, P, 0.005, 0, 9);
    /* the fine mesh: every child of the wall (face of P) */
    double side = 0;
    for (int d = 0; d < 3; d++) side += (v[3 * ix[1] + d] - v[3 * ix[0] + d]) * (v[3 * ix[1] + d] - v[3 * ix[0] + d]);
    assert_int_equal(ulam_scene_subdivide(s, sqrt(side) / 8 * 1.0001, &fine), ULAM_OK);
    ulam_tracer *tf = must_tracer_of(fine);
    double A = 0, BA = 0, var = 0;
    int children = 0;
    for (int64_t q = 0; q < fine->npatches; q++) {
        if (fine->face[q] != s->face[P]) continue;
        ulam_rad_result c = patch_query(tf, q, 0, 1500, 1000 + (uint64_t)q);
        A += fine->area[q], BA += fine->area[q] * c.radiosity[0];
        var += fine->area[q] * fine->area[q] * c.std_error[0] * c.std_error[0];
        children++;
    }
    double Bf = BA / A, se_f = sqrt(var) / A, zf = (Bf - mean) / sqrt(se_f * se_f + se_mean * se_mean);
    double zc = (coarse.radiosity[0] - mean) / sqrt(coarse.std_error[0] * coarse.std_error[0] + se_mean * se_mean);
    print_message("back wall R: surface mean %.5f +- %.2g; %d children %.5f +- %.2g (z %+.2f); one patch %.5f +- %.2g "
                  "(z %+.2f)\n", mean, se_mean, children, Bf, se_f, zf, coarse.radiosity[0], coarse.std_error[0], zc);
    assert_true(children >= 64);
    assert_true(se_f < 0.01 * Bf && se_mean < 0.01 * mean);
    assert_true(fabs(zf) < 4);
    assert_true(fabs(zc) > 4);
    ulam_tracer_free(tf), ulam_tracer_free(t);
    ulam_scene_free(fine), ulam_scene_free(s);
}

/* ulam_rad_adapt with points to rel_err each (walks a cap), area importance unless Y. */
static ulam_rad_adapt_info adapt(const ulam_tracer *t, const double *Y, double target, double rel_err, int64_t walks,
                                 int64_t cap, uint64_t seed, ulam_scene **out)
{
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.rel_err = rel_err, o.stop.max_walks = walks, o.exec.seed = seed, o.exec.threads = 2;
    ulam_rad_adapt_info in;
    ulam_error err;
    int st = ulam_rad_adapt(t, &o, Y, target, cap, out, &in, &err);
    if (st) print_error("%s: %s\n", ulam_strerror(st), err.msg);
    assert_int_equal(st, ULAM_OK);
    print_message("adapt: %lld -> %lld patches, %lld splits in %lld rounds, mesh error %.4f -> %.4f (target %.3g), "
                  "%lld points, %lld rays, %.2f s\n", (long long)in.patches_in, (long long)in.patches,
                  (long long)in.splits, (long long)in.rounds, in.error0, in.error, target, (long long)in.points,
                  (long long)in.rays, in.seconds);
    return in;
}

/* The furnace: the radiosity is the same at every point, so any mesh is exact and adaptive
 * subdivision splits nothing (its measured mesh error, the points' noise removed, is below the
 * target from the start): 5 points inside each of the 6 faces and a node at each of the 8
 * corners on each of its 3 faces. */
static void test_adapt_furnace(void **state)
{
    (void)state;
    ulam_scene *s = NULL, *d = NULL;
    ulam_tracer *t = must_load("tests/data/rad/furnace_half.obj", &s);
    ulam_rad_adapt_info in = adapt(t, NULL, 0.02, 0.01, 20000, 1000, 5, &d);
    assert_true(in.met && !in.capped && !in.interrupted);
    assert_int_equal(in.splits, 0);
    assert_int_equal(d->npatches, s->npatches);
    assert_true(in.error0 <= 0.02 && in.points == 6 * 5 + 8 * 3);
    for (int64_t p = 0; p < s->npatches; p++) assert_close(d->area[p], s->area[p], 1e-12);
    ulam_tracer_free(t);
    ulam_scene_free(d), ulam_scene_free(s);
}

/* The Cornell box, whose floor and walls need a finer mesh near the blocks and the lamp: the
 * adaptive mesh reaches the target with fewer patches than the coarsest uniform --subdivide
 * that reaches it (each uniform mesh's error measured the same way, by ulam_rad_adapt with
 * nothing to split). */
static void test_adapt_cornell(void **state)
{
    (void)state;
    const double target = 0.25; /* uniform: 49 patches 0.311, 185 0.211 (0.21 took 662, 18 s more) */
    ulam_scene *s = NULL, *d = NULL;
    ulam_tracer *t = must_load("examples/scenes/cornell_box.obj", &s);
    ulam_rad_adapt_info in = adapt(t, NULL, target, 0, 1024, 100000, 7, &d);
    assert_true(in.met && in.error <= target && in.error0 > target && in.splits > 0);
    ulam_scene_free(d);
    int64_t uniform = 0;
    for (double L = 280; L > 30 && !uniform; L /= 2) {
        ulam_scene *u = NULL;
        assert_int_equal(ulam_scene_subdivide(s, L, &u), ULAM_OK);
        ulam_tracer *tu = must_tracer_of(u);
        ulam_rad_adapt_info iu = adapt(tu, NULL, 1e300, 0, 1024, u->npatches, 8, &d);
        print_message("uniform --subdivide %g: %lld patches, mesh error %.4f\n", L, (long long)u->npatches, iu.error);
        if (iu.error <= target) uniform = u->npatches;
        ulam_tracer_free(tu);
        ulam_scene_free(d), ulam_scene_free(u);
    }
    print_message("Cornell box to mesh error %.3g: adaptive %lld patches, uniform %lld\n", target,
                  (long long)in.patches, (long long)uniform);
    assert_true(uniform > 0 && in.patches < uniform);
    ulam_tracer_free(t);
    ulam_scene_free(s);
}

/* The view's importance in the furnace: every walk from the picture counts 1 at the patch seen
 * and 1 at each landing, on with probability mean rho = 0.6, so sum_p Y_p = 1 / (1 - 0.6) = 2.5
 * exactly (the landings are geometric: variance 0.6 / 0.4^2 a walk), and the picture's share S
 * sums to 1. */
static void test_importance_furnace(void **state)
{
    (void)state;
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load("tests/data/rad/furnace_half.obj", &s);
    ulam_camera cam = {{0.5, 0.5, 0.05}, {0, 0, 1}, {0, 1, 0}, 35, 25};
    double Y[6], sum = 0.0;
    const int64_t walks = 40000;
    assert_int_equal(ulam_rad_importance(t, &cam, 32, 32, walks, 3, Y, NULL), ULAM_OK);
    for (int p = 0; p < 6; p++) sum += Y[p];
    double se = sqrt(0.6 / 0.16 / (double)walks);
    print_message("furnace importance: sum %.5f +- %.2g, exact 2.5\n", sum, se);
    assert_close(sum, 2.5, 4 * se);
    assert_int_equal(ulam_rad_importance(t, &cam, 32, 32, 0, 3, Y, NULL), ULAM_OK);
    sum = 0.0;
    for (int p = 0; p < 6; p++) sum += Y[p];
    assert_close(sum, 1.0, 1e-12);
    ulam_tracer_free(t);
    ulam_scene_free(s);
}

/* Importance drives the refinement: a camera looking down at the Cornell floor puts a larger
 * share of the patches made on the floor than the area's importance does, at the same target,
 * and makes fewer in all (the walls it does not see matter only through their light). */
static void test_adapt_view(void **state)
{
    (void)state;
    ulam_scene *s = NULL, *da = NULL, *dv = NULL;
    ulam_tracer *t = must_load("examples/scenes/cornell_box.obj", &s);
    ulam_camera cam = {{278, 540, 280}, {0, -1, 0}, {0, 0, 1}, 35, 25};
    double *Y = malloc((size_t)s->npatches * sizeof *Y);
    assert_non_null(Y);
    assert_int_equal(ulam_rad_importance(t, &cam, 64, 64, 20000, 4, Y, NULL), ULAM_OK);
    ulam_rad_adapt_info ia = adapt(t, NULL, 0.12, 0, 1024, 100000, 9, &da);
    ulam_rad_adapt_info iv = adapt(t, Y, 0.12, 0, 1024, 100000, 9, &dv);
    assert_true(ia.met && iv.met);
    int64_t floor_face = -1, fa = 0, fv = 0;
    assert_int_equal(ulam_scene_find(s, "floor", &floor_face), ULAM_OK);
    floor_face = s->face[floor_face];
    for (int64_t p = 0; p < da->npatches; p++) fa += da->face[p] == floor_face;
    for (int64_t p = 0; p < dv->npatches; p++) fv += dv->face[p] == floor_face;
    print_message("floor patches: area importance %lld of %lld, the view's %lld of %lld\n", (long long)fa,
                  (long long)da->npatches, (long long)fv, (long long)dv->npatches);
    assert_true((double)fv / (double)dv->npatches > (double)fa / (double)da->npatches);
    assert_true(dv->npatches < da->npatches); /* the unseen walls need less */
    free(Y);
    ulam_tracer_free(t);
    ulam_scene_free(da), ulam_scene_free(dv), ulam_scene_free(s);
}

/* The non-diffuse MTL statements are noted once a keyword a material, with file and line; the
 * matte defaults (Ka, Ni, Ks 0, Ns 0, d 1, illum 2) are not. */
static void test_mtl_notes(void **state)
{
    (void)state;
    ulam_scene *s = NULL;
    ulam_mtl_note *notes = NULL;
    int64_t n = 0;
    assert_int_equal(ulam_scene_read_obj_notes("tests/data/rad/shiny.obj", &s, &notes, &n, NULL), ULAM_OK);
    const char *kw[5] = {"Ks", "Ns", "d", "illum", "map_Kd"};
    assert_int_equal(n, 5);
    for (int k = 0; k < 5; k++) {
        assert_string_equal(notes[k].keyword, kw[k]);
        assert_string_equal(notes[k].material, "glass");
        assert_int_equal(notes[k].line, 12 + k);
        assert_non_null(strstr(notes[k].file, "shiny.mtl"));
    }
    ulam_mtl_notes_free(notes, n);
    ulam_scene_free(s);
    assert_int_equal(ulam_scene_read_obj_notes("tests/data/rad/edge_lamp.obj", &s, &notes, &n, NULL), ULAM_OK);
    assert_int_equal(n, 0);
    assert_null(notes);
    ulam_scene_free(s);
}

/* Write a furnace cube into a new temporary directory: side scale, corner at off, each face
 * n x n quads (normals inward), Kd 0.5 and Ke 1 (B = H = 2 at every point and sensor inside);
 * path gets the OBJ's path (dir is removed by test_scene_rm). */
static void write_furnace(char dir[64], char path[96], int n, double scale, double off)
{
    FILE *f = test_scene_open(dir, path, "newmtl glow\nKd 0.5 0.5 0.5\nKe 1 1 1\n");
    fprintf(f, "usemtl glow\n");
    /* face k: fixed axis a at 0 or 1, spanned by axes b, c with b x c = e_a (inward at 0) */
    static const int ax[6][4] = {{1, 2, 0, 0}, {1, 2, 0, 1}, {0, 1, 2, 0}, {0, 1, 2, 1}, {2, 0, 1, 0}, {2, 0, 1, 1}};
    int v = 0;
    for (int k = 0; k < 6; k++) {
        int a = ax[k][0], b = ax[k][1], c = ax[k][2], side = ax[k][3];
        if (side) b = ax[k][2], c = ax[k][1]; /* the far face: reversed, so its normal points back in */
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
                for (int q = 0; q < 4; q++) {
                    double x[3];
                    x[a] = side, x[b] = (double)(i + du[q]) / n, x[c] = (double)(j + dv[q]) / n;
                    fprintf(f, "v %.17g %.17g %.17g\n", off + scale * x[0], off + scale * x[1], off + scale * x[2]);
                }
                fprintf(f, "f %d %d %d %d\n", v + 1, v + 2, v + 3, v + 4);
                v += 4;
            }
    }
    fclose(f);
}

/* Rewrite the material of write_furnace's scene (Kd and Ke lines). */
static void furnace_material(const char *dir, const char *mtl)
{
    char p[96];
    snprintf(p, sizeof p, "%s/scene.mtl", dir);
    FILE *f = fopen(p, "w");
    assert_non_null(f);
    fprintf(f, "newmtl glow\n%s\n", mtl);
    fclose(f);
}

/* Check H = 2 in every channel of a furnace answer, to 4 standard errors, the error bar nonzero
 * and below 2%. */
static void check_furnace(const ulam_rad_point *r, const char *what)
{
    print_message("%s: H %.5f +- %.2g, CI %.5f .. %.5f (patch %lld)\n", what, r->irradiance[0], r->irradiance_se[0],
                  r->run.ci95[0][0], r->run.ci95[0][1], (long long)r->patch);
    for (int c = 0; c < 3; c++) {
        assert_true(r->irradiance_se[c] > 0 && r->irradiance_se[c] < 0.02);
        assert_close(r->irradiance[c], 2.0, 4 * r->irradiance_se[c]);
        assert_true(r->run.ci95[c][0] < 2.0 && r->run.ci95[c][1] > 2.0);
    }
}

/* Points on shared edges and vertices read the continuous surface, not the mesh: a furnace of
 * 4 x 4 quads a face, points where coplanar patches meet, on the concave edges between faces,
 * at a corner, and a grid whose sensors sit on vertices (all read 0 or 0.665 before: a ray
 * from the point met the neighbouring patch at distance 0). */
static void test_point_on_edges(void **state)
{
    (void)state;
    char dir[64], path[96];
    write_furnace(dir, path, 4, 1.0, 0.0);
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load(path, &s);
    const double pts[6][3] = {{0.5, 0, 0.5}, {0.25, 0, 0.6}, {0.5, 0, 0}, {0, 0.5, 0.5}, {0, 0, 0}, {1, 1, 0.75}};
    for (int k = 0; k < 6; k++) {
        if (!test_case(k)) continue;
        ulam_rad_point r = query(t, pts[k], NULL, ULAM_RAD_NEXT_EVENT, 20000, 0, 70 + (uint64_t)k);
        check_furnace(&r, "furnace point on an edge or vertex");
        for (int c = 0; c < 3; c++) assert_close(r.radiosity[c], 2.0, 4 * r.radiosity_se[c] + 1e-12);
    }
    test_case_done();
    /* a 2 x 2 grid on the floor whose sensors sit on the mesh's vertices (0.25, 0.75) */
    ulam_rad_grid g = {.origin = {0, 0, 0}, .u = {1, 0, 0}, .v = {0, 0, 1}, .normal = {0, 1, 0}, .nu = 2, .nv = 2};
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.max_walks = 20000, o.exec.seed = 5, o.exec.threads = 2;
    ulam_rad_point out[4];
    assert_int_equal(ulam_rad_grid_solve(t, &o, &g, out, NULL), ULAM_OK);
    for (int k = 0; k < 4; k++) check_furnace(&out[k], "grid sensor on a vertex");
    ulam_tracer_free(t);
    ulam_scene_free(s);
    test_scene_rm(dir);
}

/* Radiosity is scale-free: the furnace (B = H = 2) of side 1e13, 4e18, 1e-12 and 1e-20 (and far
 * from the origin), at a patch and at points on a face and an edge; a sensor normal of 1e200
 * components; a sensor too far from the scene to be represented is refused with a message. */
static void test_scale(void **state)
{
    (void)state;
    const double scales[5][2] = {{1e13, 0}, {4e18, 0}, {1e-12, 0}, {1e-20, 0}, {1, 1e9}};
    for (int k = 0; k < 5; k++) {
        if (!test_case(k)) continue;
        char dir[64], path[96];
        write_furnace(dir, path, 2, scales[k][0], scales[k][1]);
        ulam_scene *s = NULL;
        ulam_tracer *t = must_load(path, &s);
        ulam_rad_opts o = ulam_rad_defaults();
        o.stop.max_walks = 20000, o.exec.seed = 80 + (uint64_t)k, o.exec.threads = 2, o.index = 0;
        ulam_rad_result pr = run_solver(t, &o);
        print_message("scale %g: patch B %.5f +- %.2g, CI %.5f .. %.5f\n", scales[k][0], pr.radiosity[0],
                      pr.std_error[0], pr.ci95[0][0], pr.ci95[0][1]);
        for (int c = 0; c < 3; c++) {
            assert_true(pr.std_error[c] > 0 && pr.std_error[c] < 0.02);
            assert_close(pr.radiosity[c], 2.0, 4 * pr.std_error[c]);
            assert_true(pr.ci95[c][0] < 2.0 && pr.ci95[c][1] > 2.0);
        }
        const double at[2][3] = {{0.3, 0, 0.3}, {0.3, 0, 0}};
        for (int q = 0; q < 2; q++) {
            double x[3];
            for (int d = 0; d < 3; d++) x[d] = scales[k][1] + scales[k][0] * at[q][d];
            ulam_rad_point r = query(t, x, NULL, ULAM_RAD_NEXT_EVENT, 20000, 0, 90 + (uint64_t)q);
            check_furnace(&r, "scaled furnace point");
        }
        ulam_tracer_free(t);
        ulam_scene_free(s);
        test_scene_rm(dir);
    }
    test_case_done();
    char dir[64], path[96];
    write_furnace(dir, path, 1, 1.0, 0.0);
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load(path, &s);
    double mid[3] = {0.5, 0.5, 0.5}, huge_n[3] = {1e200, 1e200, 0}, far[3] = {1e20, 0.5, 0.5}, n[3] = {1, 0, 0};
    ulam_rad_point r = query(t, mid, huge_n, ULAM_RAD_NEXT_EVENT, 20000, 0, 7);
    assert_close(r.n[0], sqrt(0.5), 1e-12);
    check_furnace(&r, "sensor with a normal of 1e200 components");
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.max_walks = 100;
    ulam_error err;
    assert_int_equal(ulam_rad_point_query(t, &o, far, n, &r, &err), ULAM_EINVAL);
    print_message("refused: %s\n", err.msg);
    assert_non_null(strstr(err.msg, "scene"));
    double back[3] = {-1, 0, 0}; /* a ray from there: -1, not Embree's abort */
    assert_int_equal(ulam_tracer_cast(t, far, back, NULL), -1);
    double near[3] = {1e5, 0.5, 0.5};
    int front = 1;
    assert_true(ulam_tracer_cast(t, near, back, &front) >= 0 && !front); /* the cube's outside: a back side */
    ulam_tracer_free(t);
    ulam_scene_free(s);
    test_scene_rm(dir);
}

/* Walks cut at max_steps: on a furnace of Kd 0.999 and Ke 0.001 (B = H = 1) walks of at most 100
 * steps see a tenth of the light; the interval must still hold the truth (it widens by the most
 * the cut can miss, ulam__point_tail), at a point and at a patch; uncut, it is as narrow as ever
 * (below 0.1 of B at 2000 walks of 10^6 steps). */
static void test_cut_interval(void **state)
{
    (void)state;
    char dir[64], path[96];
    write_furnace(dir, path, 1, 1.0, 0.0);
    furnace_material(dir, "Kd 0.999 0.999 0.999\nKe 0.001 0.001 0.001");
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load(path, &s);
    double x[3] = {0.3, 0, 0.4};
    for (int k = 0; k < 2; k++) {
        ulam_rad_opts o = ulam_rad_defaults();
        o.stop.max_walks = 2000, o.stop.max_steps = k ? 1000000 : 100, o.exec.seed = 11, o.exec.threads = 2;
        ulam_rad_point r;
        assert_int_equal(ulam_rad_point_query(t, &o, x, NULL, &r, NULL), ULAM_OK);
        o.index = 2;
        ulam_rad_result pr = run_solver(t, &o);
        print_message("max_steps %lld: point H %.4f, CI %.4f .. %.4f, cut %lld; patch B %.4f, CI %.4f .. %.4f, cut %lld\n",
                      (long long)o.stop.max_steps, r.irradiance[0], r.run.ci95[0][0], r.run.ci95[0][1],
                      (long long)r.run.cut, pr.radiosity[0], pr.ci95[0][0], pr.ci95[0][1], (long long)pr.cut);
        assert_true(k ? r.run.cut == 0 : r.run.cut > 1000);
        for (int c = 0; c < 3; c++) {
            assert_true(r.run.ci95[c][0] <= 1.0 && r.run.ci95[c][1] >= 1.0);
            assert_true(pr.ci95[c][0] <= 1.0 && pr.ci95[c][1] >= 1.0);
            if (k) assert_true(r.run.ci95[c][1] - r.run.ci95[c][0] < 0.2);
        }
    }
    ulam_tracer_free(t);
    ulam_scene_free(s);
    test_scene_rm(dir);
}

/* Reverse the vertex order of every face of write_furnace's scene (inside out). */
static void furnace_flip(const char *path)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[256], out[1 << 16] = "";
    size_t len = 0;
    while (fgets(line, sizeof line, f)) {
        int a, b, c, d;
        if (sscanf(line, "f %d %d %d %d", &a, &b, &c, &d) == 4) snprintf(line, sizeof line, "f %d %d %d %d\n", d, c, b, a);
        len += (size_t)snprintf(out + len, sizeof out - len, "%s", line);
        assert_true(len < sizeof out);
    }
    fclose(f);
    assert_non_null(f = fopen(path, "w"));
    fputs(out, f);
    fclose(f);
}

/* A scene that answers 0 says why (ulam_rad_scene_diagnose): the furnace with no Ke has no
 * emitter; turned inside out, its backs' rays land on backs and its fronts' leave; as built,
 * every front's ray lands on a front and every back's leaves. */
static void test_scene_diagnose(void **state)
{
    (void)state;
    char dir[64], path[96];
    write_furnace(dir, path, 1, 1.0, 0.0);
    for (int k = 0; k < 3; k++) {
        furnace_material(dir, k == 0 ? "Kd 0.5 0.5 0.5" : "Kd 0.5 0.5 0.5\nKe 1 1 1");
        if (k == 2) furnace_flip(path);
        ulam_scene *s = NULL;
        ulam_tracer *t = must_load(path, &s);
        ulam_rad_scene_diag d;
        assert_int_equal(ulam_rad_scene_diagnose(t, 1000, 3, &d), ULAM_OK);
        print_message("case %d: %lld emitters; fronts %lld %lld %lld, backs %lld %lld %lld, lamps %lld %lld %lld\n", k,
                      (long long)d.emitters, (long long)d.front[0], (long long)d.front[1], (long long)d.front[2],
                      (long long)d.back[0], (long long)d.back[1], (long long)d.back[2], (long long)d.lamp[0],
                      (long long)d.lamp[1], (long long)d.lamp[2]);
        assert_int_equal(d.emitters, k ? 6 : 0);
        assert_int_equal(d.front[0] + d.front[1] + d.front[2], 1000);
        assert_int_equal(d.back[0] + d.back[1] + d.back[2], 1000);
        if (k < 2) assert_true(d.front[0] == 1000 && d.back[2] == 1000);
        else assert_true(d.front[2] == 1000 && d.back[1] == 1000 && d.lamp[2] == d.lamp[0] + d.lamp[1] + d.lamp[2]);
        if (k == 2) { /* and the walks read exactly 0 */
            double x[3] = {0.5, 0, 0.5};
            ulam_rad_point r = query(t, x, NULL, ULAM_RAD_NEXT_EVENT, 2000, 0, 1);
            assert_true(r.irradiance[0] == 0 && r.irradiance_se[0] == 0);
        }
        ulam_tracer_free(t);
        ulam_scene_free(s);
    }
    assert_int_equal(ulam_rad_scene_diagnose(NULL, 10, 1, NULL), ULAM_EINVAL);
    test_scene_rm(dir);
}

/* A block stops inside once time is up or the run is interrupted (a block of 256 walks of 10^6
 * rays took minutes past --time 3): at a time limit already spent, the first block (which always
 * runs, so there is an estimate) keeps the walks it finished, one here, not all 256 (counts, not
 * seconds); a point and a patch solver on a furnace of Kd 0.99. */
static void test_block_stops_inside(void **state)
{
    (void)state;
    char dir[64], path[96];
    write_furnace(dir, path, 1, 1.0, 0.0);
    furnace_material(dir, "Kd 0.99 0.99 0.99\nKe 1 1 1");
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load(path, &s);
    double x[3] = {0.5, 0, 0.5};
    for (int k = 0; k < 2; k++) {
        ulam_rad_opts o = ulam_rad_defaults();
        o.stop.max_walks = 0, o.stop.max_seconds = 1e-12, o.exec.threads = 1, o.index = 1;
        ulam_rad_solver *sv = NULL;
        assert_int_equal(k ? ulam_rad_solver_alloc(t, &o, &sv, NULL) : ulam_rad_point_alloc(t, &o, x, NULL, &sv, NULL),
                         ULAM_OK);
        while (!ulam_rad_solver_done(sv)) assert_int_equal(ulam_rad_solver_iterate(sv), ULAM_OK);
        ulam_rad_result r;
        ulam_rad_solver_result(sv, &r);
        print_message("%s solver at a spent time limit: %lld walks, %lld rays\n", k ? "patch" : "point",
                      (long long)r.walks, (long long)r.rays);
        assert_true(r.walks >= 1 && r.walks < 256);
        ulam_rad_solver_free(sv);
    }
    ulam_tracer_free(t);
    ulam_scene_free(s);
    test_scene_rm(dir);
}

/* ulam_render_hdr: one centre ray a pixel, flat, is ulam_render's picture byte for byte; smooth
 * shading of a constant radiosity is that constant at every pixel (corner means of equal values),
 * jittered or not; a linear gradient over a subdivided face is interpolated (between the patch
 * values, not a staircase). */
static void test_render_hdr(void **state)
{
    (void)state;
    ulam_scene *s0 = NULL, *s = NULL;
    ulam_tracer *t0 = must_load("tests/data/rad/furnace_half.obj", &s0);
    assert_int_equal(ulam_scene_subdivide(s0, 0.25, &s), ULAM_OK);
    ulam_tracer *t = must_tracer_of(s);
    int64_t n = s->npatches;
    double *B = malloc((size_t)(3 * n) * sizeof *B);
    ulam_camera cam = {.eye = {0.5, 0.5, 0.9}, .dir = {0, 0, -1}, .up = {0, 1, 0}, .focal = 1, .film = 1.5};
    enum { W = 24, H = 16 };
    float hdr[3 * W * H];
    unsigned char a[3 * W * H], b[3 * W * H];
    for (int64_t p = 0; p < n; p++) {
        double c[3];
        ulam_scene_centroid(s, p, c);
        for (int k = 0; k < 3; k++) B[3 * p + k] = 1.0 + c[0]; /* a gradient in x */
    }
    assert_int_equal(ulam_render(t, B, &cam, W, H, 0.5, a, NULL), ULAM_OK);
    assert_int_equal(ulam_render_hdr(t, B, &cam, W, H, 1, 0, 1, 0.5, hdr, b, NULL), ULAM_OK);
    assert_memory_equal(a, b, sizeof a);
    /* smooth: on the floor (the picture's lower middle) values lie between neighbours, and vary
     * continuously: no jump between adjacent pixels as large as a patch step (0.25) */
    assert_int_equal(ulam_render_hdr(t, B, &cam, W, H, 4, 1, 1, 0.5, hdr, b, NULL), ULAM_OK);
    for (int y = 0; y < H; y++)
        for (int x = 0; x + 1 < W; x++) assert_true(fabs(hdr[3 * (y * W + x + 1)] - hdr[3 * (y * W + x)]) < 0.2);
    for (int64_t p = 0; p < n; p++)
        for (int k = 0; k < 3; k++) B[3 * p + k] = 2.0;
    assert_int_equal(ulam_render_hdr(t, B, &cam, W, H, 3, 1, 7, 0, hdr, NULL, NULL), ULAM_OK);
    for (int k = 0; k < 3 * W * H; k++) assert_close(hdr[k], 2.0, 1e-6);
    assert_int_equal(ulam_render_hdr(t, B, &cam, W, H, 0, 1, 7, 0, hdr, NULL, NULL), ULAM_EINVAL);
    B[5] = NAN;
    assert_int_equal(ulam_render_hdr(t, B, &cam, W, H, 1, 1, 7, 0, hdr, NULL, NULL), ULAM_ENONFINITE);
    free(B);
    ulam_tracer_free(t), ulam_tracer_free(t0);
    ulam_scene_free(s), ulam_scene_free(s0);
}

/* The Radiance .hdr beside the PFM: its header, and every pixel decoded from RGBE within the
 * format's 8-bit mantissa (1/128 of the pixel's largest channel) of the linear value; black
 * stays black. */
static void test_hdr_write(void **state)
{
    (void)state;
    enum { W = 5, H = 3 };
    float rgb[3 * W * H];
    for (int k = 0; k < 3 * W * H; k++) rgb[k] = (float)(k % 7 == 0 ? 0.0 : pow(10.0, (k % 11) - 5.0) * (1 + k % 3));
    char path[] = "/tmp/ulam_hdr_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(ulam_hdr_write(path, W, H, rgb), ULAM_OK);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char line[128];
    assert_non_null(fgets(line, sizeof line, f));
    assert_string_equal(line, "#?RADIANCE\n");
    int w = 0, h = 0, blank = 0;
    while (fgets(line, sizeof line, f) && !(blank && sscanf(line, "-Y %d +X %d", &h, &w) == 2)) blank = line[0] == '\n';
    assert_int_equal(w, W);
    assert_int_equal(h, H);
    for (int i = 0; i < W * H; i++) {
        unsigned char b[4];
        assert_int_equal(fread(b, 1, 4, f), 4);
        float *c = rgb + 3 * i;
        double big = fmax(c[0], fmax(c[1], c[2]));
        for (int k = 0; k < 3; k++) {
            double v = b[3] ? ldexp(b[k] + 0.5, b[3] - 136) : 0.0;
            assert_close(v, c[k], big / 128 + 1e-300);
        }
    }
    assert_int_equal(fgetc(f), EOF);
    fclose(f);
    remove(path);
    assert_int_equal(ulam_hdr_write(path, 0, H, rgb), ULAM_EINVAL);
}

/* Shooting's --rel-err takes src/stop.c's rule (a certified range of one particle's tally at the
 * patch, at least 1000 particles), not the standard error alone: 50 seeds at rel_err 0.03 on the
 * edge lamp's wall (exact 0.5 F(C-14)), every run met (a range the rule's walk count covers),
 * at least 43 of 50 intervals (95%) covering (P(Binomial(50, 0.95) < 43) < 0.01).  Light sampling
 * alone there (the lamp shares the wall's edge: no bound on 1 / r^2) refuses rel_err. */
static void test_shoot_rel_err(void **state)
{
    (void)state;
    ulam_scene *s = NULL;
    ulam_tracer *t = must_load("tests/data/rad/edge_lamp.obj", &s);
    double exact = 0.5 * ulam_ff_perpendicular_rectangles(1, 1, 1);
    int inside = 0;
    for (uint64_t seed = 0; seed < 50; seed++) {
        ulam_rad_opts o = ulam_rad_defaults();
        o.mode = ULAM_FORWARD, o.estimator = ULAM_RAD_COLLISION, o.index = 1, o.stop.rel_err = 0.03, o.stop.max_walks = 0;
        o.exec.seed = 300 + seed, o.exec.threads = 2;
        ulam_rad_result r = run_solver(t, &o);
        assert_true(r.rel_err_met && r.walks >= 1000 && (double)r.walks >= r.min_walks && r.min_walks > 1000);
        assert_true(r.std_error[0] <= 0.03 * r.radiosity[0]);
        inside += fabs(r.radiosity[0] - exact) <= 1.96 * r.std_error[0];
    }
    print_message("shooting at rel_err 0.03: %d of 50 intervals cover\n", inside);
    assert_true(inside >= 43);
    ulam_rad_opts o = ulam_rad_defaults();
    o.estimator = ULAM_RAD_NEXT_EVENT_LIGHT, o.index = 1, o.stop.rel_err = 0.03;
    ulam_rad_solver *sv = NULL;
    ulam_error err;
    assert_int_equal(ulam_rad_solver_alloc(t, &o, &sv, &err), ULAM_EINVAL);
    assert_null(sv);
    assert_non_null(strstr(err.msg, "certified bound"));
    o.stop.rel_err = 0, o.stop.max_walks = 1000; /* a walk budget still runs */
    assert_int_equal(ulam_rad_solver_alloc(t, &o, &sv, &err), ULAM_OK);
    ulam_rad_solver_free(sv);
    ulam_tracer_free(t);
    ulam_scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_parallel), cmocka_unit_test(test_point_perpendicular),
        cmocka_unit_test(test_point_furnace),  cmocka_unit_test(test_point_coverage),
        cmocka_unit_test(test_point_refused),  cmocka_unit_test(test_grid),
        cmocka_unit_test(test_grid_interval),  cmocka_unit_test(test_grid_shared_solver),
        cmocka_unit_test(test_mesh_error_flags), cmocka_unit_test(test_mesh_converges),
        cmocka_unit_test(test_mtl_notes),        cmocka_unit_test(test_render_hdr),
        cmocka_unit_test(test_shoot_rel_err),    cmocka_unit_test(test_adapt_furnace),
        cmocka_unit_test(test_adapt_cornell),    cmocka_unit_test(test_importance_furnace),
        cmocka_unit_test(test_adapt_view),       cmocka_unit_test(test_hdr_write),
        cmocka_unit_test(test_point_on_edges),   cmocka_unit_test(test_scale),
        cmocka_unit_test(test_cut_interval),     cmocka_unit_test(test_scene_diagnose),
        cmocka_unit_test(test_block_stops_inside), cmocka_unit_test(test_points_solve),
    };
    return test_run(tests);
}
