/* Matrix Market reading and writing: every good kind, every malformed input class. */
#include "testutil.h"

#include <string.h>
#include <unistd.h>

typedef struct {
    const char *file;
    int status;
    long line;
    int as_vector;
} bad_case;

/* Each malformed input, the status it must get, and the line it must name. */
static const bad_case bad_cases[] = {
    {"tests/data/empty.mtx", ULAM_EEMPTY, 1, 0},
    {"tests/data/no_banner.mtx", ULAM_EBANNER, 1, 0},
    {"tests/data/bad_format.mtx", ULAM_EBANNER, 1, 0},
    {"tests/data/complex.mtx", ULAM_EUNSUPPORTED, 1, 0},
    {"tests/data/hermitian.mtx", ULAM_EUNSUPPORTED, 1, 0},
    {"tests/data/no_size.mtx", ULAM_ESIZELINE, 3, 0},
    {"tests/data/bad_size.mtx", ULAM_ESIZELINE, 3, 0},
    {"tests/data/negative_size.mtx", ULAM_ESIZELINE, 2, 0},
    {"tests/data/too_few.mtx", ULAM_ETOOFEW, 4, 0},
    {"tests/data/too_many.mtx", ULAM_ETOOMANY, 5, 0},
    {"tests/data/index_zero.mtx", ULAM_EINDEX, 4, 0},
    {"tests/data/row_too_big.mtx", ULAM_EINDEX, 4, 0},
    {"tests/data/col_too_big.mtx", ULAM_EINDEX, 4, 0},
    {"tests/data/not_a_number.mtx", ULAM_ESYNTAX, 4, 0},
    {"tests/data/index_not_a_number.mtx", ULAM_ESYNTAX, 4, 0},
    {"tests/data/nan.mtx", ULAM_ENONFINITE, 3, 0},
    {"tests/data/inf.mtx", ULAM_ENONFINITE, 4, 0},
    {"tests/data/missing_value.mtx", ULAM_ESYNTAX, 4, 0},
    {"tests/data/extra_field.mtx", ULAM_ESYNTAX, 4, 0},
    {"tests/data/huge_dims.mtx", ULAM_EOVERFLOW, 2, 0},
    {"tests/data/huge_nnz.mtx", ULAM_ETOOFEW, 2, 0},
    {"tests/data/nnz_exceeds_size.mtx", ULAM_ETOOFEW, 2, 0}, /* more than rows x columns is allowed (duplicates); not more than the file holds */
    {"tests/data/sparse_dims.mtx", ULAM_EOVERFLOW, 2, 0},   /* 74 bytes declaring 16,777,280 rows and one entry */
    {"tests/data/nul_after_value.mtx", ULAM_ESYNTAX, 4, 0}, /* "0.25\0junk": not read as 0.25 */
    {"tests/data/truncated.mtx.gz", ULAM_ESYNTAX, 0, 0},    /* a gzip stream cut short */
    {"tests/data/skew_diagonal.mtx", ULAM_EINDEX, 4, 0},
    {"tests/data/integer_not_integer.mtx", ULAM_ESYNTAX, 3, 0},
    {"tests/data/vector_not_column.mtx", ULAM_EDIM, 0, 1},
    {"tests/data/vector_too_short.mtx", ULAM_ETOOFEW, 4, 1},
    {"tests/data/does_not_exist.mtx", ULAM_EIO, 0, 0},
};

/* A malformed file fails with its status and line, and leaves the output NULL. */
static void test_bad(void **state)
{
    const bad_case *c = *state;
    ulam_error err;
    int s;
    if (c->as_vector) {
        double *x = (double *)1;
        int64_t n = -1;
        s = ulam_mm_read_vector(c->file, &x, &n, &err);
        assert_null(x);
    } else {
        ulam_csr *A = (ulam_csr *)1;
        s = ulam_mm_read_matrix(c->file, &A, &err);
        assert_null(A);
    }
    if (s != c->status || err.line != c->line)
        print_error("%s: got status %d (%s) at line %ld: %s\n", c->file, s, ulam_strerror(s),
                    err.line, err.msg);
    assert_int_equal(s, c->status);
    assert_int_equal(err.status, c->status);
    assert_int_equal(err.line, c->line);
    assert_true(strlen(err.msg) > 5); /* says what was expected */
}

/* Symmetric files are expanded to both triangles. */
static void test_symmetric(void **state)
{
    (void)state;
    ulam_csr *A = must_read("tests/data/symmetric.mtx");
    assert_int_equal(ulam_csr_nnz(A), 6);
    assert_close(csr_get(A, 0, 1), -1.0, 0);
    assert_close(csr_get(A, 1, 0), -1.0, 0);
    assert_close(csr_get(A, 1, 2), -1.0, 0);
    assert_close(csr_get(A, 2, 2), 2.0, 0);
    assert_close(csr_get(A, 1, 1), 0.0, 0);
    ulam_csr_free(A);
}

/* Skew-symmetric files mirror with a sign change. */
static void test_skew(void **state)
{
    (void)state;
    ulam_csr *A = must_read("tests/data/skew.mtx");
    assert_int_equal(ulam_csr_nnz(A), 4);
    assert_close(csr_get(A, 1, 0), 0.5, 0);
    assert_close(csr_get(A, 0, 1), -0.5, 0);
    assert_close(csr_get(A, 2, 0), -2.0, 0);
    assert_close(csr_get(A, 0, 2), 2.0, 0);
    ulam_csr_free(A);
}

/* Pattern entries are ones; integer entries keep their values. */
static void test_pattern_and_integer(void **state)
{
    (void)state;
    ulam_csr *P = must_read("tests/data/pattern.mtx");
    assert_int_equal(ulam_csr_nnz(P), 3);
    assert_close(csr_get(P, 2, 0), 1.0, 0);
    ulam_csr *I = must_read("tests/data/integer.mtx");
    assert_close(csr_get(I, 0, 0), -3.0, 0);
    assert_close(csr_get(I, 1, 1), 7.0, 0);
    ulam_csr_free(P);
    ulam_csr_free(I);
}

/* Duplicates are summed; explicit zeros and entries that cancel are dropped. */
static void test_duplicates(void **state)
{
    (void)state;
    ulam_csr *A = must_read("tests/data/duplicates.mtx");
    assert_int_equal(ulam_csr_nnz(A), 1);
    assert_close(csr_get(A, 0, 0), 0.5, 0);
    ulam_csr_free(A);
}

/* More entries than rows x columns (duplicates, summed) are read as SciPy reads them. */
static void test_duplicates_beyond(void **state)
{
    (void)state;
    ulam_csr *A = must_read("tests/data/duplicates_beyond.mtx");
    assert_int_equal(ulam_csr_nnz(A), 4);
    assert_close(csr_get(A, 0, 0), 0.5, 0);
    assert_close(csr_get(A, 1, 0), 0.5, 0);
    assert_close(csr_get(A, 0, 1), 2.0, 0);
    assert_close(csr_get(A, 1, 1), 3.0, 0);
    ulam_csr_free(A);
    ulam_mm_opts o = ulam_mm_defaults(); /* the parallel reader too */
    o.threads = 2;
    FILE *f = fopen("tests/data/duplicates_beyond.mtx", "rb");
    assert_non_null(f);
    assert_int_equal(ulam_mm_read_matrix_opts(f, "d", &o, &A, NULL), ULAM_OK);
    fclose(f);
    assert_close(csr_get(A, 1, 1), 3.0, 0);
    ulam_csr_free(A);
}

/* Comment lines may be indented (blanks or tabs before the '%'), before the size line too. */
static void test_indented_comment(void **state)
{
    (void)state;
    ulam_csr *A = must_read("tests/data/indented_comment.mtx");
    assert_int_equal(ulam_csr_nnz(A), 2);
    assert_close(csr_get(A, 1, 0), 0.25, 0);
    ulam_csr_free(A);
}

/* A gzip-compressed file is read through zlib by its path (the same matrix and vector); from an
 * open FILE it is named as gzip-compressed. */
static void test_gzip(void **state)
{
    (void)state;
    ulam_csr *A = must_read("tests/data/dag5.mtx"), *Z = must_read("tests/data/dag5.mtx.gz");
    assert_csr_same(Z, A);
    double *x = NULL, *y = NULL;
    int64_t n = 0, m = 0;
    assert_int_equal(ulam_mm_read_vector("tests/data/ones3.mtx", &x, &n, NULL), ULAM_OK);
    assert_int_equal(ulam_mm_read_vector("tests/data/ones3.mtx.gz", &y, &m, NULL), ULAM_OK);
    assert_int_equal(n, m);
    assert_memory_equal(x, y, (size_t)n * sizeof *x);
    FILE *f = fopen("tests/data/dag5.mtx.gz", "rb");
    assert_non_null(f);
    ulam_csr *B = NULL;
    ulam_error err;
    assert_int_equal(ulam_mm_read_matrix_opts(f, "dag5.mtx.gz", NULL, &B, &err), ULAM_EUNSUPPORTED);
    assert_non_null(strstr(err.msg, "gzip"));
    fclose(f);
    ulam_csr_free(A), ulam_csr_free(Z);
    free(x), free(y);
}

/* CR LF line ends, blank lines, upper-case banners and a missing final newline are read. */
static void test_lenient_text(void **state)
{
    (void)state;
    ulam_csr *A = must_read("tests/data/crlf.mtx");
    assert_close(csr_get(A, 1, 1), 0.25, 0);
    ulam_csr *B = must_read("tests/data/banner_case.mtx");
    assert_close(csr_get(B, 0, 0), 3.0, 0);
    ulam_csr *C = must_read("tests/data/no_final_newline.mtx");
    assert_close(csr_get(C, 0, 0), 0.5, 0);
    ulam_csr_free(A);
    ulam_csr_free(B);
    ulam_csr_free(C);
}

/* Dense array matrices are read column by column, zeros dropped. */
static void test_dense_array(void **state)
{
    (void)state;
    ulam_csr *A = must_read("tests/data/dense_array.mtx");
    assert_int_equal(ulam_csr_nnz(A), 3);
    assert_close(csr_get(A, 0, 0), 1.0, 0);
    assert_close(csr_get(A, 0, 1), 3.0, 0);
    assert_close(csr_get(A, 1, 1), 4.0, 0);
    ulam_csr_free(A);
}

/* Vectors come as array n x 1 or coordinate n x 1. */
static void test_vectors(void **state)
{
    (void)state;
    int64_t n;
    double *x = must_read_vector("matrices/chain4_b.mtx", &n);
    assert_int_equal(n, 4);
    assert_close(x[3], 2.0, 0);
    free(x);
    x = must_read_vector("tests/data/vector_coordinate.mtx", &n);
    assert_int_equal(n, 4);
    assert_close(x[0], 0.0, 0);
    assert_close(x[1], 5.0, 0);
    assert_close(x[3], -1.0, 0);
    free(x);
}

/* Writing then reading returns the same matrix and vector, bit for bit. */
static void test_roundtrip(void **state)
{
    (void)state;
    ulam_csr *A = must_read("matrices/randsub1000.mtx");
    char path[] = "/tmp/ulam_test_rtXXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(ulam_mm_write_matrix(path, A, "round trip"), ULAM_OK);
    ulam_csr *B = NULL;
    assert_int_equal(ulam_mm_read_matrix(path, &B, NULL), ULAM_OK);
    assert_csr_same(A, B);
    double v[3] = {1.0 / 3.0, -2e-300, 12345.678};
    assert_int_equal(ulam_mm_write_vector(path, v, 3, NULL), ULAM_OK);
    int64_t n;
    double *w = must_read_vector(path, &n);
    assert_int_equal(n, 3);
    assert_memory_equal(v, w, sizeof v);
    free(w);
    remove(path);
    ulam_csr_free(A);
    ulam_csr_free(B);
}

/* A vector holding NaN is refused and no file is left behind. */
static void test_write_refuses_nonfinite(void **state)
{
    (void)state;
    const char *path = "/tmp/ulam_test_nonfinite.mtx";
    remove(path);
    double v[2] = {1.0, NAN};
    assert_int_equal(ulam_mm_write_vector(path, v, 2, NULL), ULAM_ENONFINITE);
    assert_int_equal(access(path, F_OK), -1);
}

/* Writing into a directory that does not exist fails with ULAM_EIO. */
static void test_write_unwritable(void **state)
{
    (void)state;
    double v[1] = {1.0};
    assert_int_equal(ulam_mm_write_vector("/nonexistent-dir/x.mtx", v, 1, NULL), ULAM_EIO);
}

/* Reading from a memory stream (what the fuzzer does) gives the same as from a file. */
static void test_read_from_stream(void **state)
{
    (void)state;
    static char text[] = "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 2 0.5\n2 1 0.25\n";
    FILE *f = fmemopen(text, sizeof text - 1, "r");
    assert_non_null(f);
    ulam_csr *A = NULL;
    assert_int_equal(ulam_mm_read_matrix_opts(f, "mem", NULL, &A, NULL), ULAM_OK);
    fclose(f);
    assert_close(csr_get(A, 0, 1), 0.5, 0);
    assert_close(csr_get(A, 1, 0), 0.25, 0);
    ulam_csr_free(A);
}

/* ulam_strtod gives strtod's double (bit for bit) and end on input s; prints case k on failure. */
static void same_as_strtod(const char *s, long k)
{
    char *e1, *e2;
    if (!test_case(k)) return; /* the random strings are still drawn: case k is the same string alone */
    double a = ulam_strtod(s, &e1), b = strtod(s, &e2);
    if (memcmp(&a, &b, sizeof a) || e1 != e2)
        fail_msg("case %ld '%s': ulam_strtod %a (end +%td), strtod %a (end +%td)", k, s, a, e1 - s, b, e2 - s);
}

/* The fast number parser against strtod: a corpus of edge cases (17-digit values, ties,
 * subnormals, the exponent limits, more digits than 64 bits hold, forms strtod parses and the
 * reader refuses), then seeded random doubles printed several ways and random decimal strings. */
static void test_strtod(void **state)
{
    (void)state;
    static const char *const corpus[] = {
        "0", "-0", "+0", "0.0", "00000", "1", "-1", "+1.5", ".5", "5.", "-.5e1", "1e0", "1E+2", "1e-2",
        "0.1", "0.2", "0.3", "0.30000000000000004", "0.1000000000000000055511151231257827021181583404541015625",
        "3.141592653589793", "3.1415926535897932", "2.718281828459045235360287", "0.09999999999999999",
        "1.7976931348623157e308", "1.7976931348623158e308", "1.7976931348623159e308", "1e308", "1e309",
        "2.2250738585072014e-308", "2.2250738585072011e-308", "2.2250738585072009e-308", "4.9406564584124654e-324",
        "5e-324", "2.4703282292062327e-324", "2.4703282292062328e-324", "1e-320", "1e-400", "1e-342", "1e-343",
        "9007199254740992", "9007199254740993", "9007199254740994", "9007199254740995", "9007199254740993.0000001",
        "18446744073709551615", "18446744073709551616", "1844674407370955161", "9999999999999999999",
        "99999999999999999999", "12345678901234567890123", "1e22", "1e23", "8.988465674311579e307",
        "7.3177701707893310e+15", "1.00000000000000011102230246251565404236316680908203125",
        "1.00000000000000011102230246251565404236316680908203124", "1.00000000000000011102230246251565404236316680908203126",
        "4503599627370496.5", "4503599627370497.5", "0.000000000000000000000000000001234567890123456789",
        "123456789012345678e-30", "1e", "1e+", "1e-", "e5", ".", "-", "+", "", "   1.25", "\t-2.5e3x", "1.5 2",
        "inf", "-inf", "INF", "infinity", "nan", "NaN", "nan(0x1)", "0x1p3", "0X1.8P1", "-0x", "0x", "1e99999999999",
        "1e-99999999999", "0e99999999999", "1.0000000000000000000000000000000000000000000001", "00000000000000000000001.5",
        "100000000000000000000000", "1000000000000000000000000e-24", "7e-10", "6.02214076e23", "1.602176634e-19",
    };
    long k = 0;
    for (size_t i = 0; i < sizeof corpus / sizeof corpus[0]; i++) same_as_strtod(corpus[i], k++);
    static const char *const fmts[] = {"%.17g", "%.16g", "%.15g", "%.6e", "%.20e", "%g", "%.17e", "%.3f"};
    ulam_rng r;
    ulam_rng_seed(&r, 17, 0);
    char buf[512];
    for (int t = 0; t < 40000; t++) {
        uint64_t bits = ulam_rng_bounded(&r, 0);
        if (t % 4 == 1) bits &= 0x800FFFFFFFFFFFFFu; /* subnormal */
        if (t % 4 == 2) bits = (bits & 0x800FFFFFFFFFFFFFu) | (uint64_t)(1023 + (int)(bits >> 52) % 60 - 30) << 52;
        double x;
        memcpy(&x, &bits, sizeof x);
        if (!isfinite(x)) continue;
        for (size_t f = 0; f < sizeof fmts / sizeof fmts[0]; f++) {
            snprintf(buf, sizeof buf, fmts[f], x);
            same_as_strtod(buf, k++);
        }
    }
    for (int t = 0; t < 40000; t++) { /* random digits, point and exponent */
        int nd = 1 + (int)ulam_rng_bounded(&r, 24), dot = (int)ulam_rng_bounded(&r, (uint64_t)nd + 1), m = 0;
        if (ulam_rng_bounded(&r, 2)) buf[m++] = '-';
        for (int d = 0; d < nd; d++) {
            if (d == dot) buf[m++] = '.';
            buf[m++] = (char)('0' + ulam_rng_bounded(&r, 10));
        }
        m += snprintf(buf + m, sizeof buf - (size_t)m, "e%d", (int)ulam_rng_bounded(&r, 700) - 350);
        same_as_strtod(buf, k++);
    }
    test_case_done();
}

/* Write a coordinate file of nrows x nrows with k entries a row to path: rows rising (or
 * not), with comments, blank lines, CRLF ends, explicit zeros and repeated entries mixed in;
 * bad_line > 0 replaces that line (1-based) with text. */
static void write_big(const char *path, int64_t nrows, int k, int shuffled, long bad_line, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    ulam_rng r;
    ulam_rng_seed(&r, 99, (uint64_t)shuffled);
    fprintf(f, "%%%%MatrixMarket matrix coordinate real general\n%% a comment\n%lld %lld %lld\n", (long long)nrows,
            (long long)nrows, (long long)(nrows * k));
    long line = 3;
    for (int64_t q = 0; q < nrows * k; q++) {
        int64_t i = shuffled ? (int64_t)ulam_rng_bounded(&r, (uint64_t)nrows) : q / k;
        if (q % 997 == 0 && (bad_line <= 0 || line + 2 < bad_line - 1 || line > bad_line)) fprintf(f, "%% comment inside\n\n"), line += 2;
        line++;
        if (line == bad_line) fprintf(f, "%s\n", text);
        else if (q % 101 == 0) fprintf(f, "%lld %lld 0\r\n", (long long)i + 1, (long long)(i % nrows) + 1);
        else if (q % 103 == 0) fprintf(f, "%lld 1 %.17g\n", (long long)i + 1, ulam_rng_uniform(&r) - 0.5);
        else
            fprintf(f, "%lld %llu %.17g\n", (long long)i + 1, (unsigned long long)ulam_rng_bounded(&r, (uint64_t)nrows) + 1,
                    ulam_rng_uniform(&r) - 0.5);
    }
    fclose(f);
}

/* Read path with the given threads (1: the sequential reader). */
static int read_with(const char *path, int threads, ulam_csr **A, ulam_error *err)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    ulam_mm_opts o = {.threads = threads};
    int st = ulam_mm_read_matrix_opts(f, path, &o, A, err);
    fclose(f);
    return st;
}

/* The parallel reader gives the sequential reader's matrix (rows rising or not, comments,
 * zeros, repeats, CRLF), and every error at the same line with the same status (each case
 * prints its index when it fails). */
static void test_parallel_read(void **state)
{
    (void)state;
    char path[] = "/tmp/ulam_mm_parXXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    for (int shuffled = 0; shuffled < 2; shuffled++) {
        write_big(path, 3000, 8, shuffled, 0, NULL);
        ulam_csr *A = NULL, *B = NULL;
        assert_int_equal(read_with(path, 1, &A, NULL), ULAM_OK);
        assert_int_equal(read_with(path, 2, &B, NULL), ULAM_OK);
        assert_csr_same(A, B);
        ulam_csr_free(B);
        assert_int_equal(read_with(path, 3, &B, NULL), ULAM_OK);
        assert_csr_same(A, B);
        ulam_csr_free(A), ulam_csr_free(B);
    }
    static const struct {
        long line;
        const char *text;
        int status;
    } bad[] = {{5000, "12 x 0.5", ULAM_ESYNTAX},      {20000, "1 3001 0.5", ULAM_EINDEX},
               {12345, "7 7 nan", ULAM_ENONFINITE},   {23999, "1 2 0.5 9", ULAM_ESYNTAX},
               {7, "0 1 1", ULAM_EINDEX},             {18000, "% now a comment: one entry too few", ULAM_ETOOFEW},
               {9000, "1 1 1e999", ULAM_ENONFINITE}, {24100, "5 5 1", ULAM_ETOOMANY}};
    for (size_t c = 0; c < sizeof bad / sizeof bad[0]; c++) {
        if (!test_case((long)c)) continue;
        write_big(path, 3000, 8, 0, bad[c].line, bad[c].text);
        if (bad[c].status == ULAM_ETOOMANY) { /* one entry more than declared, at the end */
            FILE *f = fopen(path, "a");
            fprintf(f, "5 5 1\n");
            fclose(f);
        }
        ulam_csr *A = NULL;
        ulam_error e1, e2;
        int s1 = read_with(path, 1, &A, &e1), s2 = read_with(path, 2, &A, &e2);
        if (s1 != bad[c].status || s2 != s1 || e1.line != e2.line || strcmp(e1.msg, e2.msg))
            fail_msg("bad case %zu: sequential %d at line %ld, parallel %d at line %ld", c, s1, e1.line, s2, e2.line);
        if (bad[c].status != ULAM_ETOOMANY && bad[c].status != ULAM_ETOOFEW && e2.line != bad[c].line)
            fail_msg("bad case %zu: line %ld, expected %ld", c, e2.line, bad[c].line);
        assert_null(A);
    }
    test_case_done();
    remove(path);
}

int main(void)
{
    enum { NBAD = sizeof bad_cases / sizeof bad_cases[0] };
    struct CMUnitTest tests[NBAD + 16];
    size_t k = 0;
    for (size_t i = 0; i < NBAD; i++)
        tests[k++] = (struct CMUnitTest){bad_cases[i].file, test_bad, NULL, NULL, (void *)&bad_cases[i]};
    const struct CMUnitTest good[] = {
        cmocka_unit_test(test_symmetric),       cmocka_unit_test(test_skew),
        cmocka_unit_test(test_pattern_and_integer), cmocka_unit_test(test_duplicates),
        cmocka_unit_test(test_lenient_text),    cmocka_unit_test(test_dense_array),
        cmocka_unit_test(test_vectors),         cmocka_unit_test(test_roundtrip),
        cmocka_unit_test(test_write_refuses_nonfinite), cmocka_unit_test(test_write_unwritable),
        cmocka_unit_test(test_read_from_stream), cmocka_unit_test(test_strtod),
        cmocka_unit_test(test_parallel_read),   cmocka_unit_test(test_duplicates_beyond),
        cmocka_unit_test(test_indented_comment), cmocka_unit_test(test_gzip),
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) tests[k++] = good[i];
    return test_run_("mmio", tests, k);
}
