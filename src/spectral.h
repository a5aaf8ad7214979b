/* The spectral radius' privates (src/spectral.c): certain verdicts, power iteration from
 * bounds, the length tail's certificate.  Internal. */
#ifndef ULAM_SPECTRAL_H
#define ULAM_SPECTRAL_H

#include "internal.h"

/* Nonzero when [lower, upper] decides a radius' verdict and its warning: wholly below 0.99,
 * wholly at or above 1, or wholly in [0.99, 1) (src/spectral.c; the guards use it). */
int ulam__power_certain(double lower, double upper);

/* Power iteration on diag(left) |A| diag(right) (left, right may be NULL) from the bounds
 * already in *out (the guards' one-pass sums), with out->iterations and out->seconds added
 * to; out keeps the tighter bounds of both (src/spectral.c; ulam__spectral_power starts it
 * from [0, INFINITY]). */
int ulam__power_from(const ulam_csr *A, const double *left, const double *right, const ulam_power_opts *o,
                     ulam_power *out, ulam_error *err);

/* A Collatz-Wielandt certificate |K| v <= u v over the rows in seen (closed under K's moves)
 * from the expected lengths h = (I - |K|)^-1 1, solved roughly by CG or GMRES in at most
 * max_iter products: *u (1: none), *kappa = max h / min h; *matvecs added to; hout (n doubles, may
 * be NULL) gets the certified v = h over seen (NaN elsewhere) when it holds (src/spectral.c). */
int ulam__length_certificate(const ulam_csr *K, const char *seen, int max_iter, double *u, double *kappa,
                             int64_t *matvecs, double *hout);

/* rho(diag(left) |A| diag(right)) by shifted power iteration with Collatz-Wielandt bounds; left
 * and right may be NULL (all ones), opts NULL (ulam_power_defaults()): the guards' iteration
 * started from [0, INFINITY] (src/spectral.c). */
int ulam__spectral_power(const ulam_csr *A, const double *left, const double *right, const ulam_power_opts *opts,
                         ulam_power *out, ulam_error *err);

/* Spectral radius of a linear operator given as y = op(ctx, x), n x n. */
int ulam__spectral_radius_op(int64_t n, void (*op)(const void *ctx, const double *x, double *y),
                            const void *ctx, int positive_start, const ulam_spectral_opts *opts,
                            ulam_radius *out);

#endif
