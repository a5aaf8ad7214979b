/* A walk result as JSON and a walk run's report (include/ulam_report.h), and the reference solve
 * (include/ulam_reference.h): the members ulam solve --json prints, written to the caller's stream,
 * null for what is not finite; the report's lines as ulam solve prints them; the reference LU as
 * chosen, and GMRES when the LU would pass the memory limit. */
#include "testutil.h"
#include "ulam_reference.h"
#include "ulam_report.h"

/* Numbers, strings and the result's members, in order, with null for NaN and infinities. */
static void test_json(void **state)
{
    (void)state;
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    ulam_json_number(f, "a", 0.1, 0);
    ulam_json_number(f, "b", NAN, 0);
    ulam_json_string(f, "c", "q\"\\\n", 1);
    ulam_json_number(f, NULL, INFINITY, 1);
    fclose(f); /* buf now holds what was written */
    char *s = buf;
    assert_string_equal(s, "\"a\": 0.10000000000000001, \"b\": null, \"c\": \"q\\\"\\\\\\u000a\"null");
    free(s);

    ulam_walk_opts o = ulam_walk_defaults();
    o.exec.seed = 7;
    ulam_walk_result r = {.estimate = 1.875, .std_error = 0.01, .ci95 = {1.85, 1.9}, .variance_finite = 1,
                          .walks = 2000, .steps = 6000, .threads = 1, .seconds = 0.5, .tail_bound = INFINITY};
    buf = NULL, f = open_memstream(&buf, &len);
    ulam_walk_result_json(f, &o, &r, NULL);
    fclose(f);
    s = buf;
    const char *keys[] = {"\"estimate\": ", "\"stderr\": ", "\"ci95\": ", "\"variance_finite\": ", "\"kernel_alpha\": ",
                          "\"walks\": 2000, ", "\"method\": \"walks\", \"mode\": \"adjoint\", \"estimator\": \"collision\", ",
                          "\"seed\": 7, \"threads\": 1, "};
    const char *at = s;
    for (size_t k = 0; k < sizeof keys / sizeof *keys; k++) { /* each present, in this order */
        const char *p = strstr(at, keys[k]);
        assert_non_null(p);
        at = p;
    }
    assert_null(strstr(s, "rho_abs")); /* no guard given */
    assert_null(strstr(s, "rel_err_met")); /* no target */
    assert_true(strtod(strstr(s, "\"estimate\": ") + 12, NULL) == r.estimate); /* %.17g reads back exactly */
    assert_int_equal(s[strlen(s) - 2], ','); /* every member followed by ", ": the caller closes */
    assert_non_null(strstr(s, "\"tail_bound\": null, ")); /* not finite: null */
    assert_non_null(strstr(s, "\"ci95\": [1.8500000000000001, 1.8999999999999999], "));
    free(s);
}

/* What auto chose, by hand: one candidate chosen; brief, verbose and JSON say so. */
static void test_choice(void **state)
{
    (void)state;
    static ulam_choice ch; /* large: not on the stack */
    memset(&ch, 0, sizeof ch);
    ch.walks.ncand = 1, ch.walks.chosen = 0, ch.walks.closest = 0, ch.walks.stages = 1, ch.walks.pilot_work = 30;
    ch.walks.reused_work = 10;
    ulam_auto_candidate *c = &ch.walks.cand[0];
    c->mode = ULAM_ADJOINT, c->estimator = ULAM_EXPECTED, c->kernel_alpha = 1, c->certified = 1;
    c->state = ULAM_AUTO_CHOSEN, c->pilot_walks = 128, c->predicted_work = 60, c->hat.rho = 0.5, c->hat.upper = 0.6;
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    ulam_choice_fprint(f, &ch, 0, ULAM_REPORT_BRIEF);
    fclose(f);
    assert_string_equal(buf, "auto            chose it among 1 candidates by predicted cost (--verbose lists them)\n");
    free(buf);
    f = open_memstream(&buf, &len);
    ulam_choice_fprint(f, &ch, 0, ULAM_REPORT_VERBOSE);
    fclose(f);
    assert_non_null(strstr(buf, "the pilots' overhead is 22.2% of the predicted work")); /* (30 - 10) / (20 + 10 + 60) */
    assert_non_null(strstr(buf, "  * adjoint  expected   analog     alpha 1   rho(M^) 0.5 "));
    free(buf);
    f = open_memstream(&buf, &len);
    ulam_choice_fprint(f, &ch, 0, ULAM_REPORT_JSON);
    fclose(f);
    const char *head = "\"auto\": {\"chosen\": 1, \"closest\": 1, \"stages\": 1, "; /* 1-based */
    assert_int_equal(strncmp(buf, head, strlen(head)), 0);
    assert_non_null(strstr(buf, "\"pilot_share\": 0.22222222222222221, "));
    assert_non_null(strstr(buf, "\"state\": \"chosen\", "));
    assert_string_equal(buf + strlen(buf) - 4, "]}, ");
    free(buf);
}

/* The reference solve: dense LU on a small M (auto), GMRES past a tiny memory limit, the limit
 * refused without the fallback. */
static void test_reference(void **state)
{
    (void)state;
    int32_t ti[2] = {0, 1}, tj[2] = {1, 0}; /* M = [0 1/2; 1/4 0], b = 1: x = (12/7, 10/7) */
    double tx[2] = {0.5, 0.25}, b[2] = {1, 1}, x[2], want[2] = {12.0 / 7, 10.0 / 7};
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(2, 2, 2, ti, tj, tx, &M), ULAM_OK);
    ulam_direct_info info;
    ulam_error err;
    const char *how = NULL;
    ulam_reference_info plan;
    assert_int_equal(ulam_reference_plan(M, -1, 1, &plan, &err), ULAM_OK); /* n = 2: dense */
    assert_true(!plan.sparse && plan.bytes == (double)ulam_direct_bytes(2) && plan.flops == 2.0 / 3.0 * 8);
    assert_int_equal(ulam_reference_plan(M, 1, 0, &plan, &err), ULAM_OK);
    assert_true(plan.sparse && isnan(plan.bytes));
    assert_int_equal(ulam_reference_plan(M, 1, 0, NULL, &err), ULAM_EINVAL);
    assert_int_equal(ulam_reference_solve(M, b, -1, (size_t)1 << 30, 1, x, &info, &how, &err), ULAM_OK);
    assert_string_equal(how, "dense LU");
    for (int i = 0; i < 2; i++) assert_true(fabs(x[i] - want[i]) < 1e-14);
    assert_int_equal(ulam_reference_solve(M, b, 0, 16, 0, x, &info, &how, &err), ULAM_EMEMLIMIT);
    assert_int_equal(ulam_reference_solve(M, b, 0, 16, 1, x, &info, &how, &err), ULAM_OK);
    assert_string_equal(how, "GMRES");
    for (int i = 0; i < 2; i++) assert_true(fabs(x[i] - want[i]) < 1e-11);
    assert_true(info.residual <= 1e-12);
    assert_int_equal(ulam_reference_solve(NULL, b, 0, 16, 1, x, &info, &how, &err), ULAM_EINVAL);
    ulam_csr_free(M);
}

/* What a writer wrote: the string of its last call (freed by the next, and at the end). */
typedef struct {
    char *buf;
    size_t len;
} sink;

/* Write p in format to k, and return what was written. */
static const char *walk_report_text(sink *k, const ulam_walk_report *p, int format)
{
    free(k->buf);
    k->buf = NULL;
    FILE *f = open_memstream(&k->buf, &k->len);
    ulam_walk_report_fprint(f, p, format);
    fclose(f);
    return k->buf;
}

/* Nonzero when s starts with prefix. */
static int starts(const char *s, const char *prefix)
{
    return !strncmp(s, prefix, strlen(prefix));
}

/* A walk run's report by hand: the quiet answer line, the brief block, PageRank's line, the
 * --check line, the JSON object and the first round's warnings, each as ulam solve prints it. */
static void test_walk_report(void **state)
{
    (void)state;
    ulam_walk_opts o = ulam_walk_defaults();
    o.query.index = 2, o.exec.seed = 7, o.stop.rel_err = 0.01, o.stop.max_walks = 0;
    ulam_walk_result r = {.estimate = 1.875, .std_error = 0.01, .ci95 = {1.85, 1.9}, .variance_finite = 1,
                          .walks = 2000, .steps = 6000, .threads = 1, .seconds = 0.5, .tail_bound = INFINITY,
                          .score_bound = INFINITY, .cut_bound = 0, .rel_err_met = 0};
    ulam_walk_report p = {.opts = &o, .result = &r, .n = 10, .node_base = 1, .total_seconds = 0.75,
                          .check = 1, .direct = 1.87, .direct_seconds = 0.5, .direct_method = "dense LU",
                          .prefix = "ulam: m.mtx: "};
    sink k = {0};
    const char *s = walk_report_text(&k, &p, ULAM_REPORT_QUIET);
    assert_string_equal(s, "x[3]            1.875 +- 0.01 (95% CI 1.85 .. 1.9)\n");
    s = walk_report_text(&k, &p, ULAM_REPORT_BRIEF);
    assert_string_equal(s, "x[3]            1.875 +- 0.01 (95% CI 1.85 .. 1.9)\n"
                           "method          adjoint random walks, collision estimator (walks start at the unknown)\n"
                           "walks           2000 (mean length 3 steps)\n"
                           "seconds         0.5 walking on 1 threads; 0.75 in all (inputs, guards, set-up)\n"
                           "rel-err         NOT met (target 0.01; no bound on a single score: no walk count can certify it)\n");
    s = walk_report_text(&k, &p, ULAM_REPORT_CHECK);
    assert_string_equal(s, "direct          1.87 (dense LU, 0.5 s), z = 0.500\n");
    s = walk_report_text(&k, &p, ULAM_REPORT_WARN);
    assert_string_equal(s, "ulam: m.mtx: warning: --rel-err 0.01: no bound on a single walk's score holds (weights can "
                           "grow without bound, or the walk's length tail is not certified): the rule cannot be met; the "
                           "run ends by --walks or --time\n");
    s = walk_report_text(&k, &p, ULAM_REPORT_JSON);
    assert_true(starts(s, "{\"index\": 3, \"estimate\": 1.875, "));
    const char *key = "\"direct_method\": \"dense LU\", \"z\": ";
    assert_non_null(strstr(s, key));
    assert_true(fabs(strtod(strstr(s, key) + strlen(key), NULL) - 0.5) < 1e-9); /* (1.875 - 1.87) / 0.01 */
    assert_null(strstr(s, "quantity")); /* x: no name */
    assert_string_equal(s + strlen(s) - 22, "\"interrupted\": false}\n");
    p.answer_name = "pi", r.interrupted = 1; /* PageRank's pi: named, with its line (not when quiet) */
    s = walk_report_text(&k, &p, ULAM_REPORT_BRIEF);
    assert_true(starts(s, "pi[3]           1.875 +- 0.01 (95% CI 1.85 .. 1.9)  [INTERRUPTED]\npagerank        pi = x"));
    s = walk_report_text(&k, &p, ULAM_REPORT_QUIET);
    assert_null(strstr(s, "pagerank"));
    s = walk_report_text(&k, &p, ULAM_REPORT_JSON);
    assert_non_null(strstr(s, "{\"index\": 3, \"quantity\": \"pi\", "));
    o.estimator = 3; /* not an estimator: nothing */
    s = walk_report_text(&k, &p, ULAM_REPORT_BRIEF);
    assert_string_equal(s, "");
    ulam_walk_report_fprint(NULL, &p, ULAM_REPORT_BRIEF); /* no stream, no report: nothing */
    ulam_walk_report_fprint(stdout, NULL, ULAM_REPORT_BRIEF);
    free(k.buf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_json),
        cmocka_unit_test(test_choice),
        cmocka_unit_test(test_reference),
        cmocka_unit_test(test_walk_report),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
