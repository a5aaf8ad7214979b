/* The study's privates (src/study.c), for its module unit (src/study_test.c).  Internal. */
#ifndef ULAM_STUDY_PRIV_H
#define ULAM_STUDY_PRIV_H

#include "internal.h"
#include "ulam_study.h"

/* The exact x_index of (I - M) x = b for a study (index 0-based).  ULAM_OK, ULAM_EINVAL or
 * ULAM_ENOMEM. */
int ulam__study_reference(const ulam_csr *M, const double *b, int64_t index, ulam_study_ref *ref, ulam_error *err);

/* Set o's mode, estimator, roulette and split to method k's on b (n entries; read only in
 * forward mode, for w0 = ||b||_1).  ULAM_OK or ULAM_EINVAL. */
int ulam__study_method_opts(int k, const double *b, int64_t n, ulam_walk_opts *o);

enum { MAXBUDGET = 16, MAXREPEAT = 4096 };

/* A study: its question, the guards' verdicts, each method's screening and every run's record. */
struct ulam_study {
    const ulam_csr *M;
    const double *b;
    int64_t index;
    ulam_study_params p;
    double budget[MAXBUDGET];
    ulam_guard g;
    ulam_study_ref ref;
    ulam_study_screen screen[ULAM_STUDY_METHODS];
    ulam_study_run *run; /* [method][budget][repeat] */
    unsigned char *done;
};

#endif
