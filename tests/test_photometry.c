/* Photometry (include/ulam_photometry.h): IES LM-63 and EULUMDAT files written here and read back
 * (values at the table's angles, bilinear between them, every symmetry unfolded to the same
 * intensities, the flux against closed forms), malformed files refused at their line, a point
 * source's direct illuminance on a plane against E = I cos / d^2 (rotated, in millimetres, behind
 * a blocker), the flux a closed box receives against the table's, the EN 12464-1 grid and the
 * uniformity's intervals.  Everything deterministic: the direct light of a point source has no
 * noise. */
#include "testutil.h"
#include "ulam_photometry.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char dir[4096];
static char made[64][64]; /* the files written, removed at the end */
static int nmade;

/* Write text to dir/name; its path. */
static const char *put(const char *name, const char *text)
{
    static char path[8][4200];
    static int k;
    char *p = path[k++ % 8];
    snprintf(p, 4200, "%.4000s/%.64s", dir, name);
    int seen = 0;
    for (int i = 0; i < nmade; i++) seen |= !strcmp(made[i], name);
    if (!seen && nmade < 64) snprintf(made[nmade++], 64, "%s", name);
    FILE *f = fopen(p, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return p;
}

/* A distribution that depends on C and gamma, linear in each between 30-degree steps, so that
 * bilinear interpolation reproduces it wherever both are on the steps' lines: I = 100 + 2 gamma
 * + 50 cos-ish(C) with the C part given at 0, 90, 180, 270 (mirror symmetric about C0-C180 and
 * C90-C270: a quadrant table describes it). */
static double truth(double c, double g)
{
    double cc = fmod(c, 360.0);
    double fold = cc <= 90 ? cc : cc <= 180 ? 180 - cc : cc <= 270 ? cc - 180 : 360 - cc; /* 0 .. 90 */
    return 100.0 + 2.0 * g + 50.0 * (1.0 - fold / 90.0);
}

/* An IES file of truth() on horizontal angles h (n of them) and gamma 0, 30, ..., 180. */
static const char *ies_of(const char *name, const double *h, int n)
{
    static char text[8192];
    int len = snprintf(text, sizeof text, "IESNA:LM-63-2002\n[TEST] symmetric\n[LUMINAIRE] test\nTILT=NONE\n"
                                          "1 -1 1.0 7 %d 1 2 0.1 0.2 0\n1.0 1.0 20\n0 30 60 90 120 150 180\n",
                       n);
    for (int k = 0; k < n; k++) len += snprintf(text + len, sizeof text - (size_t)len, "%g ", h[k]);
    len += snprintf(text + len, sizeof text - (size_t)len, "\n");
    for (int k = 0; k < n; k++) {
        for (int j = 0; j < 7; j++) len += snprintf(text + len, sizeof text - (size_t)len, "%.17g ", truth(h[k], 30.0 * j));
        len += snprintf(text + len, sizeof text - (size_t)len, "\n");
    }
    return put(name, text);
}

/* A table read that must succeed. */
static ulam_gonio *must(const char *path)
{
    ulam_gonio *g = NULL;
    ulam_error err;
    int st = ulam_gonio_read(path, &g, &err);
    if (st) print_error("%s:%ld: %s\n", path, err.line, err.msg);
    assert_int_equal(st, ULAM_OK);
    return g;
}

/* Every IES symmetry gives truth() on the 30-degree lines and the same in between. */
static void test_ies_symmetries(void **state)
{
    (void)state;
    double full[] = {0, 90, 180, 270, 360}, quad[] = {0, 90}, c0[] = {0, 90, 180}, c90[] = {90, 180, 270};
    ulam_gonio *g[4] = {must(ies_of("full.ies", full, 5)), must(ies_of("quad.ies", quad, 2)),
                        must(ies_of("c0.ies", c0, 3)), must(ies_of("c90.ies", c90, 3))};
    for (int k = 0; k < 4; k++) {
        for (double c = 0; c < 360; c += 90)
            for (double gm = 0; gm <= 180; gm += 15) /* on the C lines, linear in gamma: exact */
                assert_close(ulam_gonio_intensity(g[k], c, gm), truth(c, gm), 1e-12);
        for (double c = 0; c < 720; c += 7.5)
            for (double gm = 0; gm <= 180; gm += 11)
                assert_close(ulam_gonio_intensity(g[k], c, gm), ulam_gonio_intensity(g[0], c, gm), 1e-12);
        assert_close(ulam_gonio_flux(g[k]), ulam_gonio_flux(g[0]), 1e-12);
        assert_true(isnan(ulam_gonio_rated_flux(g[k]))); /* lumens -1: absolute photometry */
    }
    /* the flux: trapezoid over C of the exact zones; truth's C part averages 25 over the circle
     * (piecewise linear 50 .. 0 .. 50), the gamma part: int (100 + 2 g) sin g over [0, pi] with g in
     * degrees = 2 (100 + 180) ... computed: int_0^pi (100 + (360/pi) x) sin x dx = 200 + 360 */
    double flux = 2.0 * M_PI * (200.0 + 360.0 + 25.0 * 2.0);
    assert_close(ulam_gonio_flux(g[0]), flux, 1e-12);
    int nc, ng;
    ulam_gonio_size(g[1], &nc, &ng);
    assert_int_equal(nc, 4), assert_int_equal(ng, 7);
    for (int k = 0; k < 4; k++) ulam_gonio_free(g[k]);
}

/* The EULUMDAT file of truth() (cd/klm x flux / 1000) with symmetry isym: the planes it stores. */
static const char *ldt_of(const char *name, int isym, double lamp_flux)
{
    static char text[16384];
    int mc = 4, ng = 7;
    int mc1 = isym == 3 ? 3 * mc / 4 + 1 : 1, mc2 = isym == 0 ? mc : isym == 1 ? 1 : isym == 2 ? mc / 2 + 1
                                                                  : isym == 4 ? mc / 4 + 1 : mc1 + mc / 2;
    int len = snprintf(text, sizeof text,
                       "test company\n1\n%d\n%d\n90\n%d\n30\nreport\nluminaire\nnumber\nfile.ldt\ndate\n"
                       "600\n600\n80\n580\n580\n0\n0\n0\n0\n100\n85\n1.0\n0\n1\n2\nT5 28W\n%g\n3000K\n1B\n62\n",
                       isym, mc, ng, lamp_flux);
    for (int k = 0; k < 10; k++) len += snprintf(text + len, sizeof text - (size_t)len, "0.5\n");
    for (int k = 0; k < mc; k++) len += snprintf(text + len, sizeof text - (size_t)len, "%d\n", 90 * k);
    for (int k = 0; k < ng; k++) len += snprintf(text + len, sizeof text - (size_t)len, "%d\n", 30 * k);
    for (int p = mc1; p <= mc2; p++)
        for (int k = 0; k < ng; k++)
            len += snprintf(text + len, sizeof text - (size_t)len, "%.17g\n",
                            truth(90.0 * ((p - 1) % mc), 30.0 * k) * 1000.0 / lamp_flux);
    return put(name, text);
}

/* EULUMDAT's symmetries 0, 2, 3, 4 give the IES table's intensities; symmetry 1 the C0 plane's. */
static void test_ldt_symmetries(void **state)
{
    (void)state;
    double full[] = {0, 90, 180, 270, 360};
    ulam_gonio *ref = must(ies_of("ref.ies", full, 5));
    for (int isym = 0; isym <= 4; isym++) {
        char name[32];
        snprintf(name, sizeof name, "sym%d.ldt", isym);
        ulam_gonio *g = must(ldt_of(name, isym, 2500.0));
        assert_close(ulam_gonio_rated_flux(g), 2500.0, 0);
        for (double c = 0; c < 360; c += 7.5)
            for (double gm = 0; gm <= 180; gm += 11)
                assert_close(ulam_gonio_intensity(g, c, gm),
                             isym == 1 ? truth(0, gm) : ulam_gonio_intensity(ref, c, gm), 1e-9);
        ulam_gonio_free(g);
    }
    ulam_gonio_free(ref);
}

/* A Lambertian emitter's table (I0 cos gamma, 0.5-degree steps) has flux pi I0 to the chord error. */
static void test_flux_lambertian(void **state)
{
    (void)state;
    char *text = malloc(1 << 16);
    int len = sprintf(text, "IESNA91\nTILT=NONE\n1 1000 1 361 1 1 2 0 0 0\n1 1 10\n");
    for (int j = 0; j <= 360; j++) len += sprintf(text + len, "%g%s", 0.5 * j, j % 10 == 9 ? "\n" : " ");
    len += sprintf(text + len, "\n0\n");
    for (int j = 0; j <= 360; j++)
        len += sprintf(text + len, "%.17g\n", j <= 180 ? 1000.0 * cos(0.5 * j * M_PI / 180.0) : 0.0);
    ulam_gonio *g = must(put("lambert.ies", text));
    free(text);
    /* the chord of cos under-reads by about h^2 / 12 of the curvature: 2e-5 relative at 0.5 degree */
    assert_close(ulam_gonio_flux(g) / (1000.0 * M_PI), 1.0, 3e-5);
    assert_true(ulam_gonio_flux(g) < 1000.0 * M_PI);
    assert_close(ulam_gonio_rated_flux(g), 1000.0, 0);
    ulam_gonio_free(g);
}

/* IES: TILT=INCLUDE's block read past, commas as separators, numbers split across lines, the
 * ballast and ballast-lamp factors applied; EULUMDAT: a decimal comma and CR LF. */
static void test_variants(void **state)
{
    (void)state;
    ulam_gonio *g = must(put("tilt.ies", "IESNA:LM-63-2002\n[TEST] tilt\nTILT=INCLUDE\n1\n3\n0 45 90\n1.0 0.95 0.9\n"
                                         "2,-1,2.0,3,1,1,2,0,0,0\n0.5 0.8\n40\n0 90\n180\n0\n10 20\n 30\n"));
    assert_close(ulam_gonio_intensity(g, 0, 0), 10 * 2.0 * 0.5 * 0.8, 1e-12);
    assert_close(ulam_gonio_intensity(g, 123, 45), 15 * 0.8, 1e-12);
    assert_close(ulam_gonio_intensity(g, 0, 180), 30 * 0.8, 1e-12);
    assert_true(isnan(ulam_gonio_rated_flux(g)));
    ulam_gonio_free(g);
    g = must(put("comma.ldt", "x\r\n1\r\n1\r\n4\r\n90\r\n2\r\n90\r\nr\r\nn\r\nn\r\nf\r\nd\r\n"
                              "1\r\n1\r\n1\r\n1\r\n1\r\n0\r\n0\r\n0\r\n0\r\n100\r\n80,5\r\n1,5\r\n0\r\n"
                              "1\r\n1\r\nLED\r\n2000\r\n4000K\r\n1A\r\n20\r\n"
                              "0,5\r\n0,5\r\n0,5\r\n0,5\r\n0,5\r\n0,5\r\n0,5\r\n0,5\r\n0,5\r\n0,5\r\n"
                              "0\r\n90\r\n180\r\n270\r\n0\r\n90\r\n300,5\r\n100\r\n"));
    /* cd/klm x conversion factor 1.5 x 2000 lm / 1000 */
    assert_close(ulam_gonio_intensity(g, 77, 0), 300.5 * 1.5 * 2.0, 1e-9);
    assert_close(ulam_gonio_intensity(g, 200, 45), 0.5 * (300.5 + 100) * 3.0, 1e-9);
    assert_close(ulam_gonio_rated_flux(g), 2000, 0);
    ulam_gonio_free(g);
}

/* A malformed file: its status and line, and a message naming what was expected. */
static void refused(const char *name, const char *text, int status, long line, const char *what)
{
    ulam_gonio *g = NULL;
    ulam_error err;
    int st = ulam_gonio_read(put(name, text), &g, &err);
    if (st != status || err.line != line || !strstr(err.msg, what))
        print_error("%s: status %d line %ld '%s'; expected %d line %ld '%s'\n", name, st, err.line, err.msg, status,
                    line, what);
    assert_int_equal(st, status);
    assert_int_equal(err.line, line);
    assert_non_null(strstr(err.msg, what));
    assert_null(g);
}

/* Malformed IES and EULUMDAT files are refused with their line. */
static void test_refused(void **state)
{
    (void)state;
    const char *head = "IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n";
    char t[1024];
    refused("notilt.ies", "IESNA:LM-63-2002\n[TEST] x\n1 2 3\n", ULAM_ESYNTAX, 3, "TILT=");
    snprintf(t, sizeof t, "%s1 1000 1 0 1 1 2 0 0 0\n1 1 10\n", head);
    refused("nv0.ies", t, ULAM_ERANGE, 4, "number of vertical angles");
    snprintf(t, sizeof t, "%s1 1000 1 3 99999 1 2 0 0 0\n", head);
    refused("nhbig.ies", t, ULAM_ERANGE, 4, "number of horizontal angles, an integer from 1 to 3601");
    snprintf(t, sizeof t, "%s1 1000 1 3 1 2 2 0 0 0\n1 1 10\n0 90 180\n0\n1 2 3\n", head);
    refused("typeb.ies", t, ULAM_EUNSUPPORTED, 4, "type C");
    snprintf(t, sizeof t, "%s1 1000 1 3 1 1 2 0 0 0\n1 1 10\n0 90 180\n0\n1 x 3\n", head);
    refused("word.ies", t, ULAM_ESYNTAX, 8, "a candela value");
    snprintf(t, sizeof t, "%s1 1000 1 3 1 1 2 0 0 0\n1 1 10\n0 90 180\n0\n1\n-2 3\n", head);
    refused("negative.ies", t, ULAM_ERANGE, 9, "a candela value at least 0");
    snprintf(t, sizeof t, "%s1 1000 1 3 1 1 2 0 0 0\n1 1 10\n0 90 180\n0\n1 2\n", head);
    refused("short.ies", t, ULAM_ESYNTAX, 9, "end of the file");
    snprintf(t, sizeof t, "%s1 1000 1 3 1 1 2 0 0 0\n1 1 10\n0 90 180\n0\n1 2 3\n4\n", head);
    refused("extra.ies", t, ULAM_ESYNTAX, 9, "the end of the file after");
    snprintf(t, sizeof t, "%s1 1000 1 3 1 1 2 0 0 0\n1 1 10\n0 100 90\n0\n1 2 3\n", head);
    refused("order.ies", t, ULAM_ESYNTAX, 6, "ascending");
    snprintf(t, sizeof t, "%s1 1000 1 3 2 1 2 0 0 0\n1 1 10\n0 90 180\n0 45\n1 2 3\n1 2 3\n", head);
    refused("hsym.ies", t, ULAM_ESYNTAX, 7, "type C horizontal angles");
    refused("tiltfile.ies", "IESNA:LM-63-2002\nTILT=lamp.tlt\n", ULAM_EUNSUPPORTED, 2, "TILT=NONE or TILT=INCLUDE");
    snprintf(t, sizeof t, "%s1 1000 0 3 1 1 2 0 0 0\n", head);
    refused("mult0.ies", t, ULAM_ERANGE, 4, "the candela multiplier above 0");
    /* EULUMDAT: a symmetry past 4, Mc not a multiple of 4 with symmetry 4, a truncated table */
    refused("isym.ldt", "x\n1\n5\n", ULAM_ERANGE, 3, "symmetry indicator Isym");
    refused("mc.ldt", "x\n1\n4\n6\n60\n7\n30\n", ULAM_ERANGE, 4, "Mc a multiple of 4");
    const char *ok = ldt_of("whole.ldt", 4, 1000.0);
    FILE *f = fopen(ok, "r");
    char *all = calloc(1, 1 << 14);
    size_t n = fread(all, 1, (1 << 14) - 1, f);
    fclose(f);
    all[n - 10] = 0; /* cut inside the intensities */
    long lines = 0;
    for (size_t k = 0; k < n - 10; k++) lines += all[k] == '\n';
    refused("cut.ldt", all, ULAM_ESYNTAX, lines + 2, "an intensity in cd/klm (line 30), got the end of the file");
    all[0] = 0;
    refused("empty.ldt", all, ULAM_ESYNTAX, 1, "the identification");
    free(all);
}

/* A scene: a 4 x 4 black floor at y = 0 facing up, made of four patches, with (blocker) a small black
 * square at y = 1 over (1, 1) facing up; in scene units of s. */
static ulam_tracer *floor_scene(double s, int blocker, ulam_scene **sc)
{
    char obj[1024];
    snprintf(obj, sizeof obj,
             "mtllib floor.mtl\nv %g 0 %g\nv 0 0 %g\nv %g 0 %g\nv %g 0 0\nv 0 0 0\nv %g 0 0\nv %g 0 %g\nv 0 0 %g\n"
             "v %g 0 %g\nusemtl black\nf 5 4 1 2\nf 6 5 2 3\nf 8 7 4 5\nf 9 8 5 6\n%s",
             -2 * s, -2 * s, -2 * s, 2 * s, -2 * s, -2 * s, 2 * s, -2 * s, 2 * s, 2 * s, 2 * s, 2 * s,
             blocker ? "" : "");
    if (blocker) {
        char more[512];
        snprintf(more, sizeof more, "v %g %g %g\nv %g %g %g\nv %g %g %g\nv %g %g %g\nf -1 -2 -3 -4\n", 0.9 * s, s,
                 0.9 * s, 1.1 * s, s, 0.9 * s, 1.1 * s, s, 1.1 * s, 0.9 * s, s, 1.1 * s);
        strcat(obj, more);
    }
    put("floor.mtl", "newmtl black\nKd 0 0 0\n");
    const char *path = put("floor.obj", obj);
    ulam_error err;
    int st = ulam_scene_read_obj(path, sc, &err);
    if (st) print_error("%s:%ld: %s\n", path, err.line, err.msg);
    assert_int_equal(st, ULAM_OK);
    ulam_tracer *t = NULL;
    assert_int_equal(ulam_tracer_alloc(*sc, &t, NULL), ULAM_OK);
    return t;
}

/* A point source's direct illuminance on a plane is I(toward x) cos theta / d^2: the table of
 * truth(), aimed straight down and turned (C0 along +z, so C = 90 lies along -x... computed here
 * from the geometry), in metres and in millimetres; a blocker's shadow is dark. */
static void test_point_source(void **state)
{
    (void)state;
    double full[] = {0, 90, 180, 270, 360};
    ulam_gonio *g = must(ies_of("pt.ies", full, 5));
    for (int mm = 0; mm < 2; mm++) {
        double s = mm ? 1000.0 : 1.0, m = mm ? 0.001 : 1.0; /* scene units a metre, metres a unit */
        ulam_scene *sc = NULL;
        ulam_tracer *t = floor_scene(s, 0, &sc);
        ulam_luminaire l = ulam_luminaire_defaults();
        l.gonio = g, l.pos[1] = 2.0 * s, l.c0[0] = 0, l.c0[2] = 1.0, l.scale = 0.8;
        double n[3] = {0, 1, 0};
        int checked = 0;
        for (int i = -6; i <= 6; i++)
            for (int k = -6; k <= 6; k++) {
                double x = 0.3 * i, z = 0.3 * k + (k == 0 ? 0.0 : 0.01), X[3] = {x * s, 0, z * s}, d2 = x * x + 4 + z * z, cosv = 2 / sqrt(d2);
                /* in the luminaire's frame: nadir -y, C0 +z, C90 = up x C0 = (0,1,0) x (0,0,1) = +x */
                double gm = acos(cosv) * 180 / M_PI, c = atan2(x, z) * 180 / M_PI;
                double I = 0.8 * ulam_gonio_intensity(g, c, gm);
                double E = ulam_luminaire_illuminance(t, &l, 1, m, X, n, ulam_scene_locate(sc, X, 1e-6));
                assert_close(E, I * cosv / d2, 1e-12);
                if (fabs(fmod(fabs(c), 90.0)) < 1e-9) { /* on a C line: truth itself */
                    assert_close(E, 0.8 * truth(c < 0 ? c + 360 : c, gm) * cosv / d2, 1e-9);
                    checked++;
                }
            }
        assert_true(checked >= 8);
        /* straight below: I(gamma 0) / h^2 = (100 + 50) 0.8 / 4 */
        double X0[3] = {0, 0, 1e-9 * s}; /* C = 0 (the table depends on C even at the pole) */
        assert_close(ulam_luminaire_illuminance(t, &l, 1, m, X0, n, -1), 0.8 * 150.0 / 4.0, 1e-7);
        ulam_tracer_free(t), ulam_scene_free(sc);
    }
    /* the blocker at y = 1 over (1, 1) shadows (2, 2) - (2 - 1) ... the point (2 * 0.95, 0, 2 * 0.95)
     * seen from (0, 2, 0) passes y = 1 at (0.95, 0.95): inside it; (1.9, 0, 1.5) passes (0.95, 0.75): not */
    ulam_scene *sc = NULL;
    ulam_tracer *t = floor_scene(1.0, 1, &sc);
    ulam_luminaire l = ulam_luminaire_defaults();
    l.gonio = g, l.pos[1] = 2.0;
    double n[3] = {0, 1, 0}, in[3] = {1.9, 0, 1.9}, out[3] = {1.9, 0, 1.5};
    assert_true(ulam_luminaire_illuminance(t, &l, 1, 1.0, in, n, 3) == 0.0);
    assert_true(ulam_luminaire_illuminance(t, &l, 1, 1.0, out, n, 3) > 0.0);
    /* patch means: the blocker's top face sees the lamp (facing up), the floor patch under it is part dark */
    double *H = calloc((size_t)sc->npatches, sizeof *H);
    assert_int_equal(ulam_luminaire_patch_illuminance(t, &l, 1, 1.0, 8, 2, H, NULL), ULAM_OK);
    assert_true(H[4] > H[3]);
    double *H1 = calloc((size_t)sc->npatches, sizeof *H1); /* one thread: the same bits */
    assert_int_equal(ulam_luminaire_patch_illuminance(t, &l, 1, 1.0, 8, 1, H1, NULL), ULAM_OK);
    assert_memory_equal(H, H1, (size_t)sc->npatches * sizeof *H);
    free(H1);
    l.nadir[0] = l.nadir[1] = l.nadir[2] = 0; /* no frame */
    assert_true(isnan(ulam_luminaire_illuminance(t, &l, 1, 1.0, in, n, 3)));
    assert_int_equal(ulam_luminaire_patch_illuminance(t, &l, 1, 1.0, 8, 2, H, NULL), ULAM_EINVAL);
    free(H);
    ulam_tracer_free(t), ulam_scene_free(sc);
    ulam_gonio_free(g);
}

/* A closed unit box around an isotropic source receives its whole flux: sum_p A_p H_p = 4 pi I,
 * to the midpoint rule's error (falling as q^-2). */
static void test_box_flux(void **state)
{
    (void)state;
    ulam_gonio *g = must(put("iso.ies", "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 180\n0\n"
                                        "100 100\n"));
    assert_close(ulam_gonio_flux(g), 400.0 * M_PI, 1e-12);
    ulam_scene *sc = NULL;
    ulam_error err;
    assert_int_equal(ulam_scene_read_obj(src_path("examples/scenes/cube.obj"), &sc, &err), ULAM_OK);
    ulam_scene *fine = NULL;
    assert_int_equal(ulam_scene_subdivide(sc, 0.25, &fine), ULAM_OK);
    ulam_tracer *t = NULL;
    assert_int_equal(ulam_tracer_alloc(fine, &t, NULL), ULAM_OK);
    ulam_luminaire l = ulam_luminaire_defaults();
    l.gonio = g, l.pos[0] = l.pos[1] = l.pos[2] = 0.5;
    double *H = calloc((size_t)fine->npatches, sizeof *H), err_q[2];
    for (int k = 0; k < 2; k++) {
        assert_int_equal(ulam_luminaire_patch_illuminance(t, &l, 1, 1.0, k ? 16 : 4, k + 1, H, NULL), ULAM_OK);
        double flux = 0.0;
        for (int64_t p = 0; p < fine->npatches; p++) flux += fine->area[p] * H[p];
        err_q[k] = fabs(flux / (400.0 * M_PI) - 1.0);
    }
    assert_true(err_q[1] < 1e-3);
    assert_true(err_q[1] < err_q[0] / 8); /* second order: 16 q^-2 would be 16 */
    free(H);
    ulam_tracer_free(t), ulam_scene_free(fine), ulam_scene_free(sc), ulam_gonio_free(g);
}

/* The EN 12464-1 grid: p = 0.2 x 5^log10(d), the 0.5 m band, units. */
static void test_en12464(void **state)
{
    (void)state;
    assert_close(ulam_en12464_spacing(1.0), 0.2, 1e-15);
    assert_close(ulam_en12464_spacing(10.0), 1.0, 1e-15);
    assert_close(ulam_en12464_spacing(100.0), 5.0, 1e-13);
    assert_close(ulam_en12464_spacing(1e4), 10.0, 0); /* capped */
    /* a 6 x 4 m room at 0.8 m (y up), in millimetres: 5 x 3 m left, d = 5, p = 0.2 x 5^0.69897 = 0.616 m:
     * ceil(5 / 0.616) = 9, ceil(3 / 0.616) = 5 */
    double c0[3] = {0, 800, 0}, c1[3] = {6000, 800, 4000};
    ulam_rad_grid g;
    assert_int_equal(ulam_rad_grid_en12464(c0, c1, 0.001, 0.5, &g, NULL), ULAM_OK);
    assert_int_equal(g.nu, 9), assert_int_equal(g.nv, 5);
    assert_close(g.origin[0], 500, 1e-9), assert_close(g.origin[1], 800, 0), assert_close(g.origin[2], 500, 1e-9);
    assert_close(g.u[0], 5000, 1e-9), assert_close(g.v[2], 3000, 1e-9);
    assert_close(g.normal[1], 1, 0);
    double x[3];
    ulam_rad_grid_point(&g, 0, 0, x);
    assert_close(x[0], 500 + 5000 / 18.0, 1e-9);
    /* a room no wider than the band: refused */
    double m0[3] = {0, 0.8, 0}, m1[3] = {0.9, 0.8, 4};
    ulam_error err;
    assert_int_equal(ulam_rad_grid_en12464(m0, m1, 1.0, 0.5, &g, &err), ULAM_EINVAL);
    assert_non_null(strstr(err.msg, "wall band"));
}

/* The uniformity's intervals: exact points give exact statistics; noisy ones hold together. */
static void test_uniformity(void **state)
{
    (void)state;
    double E[4] = {100, 200, 300, 400}, se0[4] = {0}, se[4] = {1, 2, 3, 4};
    ulam_uniformity u;
    assert_int_equal(ulam_uniformity_compute(E, se0, 4, 0.95, &u), ULAM_OK);
    assert_close(u.mean, 250, 0), assert_close(u.min, 100, 0), assert_close(u.max, 400, 0);
    assert_close(u.u0, 0.4, 1e-15), assert_close(u.u0_lo, 0.4, 1e-15), assert_close(u.u0_hi, 0.4, 1e-15);
    assert_int_equal(ulam_uniformity_compute(E, se, 4, 0.95, &u), ULAM_OK);
    double z = (u.min_hi - 100.0) / 1.0; /* Bonferroni: 1 - 0.05 / 8 quantile */
    assert_close(z, 2.4977054, 1e-6);
    assert_close(u.u0_lo, (100 - z) / (250 + 2.5 * z), 1e-12);
    assert_close(u.u0_hi, (100 + z) / (250 - 2.5 * z), 1e-12);
    assert_close(u.max_lo, 400 - 4 * z, 1e-12);
    se[0] = -1;
    assert_int_equal(ulam_uniformity_compute(E, se, 4, 0.95, &u), ULAM_EINVAL);
    assert_int_equal(ulam_uniformity_compute(E, se0, 0, 0.95, &u), ULAM_EINVAL);
    /* coverage: 400 grids of 20 points with normal noise, each interval holding at 95% together */
    ulam_rng r;
    ulam_rng_seed(&r, 7, 0);
    int held = 0, runs = 400;
    for (int k = 0; k < runs; k++) {
        double e[20], s[20], truthv[20], mean = 0, mn = INFINITY;
        for (int i = 0; i < 20; i++) {
            truthv[i] = 100 + 10 * i, s[i] = 5;
            double u1 = ulam_rng_uniform(&r), u2 = ulam_rng_uniform(&r);
            e[i] = truthv[i] + s[i] * sqrt(-2 * log(1 - u1)) * cos(2 * M_PI * u2);
            mean += truthv[i] / 20, mn = fmin(mn, truthv[i]);
        }
        assert_int_equal(ulam_uniformity_compute(e, s, 20, 0.95, &u), ULAM_OK);
        held += u.u0_lo <= mn / mean && mn / mean <= u.u0_hi && u.mean_lo <= mean && mean <= u.mean_hi;
    }
    /* at least 95%: the count's 99.9% lower binomial bound for p = 0.95, n = 400 is about 365 */
    assert_true(held >= 365);
}

int main(void)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/ulam_photometry_XXXXXX", tmp && *tmp ? tmp : P_tmpdir);
    assert_non_null(mkdtemp(dir));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ies_symmetries), cmocka_unit_test(test_ldt_symmetries),
        cmocka_unit_test(test_flux_lambertian), cmocka_unit_test(test_refused), cmocka_unit_test(test_variants),
        cmocka_unit_test(test_point_source),    cmocka_unit_test(test_box_flux),
        cmocka_unit_test(test_en12464),         cmocka_unit_test(test_uniformity),
    };
    int rc = test_run(tests);
    for (int i = 0; i < nmade; i++) {
        char path[4200];
        snprintf(path, sizeof path, "%.4000s/%.64s", dir, made[i]);
        unlink(path);
    }
    rmdir(dir);
    return rc;
}
