/* A unit test of src/dynload.c built with the module (tests/meson.build's module units): the
 * loader of the optional libraries, a private piece (the public calls that use it are tested in
 * tests/test_direct.c, tests/test_spectral.c).  It includes dynload.h, its module's private
 * header, beside it; the tests in tests/ include public headers only. */
#include "dynload.h"
#include "testutil.h"

/* The optional libraries are opened on first use (src/dynload.c): a library that loads fills its
 * table (libm's cos through it equals cos); one that does not, or lacks a symbol, fails with
 * ULAM_EIO and a message naming it, what it is for and why; the real rows load and solve. */
static void test_dynload(void **state)
{
    (void)state;
    struct {
        double (*cos)(double);
        double (*sqrt)(double);
    } api = {0};
    char why[320];
    const char *const libm[] = {"libulam-absent.so.9", "libm.so.6", NULL}, *const syms[] = {"cos", "sqrt", NULL};
    assert_int_equal(ulam__dl_open(libm, "a test", syms, &api, why, sizeof why), ULAM_OK);
    assert_true(api.cos && api.sqrt && api.cos(0.5) == cos(0.5) && api.sqrt(2.0) == sqrt(2.0));
    const char *const none[] = {"libulam-absent.so.9", NULL};
    assert_int_equal(ulam__dl_open(none, "a test", syms, &api, why, sizeof why), ULAM_EIO);
    assert_non_null(strstr(why, "libulam-absent.so.9 for a test (dlopen: "));
    const char *const nosym[] = {"libm.so.6", NULL}, *const bad[] = {"cos", "ulam_no_such_symbol", NULL};
    assert_int_equal(ulam__dl_open(nosym, "a test", bad, &api, why, sizeof why), ULAM_EIO);
    assert_string_equal(why, "libm.so.6 for a test (it has no ulam_no_such_symbol)");
    ulam_error err;
    assert_non_null(ulam__lapacke(&err));
    assert_non_null(ulam__arpack(&err));
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_dynload)};
    return test_run(tests);
}
