/* A unit test of src/util.c built with the module (tests/meson.build's module units): the big
 * arrays' allocator (ulam__alloc_big), which the library's matrices and pushes use and no public
 * call returns. */
#include "internal.h"
#include "testutil.h"

/* 64-byte aligned below 2 MiB, 2 MiB aligned from 2 MiB on (the whole block writable), NULL when
 * n sz overflows. */
static void test_alloc_big(void **state)
{
    (void)state;
    char *a = ulam__alloc_big(1000, 1), *b = ulam__alloc_big((size_t)1 << 19, 8), *c = ulam__alloc_big(0, 8);
    assert_non_null(a), assert_non_null(b), assert_non_null(c);
    assert_int_equal((uintptr_t)a % 64, 0);
    assert_int_equal((uintptr_t)b % ((uintptr_t)2 << 20), 0);
    memset(a, 1, 1000), memset(b, 1, (size_t)4 << 20);
    assert_null(ulam__alloc_big(SIZE_MAX / 2, 4));
    free(a), free(b), free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_alloc_big)};
    return test_run(tests);
}
