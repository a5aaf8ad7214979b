/* The mesh error adaptive subdivision measures (src/radiosity/adapt.c) against the true one: a
 * lamp over a floor quad and a floor triangle (tests/data/rad/mesh_linear.obj), the floor's
 * radiosity 0.5 F(x) with F the form factor to the lamp by Lambert's contour integral, its RMS
 * about its mean over each patch by a fine midpoint rule: the true mesh error sum_p A_p RMS_p /
 * sum_p A_p mean_p (area importance; the lamp's emission, exact on any mesh, in neither).  The
 * quadrature points alone (centroid, half way to the vertices) see 1/1.29 of a linear field's RMS
 * on a square and 1/1.15 on a triangle, and the lamp's emission in the denominator made it smaller
 * still (printed 0.0016 against a true 0.106 before; 0.1067 after). */
#include "testutil.h"
#include "ulam_radiosity.h"

/* The form factor from a point x with unit normal n to polygon p[0..k) (Lambert's contour integral). */
static double contour(const double x[3], const double n[3], const double p[][3], int k)
{
    double F = 0.0;
    for (int i = 0; i < k; i++) {
        double a[3], b[3], c[3];
        for (int j = 0; j < 3; j++) a[j] = p[i][j] - x[j], b[j] = p[(i + 1) % k][j] - x[j];
        c[0] = a[1] * b[2] - a[2] * b[1], c[1] = a[2] * b[0] - a[0] * b[2], c[2] = a[0] * b[1] - a[1] * b[0];
        double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        double cosg = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
        F += acos(fmax(-1.0, fmin(1.0, cosg))) * (n[0] * c[0] + n[1] * c[1] + n[2] * c[2]) / lc;
    }
    return fabs(F) / (2 * M_PI);
}

static const double lamp[4][3] = {{0, 3, 0}, {1, 3, 0}, {1, 3, 1}, {0, 3, 1}};

/* B on the floor at (x, z). */
static double floor_B(double x, double z)
{
    double p[3] = {x, 0, z}, n[3] = {0, 1, 0};
    return 0.5 * contour(p, n, lamp, 4);
}

/* The true mesh error of the two floor patches: sum A RMS / sum A mean, by q x q midpoint rules. */
static double true_error(int q)
{
    double num = 0.0, den = 0.0;
    { /* the quad [1, 2] x [0, 1], area 1 */
        double s = 0.0, s2 = 0.0;
        for (int i = 0; i < q; i++)
            for (int j = 0; j < q; j++) {
                double b = floor_B(1 + (i + 0.5) / q, (j + 0.5) / q);
                s += b, s2 += b * b;
            }
        double m = s / ((double)q * q);
        num += sqrt(fmax(0.0, s2 / ((double)q * q) - m * m)), den += m;
    }
    { /* the triangle (-0.5, 0), (-1.5, 0), (-1, 1): area 0.5, q^2 equal sub-triangles' centroids */
        double a[2] = {-0.5, 0}, e1[2] = {-1, 0}, e2[2] = {-0.5, 1}, s = 0.0, s2 = 0.0;
        int cnt = 0;
        for (int i = 0; i < q; i++)
            for (int j = 0; i + j < q; j++)
                for (int down = 0; down < 2 && !(down && i + j > q - 2); down++) {
                    double u = (i + (down ? 2.0 : 1.0) / 3.0) / q, w = (j + (down ? 2.0 : 1.0) / 3.0) / q;
                    double b = floor_B(a[0] + u * e1[0] + w * e2[0], a[1] + u * e1[1] + w * e2[1]);
                    s += b, s2 += b * b, cnt++;
                }
        double m = s / cnt;
        num += 0.5 * sqrt(fmax(0.0, s2 / cnt - m * m)), den += 0.5 * m;
    }
    return num / den;
}

/* The measured mesh error of the unsplit mesh is within 10% of the true one. */
static void test_mesh_error_true(void **state)
{
    (void)state;
    ulam_scene *s = NULL, *out = NULL;
    ulam_error err;
    assert_int_equal(ulam_scene_read_obj(src_path("tests/data/rad/mesh_linear.obj"), &s, &err), ULAM_OK);
    ulam_tracer *t = NULL;
    assert_int_equal(ulam_tracer_alloc(s, &t, NULL), ULAM_OK);
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.rel_err = 0.005, o.stop.max_walks = 1000000, o.exec.seed = 3, o.exec.threads = 2;
    ulam_rad_adapt_info in;
    int st = ulam_rad_adapt(t, &o, NULL, 10.0, 100, &out, &in, &err);
    if (st) print_error("%s\n", err.msg);
    assert_int_equal(st, ULAM_OK);
    double truth = true_error(400);
    print_message("mesh error measured %.5f, true %.5f (ratio %.3f); %lld points, %lld walks\n", in.error0, truth,
                  in.error0 / truth, (long long)in.points, (long long)in.walks);
    assert_true(in.met && in.splits == 0);
    assert_true(fabs(in.error0 / truth - 1.0) < 0.10);
    ulam_tracer_free(t), ulam_scene_free(out), ulam_scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_mesh_error_true)};
    return test_run(tests);
}
