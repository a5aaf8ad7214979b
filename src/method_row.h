/* A row of the method table: what a row is, the state a choice builds and the helpers a row asks
 * (the exclusion test); the rows (src/method_walks.c, src/method_bidir.c, src/method_outer.c)
 * include it, and the table (src/method.c) above them calls them.  Internal. */
#ifndef ULAM_METHOD_ROW_H
#define ULAM_METHOD_ROW_H

#include "internal.h"
#include "solve.h"

#include <stdio.h>

/* A chosen method ready to run: what the rows keep between their prediction and their run. */
struct ulam_run {
    int method;           /* enum ulam_method_row; -1 before a row is chosen or pinned */
    const ulam_csr *M;
    const double *b;
    ulam_walk_opts o;     /* the options as given (the walks row's run: the choice's) */
    ulam_solver *sv;      /* walks */
    ulam_bidir_opts bo;   /* bidirectional: its options (b's nonzeros in idx, val) */
    int64_t *idx;
    double *val;
    ulam_analysis *an;    /* bidirectional: the analysis whose transpose, push workspace and plan
                             memo it uses (the caller's, borrowed; or its own: own_an) */
    int own_an;
    const ulam_csr *Mt;   /* an's transpose */
    double *bq, *br;      /* bidirectional with a dense b: the push on b's q and residual r (src/bpush.c) */
    ulam_walk_opts bwo;   /* and the walks' options on r (adjoint from the index, offset q_i) */
    ulam_bidir_plan_info bplan; /* and its plan (also in the choice's bidir) */
    int blower;           /* 1: that plan's walks are a lower bound (its pilot does not resolve |x|) */
    int bkiters;          /* with a symmetric M: the CG products of the Krylov start (src/bkrylov.c; 0: none) */
    double bdelta;        /* and the bound on its residual's rounding a visit, */
    double bvisits;       /* times the walks' bound on their expected visits (widens the interval) */
};

/* One query's choice in progress. */
typedef struct ulam__query {
    const ulam_csr *M;
    const double *b;
    const ulam_walk_opts *o;  /* as the caller gave them */
    const ulam_auto_opts *ao; /* the walks' pins */
    const ulam_method_opts *mo; /* the rows' pin and exclusions */
    ulam_choice *ch;
    ulam_run *run;
    const ulam__reach *reach; /* the walks' bounds over every state (an analysis's), or NULL */
    ulam_analysis *an;        /* that analysis (the bidirectional row's transpose, push and plans), or NULL */
} ulam__query;

/* A row of the table (GSL's gsl_root_fsolver_type): its name, what it answers, its applicability
 * test, its cost prediction, its pinned start, its run and its release. */
typedef struct ulam__method_type {
    const char *name;
    int answers; /* ULAM_ANSWERS_ENTRY or ULAM_ANSWERS_ALL */
    /* 1 when the row applies to q (the rows before it decided); else 0 with why filled */
    int (*applies)(const ulam__query *q, int k, char *why, size_t len);
    /* Predict the row's work (q->ch->method[k]; its why says a refusal or a drop), keeping in
     * q->run what its run needs; ULAM_OK or a status that ends the choice */
    int (*predict)(ulam__query *q, int k, ulam_error *err);
    /* Start the row as pinned, from the options alone (no prediction) */
    int (*pin)(ulam__query *q, int k, ulam_error *err);
    /* Run to the end and fill a */
    int (*finish)(ulam_run *r, ulam_answer *a, ulam_error *err);
    /* Free what the run keeps for this row (it lost) */
    void (*release)(ulam_run *r);
} ulam__method_type;

/* The rows (src/method_walks.c, src/method_bidir.c, src/method_outer.c). */
extern const ulam__method_type ulam__method_walks, ulam__method_bidir, ulam__method_richardson,
    ulam__method_gauss_seidel, ulam__method_sequential, ulam__method_mcsa, ulam__method_cg, ulam__method_gmres;

/* 1 when row k is excluded by q's options (why filled: "not considered: excluded"); a row's
 * applicability test asks it (here, below the rows: the table calls the rows, never back). */
static inline int ulam__method_excluded(const ulam__query *q, int k, char *why, size_t len)
{
    if (!(q->mo->exclude & (1u << k))) return 0;
    snprintf(why, len, "not considered: excluded");
    return 1;
}

#endif
