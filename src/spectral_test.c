/* A unit test of src/spectral.c built with the module (tests/meson.build's module units): power
 * iteration on a scaled operator diag(left) |A| diag(right) (ulam__spectral_power), which no
 * public call takes with scalings.  The unscaled radius is tested through ulam_guard_check in
 * tests/test_spectral.c. */
#include "spectral.h"
#include "testutil.h"

/* diag(l) |S| and |S| diag(r) for the swap S = (0 1; 1 0): radius sqrt(l0 l1), sqrt(r0 r1),
 * bracketed by the bounds and converged to within 1e-3 (relative). */
static void test_power_scaled(void **state)
{
    (void)state;
    int32_t i[2] = {0, 1}, j[2] = {1, 0};
    double x[2] = {-1, 1}, l[2] = {0.5, 2.88}, r[2] = {3.0, 0.12};
    ulam_csr *A = NULL;
    assert_int_equal(ulam_csr_from_triplets(2, 2, 2, i, j, x, &A), ULAM_OK);
    const double *left[2] = {l, NULL}, *right[2] = {NULL, r}, exact[2] = {1.2, 0.6};
    for (int k = 0; k < 2; k++) {
        ulam_power p;
        assert_int_equal(ulam__spectral_power(A, left[k], right[k], NULL, &p, NULL), ULAM_OK);
        assert_true(p.lower <= exact[k] * (1 + 1e-12) && exact[k] <= p.upper * (1 + 1e-12));
        assert_close(p.rho, exact[k], 1e-3 * exact[k]);
        assert_true(p.converged);
    }
    ulam_power_opts po = ulam_power_defaults();
    po.tol = -1;
    ulam_power p;
    ulam_error err;
    assert_int_equal(ulam__spectral_power(A, NULL, NULL, &po, &p, &err), ULAM_EINVAL); /* a bad tol */
    assert_int_equal(ulam__spectral_power(NULL, NULL, NULL, NULL, &p, &err), ULAM_EINVAL);
    ulam_csr_free(A);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_power_scaled)};
    return test_run(tests);
}
