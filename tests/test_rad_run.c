/* A radiosity run through its library object (include/ulam_radiosity_run.h), as a front end other
 * than the CLI (Python) drives it: the furnace cube (B = E / (1 - rho) = 2 on every face) answered
 * at a patch and at points, the report and the CSV rows written into the caller's streams, and
 * the refusals (a patch the scene lacks, a run past --max-mem) said on the caller's log with a
 * status, nothing printed without a log. */
#include "testutil.h"
#include "ulam_radiosity_run.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A memory stream's text after f is closed. */
typedef struct {
    char *buf;
    size_t len;
    FILE *f;
} stream;

static void open_stream(stream *s)
{
    s->buf = NULL, s->len = 0;
    s->f = open_memstream(&s->buf, &s->len);
    assert_non_null(s->f);
}

/* The furnace cube's options with n walks, one thread, a log stream. */
static ulam_rad_run_opts cube(int64_t n, FILE *log)
{
    ulam_rad_run_opts o = ulam_rad_run_defaults();
    o.scene = "examples/scenes/cube.obj", o.log = log;
    o.o.stop.max_walks = n, o.o.exec.threads = 1;
    return o;
}

/* Gathering at patch 1 by absorption: exactly 2 with zero variance; the JSON names it, the log
 * stays empty. */
static void test_patch_json(void **state)
{
    (void)state;
    stream log, out;
    open_stream(&log), open_stream(&out);
    ulam_rad_run_opts o = cube(1000, log.f);
    o.patch = "1", o.json = 1, o.est = 1, o.o.estimator = ULAM_RAD_ABSORPTION;
    ulam_rad_run *r = NULL;
    int interrupted = -1;
    assert_int_equal(ulam_rad_run_alloc(&o, &r), ULAM_OK);
    assert_int_equal(ulam_rad_run_solve(r, &interrupted), ULAM_OK);
    assert_int_equal(interrupted, 0);
    ulam_rad_run_print(r, out.f);
    ulam_rad_run_free(r);
    fclose(out.f), fclose(log.f);
    assert_non_null(strstr(out.buf, "\"radiosity\": [2, 2, 2]"));
    assert_non_null(strstr(out.buf, "\"stderr\": [0, 0, 0]"));
    assert_non_null(strstr(out.buf, "\"walks\": 1000,"));
    assert_int_equal(log.len, 0);
    free(out.buf), free(log.buf);
}

/* A 2 x 2 sensor grid on the floor facing up: every sensor's irradiance within 4 standard errors
 * of 2, and the CSV a header and one row a sensor. */
static void test_grid_csv(void **state)
{
    (void)state;
    stream out, csv;
    open_stream(&out), open_stream(&csv);
    ulam_rad_run_opts o = cube(400, NULL);
    o.grid = 1, o.out = "grid.csv", o.o.estimator = ULAM_RAD_NEXT_EVENT;
    o.g = (ulam_rad_grid){.origin = {0.1, 0.5, 0.1}, .u = {0.8, 0, 0}, .v = {0, 0, 0.8}, .normal = {0, 1, 0}, .nu = 2, .nv = 2};
    ulam_rad_run *r = NULL;
    int interrupted = -1;
    assert_int_equal(ulam_rad_run_alloc(&o, &r), ULAM_OK);
    assert_int_equal(ulam_rad_run_solve(r, &interrupted), ULAM_OK);
    assert_int_equal(ulam_rad_run_write(r, ULAM_RAD_RUN_CSV, csv.f), ULAM_OK);
    ulam_rad_run_print(r, out.f);
    ulam_rad_run_free(r);
    fclose(out.f), fclose(csv.f);
    int lines = 0;
    for (size_t k = 0; k < csv.len; k++) lines += csv.buf[k] == '\n';
    assert_int_equal(lines, 5);
    char *row = strchr(csv.buf, '\n') + 1;
    for (int k = 0; k < 4; k++, row = strchr(row, '\n') + 1) { /* i,j,x,y,z,R,G,B,R_se,... */
        double v[11];
        assert_int_equal(sscanf(row, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3], &v[4],
                                &v[5], &v[6], &v[7], &v[8], &v[9], &v[10]), 11);
        assert_true(fabs(v[5] - 2.0) < 4 * v[8] + 1e-12);
    }
    assert_non_null(strstr(out.buf, "grid csv     grid.csv\n"));
    free(out.buf), free(csv.buf);
}

/* Refusals: a patch past the scene's six is a usage failure and a run whose form factors pass
 * --max-mem a memory limit, each said on the log; without a log, the same statuses and no line. */
static void test_refusals(void **state)
{
    (void)state;
    for (int quiet = 0; quiet < 2; quiet++) {
        stream log;
        open_stream(&log);
        ulam_rad_run_opts o = cube(100, quiet ? NULL : log.f);
        o.patch = "7";
        ulam_rad_run *r = NULL;
        assert_int_equal(ulam_rad_run_alloc(&o, &r), ULAM_RAD_RUN_USAGE);
        ulam_rad_run_free(r);
        o = cube(100, quiet ? NULL : log.f);
        o.direct = 1, o.max_mem = 10;
        r = NULL;
        assert_int_equal(ulam_rad_run_alloc(&o, &r), ULAM_EMEMLIMIT);
        ulam_rad_run_free(r);
        fclose(log.f);
        if (quiet) assert_int_equal(log.len, 0);
        else assert_non_null(strstr(log.buf, "--patch 7 is out of range 1..6")), assert_non_null(strstr(log.buf, "memory limit"));
        free(log.buf);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_patch_json),
        cmocka_unit_test(test_grid_csv),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
