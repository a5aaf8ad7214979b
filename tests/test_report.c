/* A walk result as JSON, a walk run's report, the report kinds (ulam info, direct, a query)
 * (include/ulam_report.h) and the reference solve (include/ulam_reference.h): the members ulam
 * solve --json prints, written to the caller's stream, null for what is not finite; the
 * reference LU as chosen, and GMRES when the LU would pass the memory limit; a query of a batch run
 * by the library (ulam_analysis_query). */
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

/* What f's writer wrote (the caller frees it). */
static char *written(FILE *f, char **buf)
{
    fclose(f);
    return *buf;
}

/* A bidirectional report by hand: the answer line alone (QUIET), the reverse push's lines and
 * PageRank's (BRIEF), --check's line alone, JSON without guards (radii null, the interval by its
 * ends); the single-source table's rows; nothing for a report with neither. */
static void test_bidir(void **state)
{
    (void)state;
    ulam_bidir_opts o = ulam_bidir_defaults();
    o.target = 6, o.source = 2, o.walk.exec.seed = 5;
    ulam_bidir_result r = {.estimate = 0.25, .std_error = 0.001, .ci95 = {0.248, 0.252}, .push_part = 0.2};
    r.push.rmax = 0.001, r.push.ops = 100, r.push.support = 4, r.walks.walks = 1000, r.walks.threads = 1;
    ulam_bidir_report p = {.opts = &o, .result = &r, .node_base = 1, .answer_name = "pi", .pagerank = 0.85,
                           .check = 1, .direct = 0.2515, .direct_method = "dense LU", .direct_seconds = 0.5};
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    ulam_report_fprint(f, ULAM_REPORT_BIDIR, &p, ULAM_REPORT_QUIET);
    assert_string_equal(written(f, &buf), "pi[7]           0.25 +- 0.001 (95% CI 0.248 .. 0.252)\n");
    free(buf);
    /* a side over 10 standard errors (the push's certified range leading, Poisson 200x200 --jacobi: +- 0.000919
       beside 2975.88 .. 2976.55): the +- is that side, the standard error named; on 6d7184d the line read +- 0.001 */
    r.ci95[0] = 0.2, r.ci95[1] = 0.27;
    f = open_memstream(&buf, &len);
    ulam_report_fprint(f, ULAM_REPORT_BIDIR, &p, ULAM_REPORT_QUIET);
    assert_string_equal(written(f, &buf), "pi[7]           0.25 +- 0.05 (95% CI 0.2 .. 0.27; standard error 0.001)\n");
    free(buf);
    r.ci95[0] = 0.248, r.ci95[1] = 0.252;
    f = open_memstream(&buf, &len);
    ulam_report_fprint(f, ULAM_REPORT_BIDIR, &p, ULAM_REPORT_BRIEF);
    char *s = written(f, &buf);
    const char *lines[] = {"pi[7] ", "\nmethod          bidirectional: reverse push from 7, walks from source 3 (balanced rmax)\n",
                           "\nwalks           1000 (0 cut, 0 steps, 1 threads)\n", "\nbalance ", "\nseconds ",
                           "\nload ", "\npagerank        pi = (1 - 0.85) x, ", "s e_3 (source 3)",
                           "\ndirect          0.2515 (dense LU, 0.5 s), z = -1.500\n"};
    const char *at = s;
    for (size_t k = 0; k < sizeof lines / sizeof *lines; k++) { /* each present, in this order */
        assert_non_null(at = strstr(at, lines[k]));
    }
    assert_null(strstr(s, "guards ")); /* no guard given */
    free(s);
    f = open_memstream(&buf, &len);
    ulam_report_fprint(f, ULAM_REPORT_BIDIR, &p, ULAM_REPORT_CHECK);
    assert_string_equal(written(f, &buf), "direct          0.2515 (dense LU, 0.5 s), z = -1.500\n");
    free(buf);
    /* z past 4 with direct inside the interval (a range term leads it): said, not left as a bare z = 50 */
    p.direct = 0.2, r.ci95[0] = 0.19, r.ci95[1] = 0.3;
    f = open_memstream(&buf, &len);
    ulam_report_fprint(f, ULAM_REPORT_BIDIR, &p, ULAM_REPORT_CHECK);
    assert_string_equal(written(f, &buf), "direct          0.2 (dense LU, 0.5 s), z = 50.000 (direct inside the 95% interval: "
                                          "z counts the standard error alone, the interval also its range terms)\n");
    free(buf);
    p.direct = 0.3515, r.ci95[0] = 0.248, r.ci95[1] = 0.252;
    f = open_memstream(&buf, &len);
    ulam_report_fprint(f, ULAM_REPORT_BIDIR, &p, ULAM_REPORT_CHECK);
    assert_string_equal(written(f, &buf), "direct          0.3515 (dense LU, 0.5 s), z = -101.500 (direct OUTSIDE the 95% interval)\n");
    free(buf);
    p.direct = 0.2515;
    f = open_memstream(&buf, &len);
    ulam_report_fprint(f, ULAM_REPORT_BIDIR, &p, ULAM_REPORT_JSON);
    s = written(f, &buf);
    assert_int_equal(strncmp(s, "{\"index\": 7, \"quantity\": \"pi\", \"source\": 3, \"b_nonzeros\": 1, ", 60), 0);
    assert_non_null(strstr(s, "\"ci95\": [0.248, 0.252], \"variance_finite\": true, \"rho_abs\": null, \"rho_hat\": null, "));
    assert_non_null(strstr(s, "\"direct\": 0.2515, \"z\": -1.5000000000000013, "));
    assert_string_equal(s + strlen(s) - 22, "\"interrupted\": false}\n");
    free(s);

    ulam_fpush_info t = {.rmax = 0.01, .residual_bound = 0.5, .walks = 10};
    int64_t order[2] = {4, 0};
    double x[5] = {0.1, 0, 0, 0, 0.3}, se[2] = {0.01, 0.02}, lo[2] = {0.2, NAN}, hi[2] = {0.4, NAN};
    ulam_bidir_report q = {.top = &t, .n = 5, .source = 5, .rows = 2, .order = order, .x = x, .se = se, .lo = lo, .hi = hi};
    f = open_memstream(&buf, &len);
    ulam_report_fprint(f, ULAM_REPORT_BIDIR, &q, ULAM_REPORT_QUIET);
    assert_string_equal(written(f, &buf), "1      4          0.3            0.01        0.2          0.4\n"
                                          "2      0          0.1            0.02        none\n");
    free(buf);
    f = open_memstream(&buf, &len);
    ulam_report_fprint(f, ULAM_REPORT_BIDIR, &q, ULAM_REPORT_JSON);
    s = written(f, &buf);
    assert_non_null(strstr(s, "\"top\": [{\"index\": 4, \"estimate\": 0.29999999999999999, "));
    assert_non_null(strstr(s, "\"ci95\": [null, null]}], \"dense\": false, \"interrupted\": false, \"stopped_at_time\": false}\n"));
    free(s);
    ulam_bidir_report none = {0};
    f = open_memstream(&buf, &len);
    assert_int_equal(ulam_report_fprint(f, ULAM_REPORT_BIDIR, &none, ULAM_REPORT_BRIEF), ULAM_EINVAL);
    assert_int_equal(ulam_report_fprint(NULL, ULAM_REPORT_BIDIR, &p, ULAM_REPORT_BRIEF), ULAM_EINVAL);
    assert_string_equal(written(f, &buf), "");
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
    ulam_reference_goal goal = {.index = -1}; /* every component, as narrow as it gets */
    assert_int_equal(ulam_reference_solve(M, b, -1, (size_t)1 << 30, &goal, x, &info, &how, &err), ULAM_OK);
    assert_string_equal(how, "dense LU");
    for (int i = 0; i < 2; i++) assert_true(fabs(x[i] - want[i]) < 1e-14);
    assert_int_equal(ulam_reference_solve(M, b, 0, 16, NULL, x, &info, &how, &err), ULAM_EMEMLIMIT);
    assert_int_equal(ulam_reference_solve(M, b, 0, 16, &goal, x, &info, &how, &err), ULAM_OK);
    assert_string_equal(how, "GMRES(50)"); /* M is not symmetric */
    assert_true(!goal.cg && goal.met && goal.certified && goal.reached < 1e-12 && goal.products >= 2);
    for (int i = 0; i < 2; i++) assert_true(fabs(x[i] - want[i]) < 1e-11);
    assert_true(info.residual <= 1e-12);
    assert_true(plan.cg == 0 && plan.products >= 1000);
    assert_int_equal(ulam_reference_solve(NULL, b, 0, 16, &goal, x, &info, &how, &err), ULAM_EINVAL);
    ulam_csr_free(M);
}

/* M of the g x g five-point Poisson grid's Jacobi splitting (M = (4I - A) / 4, rho(M) = cos(pi / (g + 1))). */
static ulam_csr *poisson_jacobi(int g)
{
    int64_t n = (int64_t)g * g, k = 0;
    int32_t *ti = malloc(4 * (size_t)n * sizeof *ti), *tj = malloc(4 * (size_t)n * sizeof *tj);
    double *tx = malloc(4 * (size_t)n * sizeof *tx);
    for (int y = 0; y < g; y++)
        for (int x = 0; x < g; x++) {
            int i = y * g + x, nb[4] = {x > 0 ? i - 1 : -1, x < g - 1 ? i + 1 : -1, y > 0 ? i - g : -1, y < g - 1 ? i + g : -1};
            for (int q = 0; q < 4; q++)
                if (nb[q] >= 0) ti[k] = i, tj[k] = nb[q], tx[k++] = 0.25;
        }
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(n, n, k, ti, tj, tx, &M), ULAM_OK);
    free(ti), free(tj), free(tx);
    return M;
}

/* Past the LU's memory limit on a symmetric M (a 120 x 120 Poisson grid, kappa(I - M) about 5900):
 * CG, refined until x[c]'s certified range is within the goal, that range holding a CG solution
 * to 1e-10; a cap it cannot meet says so (ENOCONV, capped, the range it reached still certified);
 * a goal below the rounding stops at the floor, not at the cap.  The old fallback ran GMRES(50)
 * to a fixed 1e-12 with 10^7 iterations of cap (12 min and more on the 500 x 500 grid). */
static void test_reference_iterative(void **state)
{
    (void)state;
    int g = 120;
    int64_t n = (int64_t)g * g, c = (int64_t)(g / 2) * g + g / 2;
    ulam_csr *M = poisson_jacobi(g);
    double *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x), *xc = malloc((size_t)n * sizeof *xc);
    for (int64_t i = 0; i < n; i++) b[i] = 0.25;
    int it;
    double res;
    ulam_cg(M, b, 1e-10, 100000, xc, &it, &res); /* a close solution beside the certified range */
    ulam_direct_info info;
    ulam_error err;
    const char *how = NULL;
    ulam_reference_info plan;
    assert_int_equal(ulam_reference_plan(M, 0, 0, &plan, &err), ULAM_OK);
    assert_true(plan.cg == 1 && plan.products == (int64_t)(4e10 / (double)(M->rowptr[n] + 10 * n)));
    ulam_reference_goal goal = {.index = c, .half_width = 1e-6 * xc[c]};
    assert_int_equal(ulam_reference_solve(M, b, 0, 16, &goal, x, &info, &how, &err), ULAM_OK);
    assert_string_equal(how, "CG");
    assert_true(goal.cg && goal.met && goal.certified && !goal.capped && goal.products <= goal.cap);
    assert_true(goal.cap == plan.products && goal.rounds >= 1 && goal.certificate > 0);
    assert_true(goal.reached <= goal.half_width && goal.lo <= x[c] && x[c] <= goal.hi);
    assert_true(goal.lo - 1e-9 * xc[c] <= xc[c] && xc[c] <= goal.hi + 1e-9 * xc[c]);
    assert_true(info.residual < 1e-6 && info.seconds >= 0);
    int64_t enough = goal.products;
    ulam_reference_goal capped = {.index = c, .half_width = 1e-6 * xc[c], .max_products = 20};
    assert_int_equal(ulam_reference_solve(M, b, 0, 16, &capped, x, &info, &how, &err), ULAM_ENOCONV);
    assert_true(capped.capped && !capped.met && capped.certified && capped.products == 20 && capped.cap == 20);
    assert_true(capped.reached > capped.half_width && isfinite(capped.reached));
    assert_true(capped.lo <= xc[c] && xc[c] <= capped.hi);
    assert_non_null(strstr(err.msg, "cap of 20 products"));
    ulam_reference_goal tiny = {.index = c, .half_width = 1e-300};
    assert_int_equal(ulam_reference_solve(M, b, 0, 16, &tiny, x, &info, &how, &err), ULAM_ENOCONV);
    assert_true(!tiny.capped && !tiny.met && tiny.certified && tiny.products < tiny.cap);
    assert_true(tiny.reached < goal.reached && tiny.products >= enough);
    assert_non_null(strstr(err.msg, "rounding's floor"));
    ulam_reference_goal all = {.index = -1}; /* every component, as narrow as it gets */
    assert_int_equal(ulam_reference_solve(M, b, 0, 16, &all, x, &info, &how, &err), ULAM_OK);
    assert_true(all.met && isnan(all.lo) && all.reached < 1e-6 * xc[c]);
    for (int64_t i = 0; i < n; i++) assert_true(fabs(x[i] - xc[i]) <= all.reached + 1e-9 * xc[c]);
    free(b), free(x), free(xc);
    ulam_csr_free(M);
}

/* Write a report of kind to a string (the caller frees it); *status gets ulam_report_fprint's. */
static char *kind_text(int kind, const void *report, int format, int *status)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    *status = ulam_report_fprint(f, kind, report, format);
    fclose(f);
    return buf;
}

/* The report kinds: a query's line and JSON object, a direct solve's first ten entries under an
 * edge list's 0-based ids, ulam info's radii, verdicts and damping table, ulam prepare's lines;
 * unknown kinds refused. */
static void test_kinds(void **state)
{
    (void)state;
    int st;
    ulam_query_report q = {.query = 4, .line = 9, .source = -1, .index = 2, .estimate = 0.5, .std_error = 0.01,
                           .ci95 = {0.48, 0.52}, .rel_err_met = 1, .walks = 100, .seconds = 0.25, .seed = 9,
                           .answer_name = "x", .node_base = 1};
    char *s = kind_text(ULAM_REPORT_QUERY, &q, ULAM_REPORT_BRIEF, &st);
    assert_int_equal(st, ULAM_OK);
    assert_string_equal(s, "x[3] 0.5 +- 0.01 (95% CI 0.48 .. 0.52)  walks 100, 0.2500 s, seed 9\n");
    free(s);
    q.ci95[0] = q.ci95[1] = NAN, q.source = 0;
    s = kind_text(ULAM_REPORT_QUERY, &q, ULAM_REPORT_JSON, &st);
    assert_string_equal(s, "{\"query\": 5, \"line\": 9, \"source\": 1, \"index\": 3, \"estimate\": 0.5, \"stderr\": "
                           "0.01, \"ci95\": null, \"rel_err_met\": true, \"walks\": 100, \"seed\": 9, \"seconds\": 0.25}\n");
    free(s);

    double x[12];
    for (int i = 0; i < 12; i++) x[i] = i / 4.0;
    ulam_direct_report d = {.n = 12, .x = x, .list = 1, .info = {.rcond = 0.5, .residual = 1e-16, .seconds = 0.125},
                            .answer_name = "pi", .node_base = 0};
    s = kind_text(ULAM_REPORT_DIRECT, &d, ULAM_REPORT_BRIEF, &st);
    assert_int_equal(st, ULAM_OK);
    /* the answer first (newuser15), then n */
    assert_non_null(strstr(s, "pi[0]      0\npi[1]      0.25\n"));
    assert_ptr_equal(strstr(s, "pi[0]"), s);
    assert_non_null(strstr(s, "pi[9]      2.25\n...        (2 more: use --out or --index)\nn          12\nmethod     dense LU (LAPACK)\n"));
    free(s);
    d.index = 12, d.sparse = 1;
    s = kind_text(ULAM_REPORT_DIRECT, &d, ULAM_REPORT_JSON, &st);
    assert_string_equal(s, "{\"n\": 12, \"index\": 11, \"estimate\": 2.75, \"value\": 2.75, \"method\": \"sparse LU\", "
                           "\"rcond\": 0.5, \"residual\": 9.9999999999999998e-17, \"seconds\": 0.125}\n");
    free(s);
    d.index = 13; /* past n */
    s = kind_text(ULAM_REPORT_DIRECT, &d, ULAM_REPORT_JSON, &st);
    assert_int_equal(st, ULAM_EINVAL);
    assert_string_equal(s, ""); /* refused before a byte */
    free(s);

    int32_t ti[2] = {0, 1}, tj[2] = {1, 0}; /* M = [0 1/2; 1/4 0]: rho(M) = rho(|M|) = sqrt(1/8) */
    double tx[2] = {0.5, 0.25};
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(2, 2, 2, ti, tj, tx, &M), ULAM_OK);
    ulam_info_report ir = {.matrix = "m.mtx", .jacobi = 1, .omega = 1.0};
    ulam_error err;
    ulam_guard_opts go = ulam_guard_defaults();
    go.tight = 1;
    assert_int_equal(ulam_csr_stats_compute(M, &ir.st), ULAM_OK);
    assert_int_equal(ulam_spectral_radius(M, 0, NULL, &ir.rho), ULAM_OK);
    assert_int_equal(ulam_guard_check(M, 0.0, &go, &ir.g, &err), ULAM_OK);
    s = kind_text(ULAM_REPORT_INFO, &ir, ULAM_REPORT_BRIEF, &st);
    assert_int_equal(st, ULAM_OK);
    assert_non_null(strstr(s, "matrix           m.mtx (Jacobi splitting of A)\nn                2\n"));
    assert_non_null(strstr(s, "Neumann series   converges (rho(M) < 1) [certified: rho(M) <= rho(|M|) < 1]\n"));
    /* J >= 0: the table from J's radii, rho(M_w) = 1 - w + w rho(J) */
    assert_non_null(strstr(s, "                  1.00   0.353553   "));
    assert_non_null(strstr(s, "                  0.50   0.676777   "));
    assert_non_null(strstr(s, "converges  converge\n                 (rho(|I - w D^-1 A|) = 1 - w + w rho(|J|)"));
    free(s);
    s = kind_text(ULAM_REPORT_INFO, &ir, ULAM_REPORT_JSON, &st);
    assert_non_null(strstr(s, "{\"matrix\": \"m.mtx\", \"jacobi\": true, \"n\": 2, "));
    assert_non_null(strstr(s, "\"neumann_converges\": true, \"neumann_certified\": true, \"walks_converge\": true, "));
    assert_null(strstr(s, "damping"));
    free(s);
    ulam_csr_free(M);

    /* a signed J = [0 -1/2; -1/4 0] of A = [1 1/2; 1/4 1]: a table only with A, by Arnoldi on each M_w */
    int32_t ai[4] = {0, 0, 1, 1}, aj[4] = {0, 1, 0, 1};
    double ax[4] = {1, 0.5, 0.25, 1}, sx[2] = {-0.5, -0.25};
    ulam_csr *A = NULL;
    assert_int_equal(ulam_csr_from_triplets(2, 2, 2, ti, tj, sx, &M), ULAM_OK);
    assert_int_equal(ulam_csr_from_triplets(2, 2, 4, ai, aj, ax, &A), ULAM_OK);
    assert_int_equal(ulam_csr_stats_compute(M, &ir.st), ULAM_OK);
    assert_int_equal(ulam_spectral_radius(M, 0, NULL, &ir.rho), ULAM_OK);
    assert_int_equal(ulam_guard_check(M, 0.0, &go, &ir.g, &err), ULAM_OK);
    s = kind_text(ULAM_REPORT_INFO, &ir, ULAM_REPORT_BRIEF, &st);
    assert_null(strstr(s, "damping"));
    free(s);
    ir.A = A;
    s = kind_text(ULAM_REPORT_INFO, &ir, ULAM_REPORT_BRIEF, &st);
    assert_int_equal(st, ULAM_OK);
    assert_non_null(strstr(s, "                  1.00   0.353553   "));
    assert_non_null(strstr(s, "                  0.50   0.676777   ")); /* eigenvalues +-0.3536 move to 0.68, 0.32 */
    assert_null(strstr(s, "as is rho(M) for J >= 0"));
    free(s);
    ulam_csr_free(M), ulam_csr_free(A);

    /* ulam prepare's lines: an upper bound just below 1 shows its digits, a tiny one six significant ones */
    ulam_certificate c = {.rowsum_min = 0.5, .rowsum_max = 1.25, .colsum_min = 0.25, .colsum_max = 2};
    c.guard.abs = (ulam_power){.rho = 0.99, .lower = 2e-23, .upper = 0.99999999, .iterations = 7, .converged = 1,
                               .seconds = 0.125};
    c.guard.verdict_abs = ULAM_VERDICT_EDGE;
    ulam_prepare_report pr = {.path = "s.ulam", .n = 2, .nnz = 3, .with_b = 1, .transpose = 1, .cert = &c,
                              .load_seconds = 0.5, .guard_seconds = 0.25};
    s = kind_text(ULAM_REPORT_PREPARE, &pr, ULAM_REPORT_BRIEF, &st);
    assert_int_equal(st, ULAM_OK);
    char want[512];
    snprintf(want, sizeof want,
             "prepared       s.ulam: n 2, nnz 3, with b, with M^T\n"
             "rho(|M|)       0.990000 (bounds [2e-23, 0.99999998999999995], 7 iterations, 0.125 s)  (%s)\n"
             "row sums |M|   0.5 .. 1.25; column sums 0.25 .. 2\nseconds        0.500 load, 0.250 guards\n",
             ulam_verdict_word(ULAM_VERDICT_EDGE));
    assert_string_equal(s, want);
    free(s);
    s = kind_text(ULAM_REPORT_PREPARE, &pr, ULAM_REPORT_JSON, &st);
    assert_int_equal(st, ULAM_EINVAL);
    assert_string_equal(s, "");
    free(s);

    assert_int_equal(ulam_report_fprint(stdout, 0, &q, ULAM_REPORT_BRIEF), ULAM_EINVAL);
    assert_int_equal(ulam_report_fprint(stdout, 99, &q, ULAM_REPORT_BRIEF), ULAM_EINVAL);
    assert_int_equal(ulam_report_fprint(stdout, ULAM_REPORT_QUERY, NULL, ULAM_REPORT_BRIEF), ULAM_EINVAL);
}

/* ulam_analysis_query, ulam solve --queries' engine: an index line is the walks on the analysis'
 * kept kernel, ulam_solve_walks' bit for bit (same seed, a fixed budget), within 4 sigma of LAPACK; a point source's line is within
 * 4 sigma of LAPACK with b = e_S, under M^T's guards it derives once; missing pieces refused. */
static void test_query_run(void **state)
{
    (void)state;
    enum { N = 60 };
    int32_t ti[4 * N], tj[4 * N];
    double tx[4 * N], b[N], e[N] = {0}, x[N], xs[N];
    for (int i = 0; i < N; i++) /* four entries of 0.2 a row: rho(M) = 0.8 */
        for (int k = 0; k < 4; k++)
            ti[4 * i + k] = i, tj[4 * i + k] = (int32_t)((i + 1 + 7 * k + (k == 3 ? i : 0)) % N), tx[4 * i + k] = 0.2;
    for (int i = 0; i < N; i++) b[i] = 1 + i % 3;
    e[2] = 1;
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(N, N, 4 * N, ti, tj, tx, &M), ULAM_OK);
    assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
    assert_int_equal(ulam_direct_solve(M, e, xs, 0, NULL, NULL), ULAM_OK);
    ulam_guard g;
    ulam_guard_opts go = ulam_guard_defaults();
    assert_int_equal(ulam_guard_check(M, 0.0, &go, &g, NULL), ULAM_OK);
    ulam_analysis_opts ao = ulam_analysis_defaults();
    ao.b = b;
    ulam_analysis *a = NULL;
    assert_int_equal(ulam_analysis_alloc(M, &ao, &a, NULL), ULAM_OK);
    ulam_walk_opts o = ulam_walk_defaults();
    o.mode = ULAM_ADJOINT, o.stop.max_walks = 4000, o.exec.threads = 1, o.exec.seed = 7, o.policy.guard = &g;
    ulam_guard gt = {0};
    int stopped = 1;
    ulam_query_report q = {.source = -1, .index = 5, .answer_name = "x", .node_base = 1};
    assert_int_equal(ulam_analysis_query(a, b, &o, &gt, &q, &stopped, NULL), ULAM_OK);
    ulam_walk_opts w = o;
    w.query.index = 5;
    ulam_walk_result r;
    assert_int_equal(ulam_solve_walks(M, b, &w, &r, NULL), ULAM_OK);
    assert_false(stopped);
    assert_true(q.estimate == r.estimate && q.std_error == r.std_error && q.walks == 4000 && q.seed == 7);
    assert_true(fabs(q.estimate - x[5]) < 4 * q.std_error);
    q.source = 2, o.exec.seed = 8;
    assert_int_equal(ulam_analysis_query(a, b, &o, &gt, &q, &stopped, NULL), ULAM_OK);
    assert_true(gt.computed & ULAM_GUARD_ADJOINT); /* M^T's guards, kept for the next point source */
    assert_true(q.std_error > 0 && fabs(q.estimate - xs[5]) < 4 * q.std_error && q.seed == 8);
    ulam_error err;
    assert_int_equal(ulam_analysis_query(a, b, &o, NULL, &q, &stopped, &err), ULAM_EINVAL); /* no M^T guards */
    q.source = -1;
    assert_int_equal(ulam_analysis_query(a, NULL, &o, &gt, &q, &stopped, &err), ULAM_EINVAL); /* no b */
    assert_int_equal(ulam_analysis_query(a, b, &o, &gt, &q, NULL, &err), ULAM_EINVAL);
    ulam_analysis_free(a);
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
    ulam_report_fprint(f, ULAM_REPORT_WALK, p, format);
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
    assert_int_equal(ulam_report_fprint(NULL, ULAM_REPORT_WALK, &p, ULAM_REPORT_BRIEF), ULAM_EINVAL); /* nothing */
    assert_int_equal(ulam_report_fprint(stdout, ULAM_REPORT_WALK, NULL, ULAM_REPORT_BRIEF), ULAM_EINVAL);
    free(k.buf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_json),
        cmocka_unit_test(test_choice),
        cmocka_unit_test(test_bidir),
        cmocka_unit_test(test_reference),
        cmocka_unit_test(test_reference_iterative),
        cmocka_unit_test(test_kinds),
        cmocka_unit_test(test_walk_report),
        cmocka_unit_test(test_query_run),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
