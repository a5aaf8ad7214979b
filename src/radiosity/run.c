/* One radiosity run (ulam_radiosity_run.h): the scene read, subdivided or adapted within
 * --max-mem, lit, then the walks, solves and point queries the options ask for.  What it finds
 * the reports (run_report.c) print; warnings and error lines go to the caller's log. */
#include "runstate.h"

#include "rad.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

/* The command's defaults (ulam_radiosity_run.h). */
ulam_rad_run_opts ulam_rad_run_defaults(void)
{
    ulam_rad_run_opts a = {.est = -1, .mis = -1, .samples = 4, .coverage = 0.25, .ff_rays = 1000, .width = 512,
                           .height = 512, .max_mem = (size_t)4 << 30, .o = ulam_walk_defaults()};
    a.o.stop.max_walks = 0;
    return a;
}

/* ulam__run_error for a status and what was expected. */
static int fail(const args *a, const char *file, int status, const char *msg)
{
    ulam_error err = {.status = status};
    snprintf(err.msg, sizeof err.msg, "%s", msg);
    return ulam__run_error(a, file, &err);
}

/* The radiosity options of the walk options (mode, estimator, patch, stopping rules, seed,
 * threads, processes). */
ulam_rad_opts ulam__run_rad_opts(const ulam_walk_opts *o)
{
    ulam_rad_opts r = ulam_rad_defaults();
    r.mode = o->mode, r.estimator = o->estimator, r.index = o->query.index, r.stop = o->stop, r.exec = o->exec;
    return r;
}

/* Nonzero when every channel of v is exactly 0 with a zero standard error se. */
int ulam__run_zero(const double v[3], const double se[3])
{
    for (int c = 0; c < 3; c++)
        if (v[c] != 0.0 || se[c] != 0.0) return 0;
    return 1;
}

/* The camera asked for, or the one framing the scene. */
ulam_camera ulam__run_camera(const args *a, const ulam_scene *s)
{
    return a->camera_given ? a->cam : ulam_camera_frame(s, a->width, a->height);
}

/* Catch or release the interrupt (the caller's hook). */
static void interrupt_on(const args *a, int on)
{
    if (a->catch_interrupt) a->catch_interrupt(on);
}

/* Bytes as GiB, MiB or KiB for a message. */
static void human(double b, char *out, size_t len)
{
    const char *u[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
    int k = 0;
    while (b >= 1024 && k < 4) b /= 1024, k++;
    snprintf(out, len, k ? "%.3g %s" : "%.0f %s", b, u[k]);
}

/* What the run will hold at once, estimated from the scene and the options before any ray is
 * cast: the ray tracer (Embree's structure, about 200 bytes a triangle), F (12 bytes a nonzero,
 * at most npatches x min(ff rays, npatches); a matrix walk adds each channel's M and kernel),
 * the dense LAPACK solve (ulam_direct_bytes; twice for every patch's error bar), shooting's
 * tallies, pictures and grids.  *what gets the breakdown. */
static double need_counts(const args *a, double n, double tri, double nverts, char *what, size_t len)
{
    double tracer = 208.0 * tri + 16.0 * nverts, ff = 0, dense = 0, walks = 0, pic = 0;
    int threads = a->o.exec.threads > 0 ? a->o.exec.threads : 2;
    int forms = (a->direct || a->check || a->matrix_walk) && !a->nat && !a->grid;
    if (forms) ff = 12.0 * n * fmin((double)a->ff_rays, n) + 8.0 * (n + 1);
    if (forms && a->matrix_walk) ff *= 3; /* F, one channel's M and the walk's kernel rows */
    if (forms && (a->direct || a->check)) dense = (double)ulam_direct_bytes((int64_t)n);
    if (forms && (a->direct || a->check) && (a->out || a->all)) dense *= 2; /* every patch's error: G whole */
    if (a->o.mode == ULAM_FORWARD) /* per patch: sums (48), the sequences and round sums (360), scratch a thread */
        walks = n * (408.0 + 29.0 * threads) + 32.0 * 256 * 32 * 64;
    if (a->image) pic = (double)a->width * a->height * 11.0 + (a->view ? 8.0 * n : 0.0);
    if (a->nat || a->grid) walks = (double)(a->nat + (a->grid ? (int64_t)a->g.nu * a->g.nv : 0)) * sizeof(ulam_rad_point);
    char h[5][32];
    human(tracer, h[0], 32), human(ff, h[1], 32), human(dense, h[2], 32), human(walks, h[3], 32), human(pic, h[4], 32);
    snprintf(what, len, "ray tracer %s (%.0f triangles), form factors %s (%.0f patches x %lld rays), dense "
                        "matrices %s, walks %s, pictures %s", h[0], tri, h[1], n, (long long)a->ff_rays, h[2], h[3], h[4]);
    return tracer + ff + dense + walks + pic;
}

/* need_counts for scene s. */
static double need_bytes(const args *a, const ulam_scene *s, char *what, size_t len)
{
    return need_counts(a, (double)s->npatches, (double)(s->start[s->npatches] - 2 * s->npatches), (double)s->nverts,
                       what, len);
}

/* The most patches --mesh-target may make: --max-patches (default 100000), and no more than
 * --max-mem holds by need_counts (an adaptive mesh of quads: 2 triangles and about 2 vertices
 * a patch). */
static int64_t patch_cap(const args *a, const ulam_scene *s)
{
    int64_t lo = s->npatches, hi = a->max_patches ? a->max_patches : 100000;
    char what[512];
    if (hi < lo) return lo;
    while (lo < hi) { /* the largest n in [lo, hi] that fits (lo when none does: the check below refuses) */
        int64_t mid = lo + (hi - lo + 1) / 2;
        if (need_counts(a, (double)mid, 2.0 * (double)mid, 2.0 * (double)mid, what, sizeof what) <= (double)a->max_mem)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

/* The scene, subdivided if asked (counted first: --max-mem refuses a mesh before it is built);
 * ULAM_OK or a status (written). */
static int load_scene(const args *a, ulam_scene **out, int64_t *faces)
{
    ulam_error err;
    ulam_scene *s = NULL;
    ulam_mtl_note *notes = NULL;
    int64_t nnotes = 0;
    if (ulam_scene_read_obj_notes(a->scene, &s, &notes, &nnotes, &err)) return ulam__run_error(a, a->scene, &err);
    for (int64_t i = 0; i < nnotes && a->rank == 0; i++) { /* one warning a material */
        int first = 1;
        for (int64_t k = 0; k < i && first; k++) first = strcmp(notes[k].material, notes[i].material) != 0;
        if (!first) continue;
        ulam__run_log(a, "ulam radiosity: warning: %s: material '%s' is rendered matte (Kd, Ke): ignored", notes[i].file,
                      notes[i].material);
        for (int64_t k = i; k < nnotes; k++)
            if (!strcmp(notes[k].material, notes[i].material))
                ulam__run_log(a, "%s %s (%s:%ld)", k == i ? "" : ",", notes[k].keyword, notes[k].file, notes[k].line);
        ulam__run_log(a, "\n");
    }
    ulam_mtl_notes_free(notes, nnotes);
    *faces = s->nfaces;
    if (a->subdivide > 0) {
        double np = 0, nv = 0, tri = 0, bytes = 0, need;
        char what[512], h[3][32];
        int status = ulam_scene_subdivide_plan(s, a->subdivide, &np, &nv, &tri, &bytes);
        need = bytes + (a->list ? 0.0 : need_counts(a, np, tri, nv, what, sizeof what));
        if ((status == ULAM_OK || status == ULAM_EOVERFLOW) && need > (double)a->max_mem) {
            human(need, h[0], 32), human((double)a->max_mem, h[1], 32), human(bytes, h[2], 32);
            ulam__run_log(a, "ulam radiosity: %s: memory limit: --subdivide %g makes %.4g patches (%.4g vertices): "
                             "this run needs about %s, more than --max-mem %s (the patches %s%s%s); refused before "
                             "building them: raise --subdivide or --max-mem\n",
                          a->scene, a->subdivide, np, nv, h[0], h[1], h[2], a->list ? "" : ", ", a->list ? "" : what);
            ulam_scene_free(s);
            return ULAM_EMEMLIMIT;
        }
        ulam_scene *d = NULL;
        status = status ? status : ulam_scene_subdivide(s, a->subdivide, &d);
        ulam_scene_free(s);
        if (status) return fail(a, a->scene, status, "a subdivision that fits in memory");
        s = d;
    }
    *out = s;
    return ULAM_OK;
}

/* --mesh-target: the scene adaptively subdivided (importance from the camera with --image, else
 * the area), *s replaced; ULAM_OK or a status (written). */
static int adapt_scene(const args *a, ulam_scene **s, report *r)
{
    ulam_error err;
    ulam_tracer *t = NULL;
    ulam_scene *d = NULL;
    double *Y = NULL;
    if (ulam_tracer_alloc(*s, &t, &err)) return ulam__run_error(a, a->scene, &err);
    int64_t cap = patch_cap(a, *s), walks = 64 * (*s)->npatches > 65536 ? 64 * (*s)->npatches : 65536;
    r->adapt_cap = cap;
    int rc = 0;
    if (a->image) {
        ulam_camera cam = ulam__run_camera(a, *s);
        if (!(Y = malloc((size_t)(*s)->npatches * sizeof *Y))) rc = fail(a, a->scene, ULAM_ENOMEM, "memory for the importance");
        else if (ulam_rad_importance(t, &cam, a->width, a->height, walks, a->o.exec.seed, Y, &err))
            rc = ulam__run_error(a, a->scene, &err);
        r->view_importance = 1;
    }
    ulam_rad_opts o = ulam__run_rad_opts(&a->o); /* the points: next-event, to half the target or 1024 walks each */
    o.mode = ULAM_ADJOINT, o.estimator = ULAM_RAD_NEXT_EVENT + (a->mis > 0 ? a->mis : 0);
    o.stop.rel_err = a->mesh_target / 2, o.stop.max_walks = 1024; /* --time: the mesh half of what is left, the solve the rest */
    o.stop.max_seconds = a->o.stop.max_seconds > 0 ? ulam__run_time_left(a, a->o.stop.max_seconds) / 2 : 0;
    if (!rc) {
        interrupt_on(a, 1);
        if (ulam_rad_adapt(t, &o, Y, a->mesh_target, cap, &d, &r->adapt, &err)) rc = ulam__run_error(a, a->scene, &err);
        interrupt_on(a, 0);
    }
    free(Y);
    ulam_tracer_free(t);
    if (rc) return rc;
    ulam_scene_free(*s);
    *s = d;
    return ULAM_OK;
}

/* The 0-based patch that --patch names; ULAM_OK or ULAM_RAD_RUN_USAGE (written). */
static int find_patch(const args *a, const ulam_scene *s, const char *arg, int64_t *p)
{
    char *end;
    long long k = strtoll(arg, &end, 10);
    if (end != arg && !*end) {
        if (k >= 1 && k <= s->npatches) return *p = k - 1, ULAM_OK;
        ulam__run_log(a, "ulam radiosity: --patch %s is out of range 1..%lld (see 'ulam radiosity --help')\n", arg, (long long)s->npatches);
        return ULAM_RAD_RUN_USAGE;
    }
    if (ulam_scene_find(s, arg, p) == ULAM_OK) return ULAM_OK;
    ulam__run_log(a, "ulam radiosity: --patch '%s' is neither a patch number nor a label; labels:", arg);
    for (int64_t g = 0; g < s->ngroups; g++) ulam__run_log(a, " %s", s->groups[g]);
    ulam__run_log(a, "\n");
    return ULAM_RAD_RUN_USAGE;
}

/* A 1-based patch number of --patches' item at *str (its digits, then end or '-' or ','), into
 * *k; 0 when the digits are not that. */
static int patch_number(const char *str, const char **end, long long *k)
{
    char *e;
    if (*str < '0' || *str > '9') return 0;
    *k = strtoll(str, &e, 10);
    *end = e;
    return *e == '\0' || *e == '-' || *e == ',';
}

/* Mark want[p] for every patch --patches names (arg: comma-separated labels, numbers K and
 * ranges K-L, 1-based, as --list shows them) and count them; ULAM_OK, ULAM_ENOMEM or
 * ULAM_RAD_RUN_USAGE (written: an empty item, a number out of range, an empty range, an unknown
 * label, or a list that chooses no patch). */
static int find_patches(const args *a, const ulam_scene *s, const char *arg, unsigned char *want, int64_t *count)
{
    int64_t n = s->npatches;
    char *buf = malloc(strlen(arg) + 1);
    if (!buf) return ULAM_ENOMEM;
    strcpy(buf, arg);
    memset(want, 0, (size_t)n);
    int rc = ULAM_OK;
    char *item = buf;
    for (int last = 0; !rc && !last;) {
        char *comma = strchr(item, ',');
        last = !comma;
        if (comma) *comma = '\0';
        const char *end;
        long long lo = 0, hi = 0;
        if (!*item) {
            ulam__run_log(a, "ulam radiosity: --patches: an empty item in '%s' (labels, numbers K and ranges K-L, "
                             "comma-separated)\n", arg);
            rc = ULAM_RAD_RUN_USAGE;
        } else if (patch_number(item, &end, &lo) && (!*end || (patch_number(end + 1, &end, &hi) && !*end))) {
            if (!strchr(item, '-')) hi = lo;
            if (lo < 1 || lo > n || hi < 1 || hi > n) {
                long long bad = lo < 1 || lo > n ? lo : hi;
                if (bad == LLONG_MAX) /* past long long: strtoll's clamp is not what was typed */
                    ulam__run_log(a, "ulam radiosity: --patches: '%s' is out of range 1..%lld (see --list)\n", item,
                                  (long long)n);
                else
                    ulam__run_log(a, "ulam radiosity: --patches: %lld is out of range 1..%lld (in '%s'; see --list)\n",
                                  bad, (long long)n, arg);
                rc = ULAM_RAD_RUN_USAGE;
            } else if (hi < lo) {
                ulam__run_log(a, "ulam radiosity: --patches: the range %s is empty (K-L needs K <= L)\n", item);
                rc = ULAM_RAD_RUN_USAGE;
            }
            for (long long k = lo; !rc && k <= hi; k++) want[k - 1] = 1;
        } else {
            int64_t g = ulam__scene_group(s, item);
            if (g < 0) {
                ulam__run_log(a, "ulam radiosity: --patches: '%s' is neither a patch number, a range K-L nor a label; "
                                 "labels:", item);
                for (int64_t k = 0; k < s->ngroups; k++) ulam__run_log(a, " %s", s->groups[k]);
                ulam__run_log(a, "%s\n", s->ngroups ? "" : " none (the scene has no o or g lines)");
                rc = ULAM_RAD_RUN_USAGE;
            }
            for (int64_t p = 0; !rc && p < n; p++) want[p] |= s->group[p] == (int32_t)g;
        }
        if (comma) item = comma + 1;
    }
    free(buf);
    *count = 0;
    for (int64_t p = 0; !rc && p < n; p++) *count += want[p];
    if (!rc && !*count) {
        ulam__run_log(a, "ulam radiosity: --patches %s chooses no patch\n", arg);
        rc = ULAM_RAD_RUN_USAGE;
    }
    return rc;
}

/* Read, adapt, check, build and light (ulam_radiosity_run.h). */
int ulam_rad_run_alloc(const ulam_rad_run_opts *opts, ulam_rad_run **out)
{
    ulam_rad_run *r = *out = calloc(1, sizeof *r);
    if (!r) return ULAM_ENOMEM;
    r->opts = *opts, r->a = &r->opts, r->r.patch = -1;
    args *a = &r->opts;
    ulam_error err;
    if (a->final && a->matrix_walk) { /* final gathers by rays over a ray-shot pilot: no matrix form */
        ulam__run_log(a, "ulam radiosity: --mode final gathers by rays over a shooting pilot: not with --matrix-walk "
                         "(use --mode shoot --matrix-walk, or drop --matrix-walk)\n");
        return ULAM_RAD_RUN_USAGE;
    }
    if (a->patches && ((!a->final && !a->list) || a->patch || a->image || a->mesh_walks)) { /* before the scene is read */
        ulam__run_log(a, "ulam radiosity: %s\n", a->patch ? "--patches and --patch: one or the other"
                                                : !a->final && !a->list ? "--patches chooses the patches of --mode final (or "
                                                                          "of --list)"
                                                                        : "--patches: not with --image or --mesh-error "
                                                                          "(they need every patch)");
        return ULAM_RAD_RUN_USAGE;
    }
    int rc = load_scene(a, &r->s, &r->r.faces);
    if (rc || (a->mesh_target > 0 && (rc = adapt_scene(a, &r->s, &r->r)))) return rc;
    r->r.adapted = a->mesh_target > 0;
    r->r.s = r->s;
    if (a->patches) {
        if (!(r->want = malloc((size_t)r->s->npatches))) return fail(a, a->scene, ULAM_ENOMEM, "memory for --patches");
        if ((rc = find_patches(a, r->s, a->patches, r->want, &r->nwant)))
            return rc == ULAM_ENOMEM ? fail(a, a->scene, rc, "memory for --patches") : rc;
    }
    if (a->list) return r->listed = 1, ULAM_OK;
    if (a->patch && (rc = find_patch(a, r->s, a->patch, &r->r.patch))) return rc;
    char what[512], h[2][32];
    double need = need_bytes(a, r->s, what, sizeof what);
    if (need > (double)a->max_mem) { /* refused before the first ray */
        human(need, h[0], 32), human((double)a->max_mem, h[1], 32);
        ulam__run_log(a, "ulam radiosity: %s: memory limit: this run needs about %s, more than --max-mem %s (%s); refused "
                         "before any work: raise --max-mem, or ask less (--patch or --at walks need no F)\n",
                      a->scene, h[0], h[1], what);
        return ULAM_EMEMLIMIT;
    }
    a->o.query.index = r->r.patch >= 0 ? r->r.patch : 0;
    if (ulam_tracer_alloc(r->s, &r->t, &err)) return ulam__run_error(a, a->scene, &err);
    int64_t coarse;
    double res = ulam_tracer_resolution(r->t, &coarse);
    if (res > 1e-3 && a->rank == 0)
        ulam__run_log(a, "ulam radiosity: warning: %s: patch %lld is only %.0f float steps across where it lies: ray "
                         "casting resolves it to %.2g of its size (move the scene's parts closer together)\n",
                      a->scene, (long long)coarse + 1, 1.0 / res, res);
    return ulam__run_photo_light(r); /* the luminaires light the patches */
}

/* After the first round: say so when the rel-err rule's minimum walk count (the bound on one
 * walk's score: a bright emitter a walk rarely hits) is out of reach, and name next-event. */
static void rel_err_warning(const args *a, const ulam_rad_result *r)
{
    double limit = a->o.stop.max_walks > 0 && a->o.stop.max_walks < ULAM_REL_ERR_CAP ? (double)a->o.stop.max_walks : 1e8;
    if (!(a->o.stop.rel_err > 0) || !(r->min_walks > limit)) return;
    const char *reach = limit < 1e8 ? "more than --walks" : "out of reach in practice";
    if (a->o.mode == ULAM_FORWARD || a->o.estimator < ULAM_RAD_COLLISION) /* next-event or shooting */
        ulam__run_log(a, "ulam: %s: warning: --rel-err %g: the rule needs about %.3g walks at this estimate before it "
                         "may stop (%s): one walk's certified score range is wide against the estimate\n",
                      a->scene, a->o.stop.rel_err, r->min_walks, reach);
    else
        ulam__run_log(a, "ulam: %s: warning: --rel-err %g: one walk can score up to a bright emitter's radiosity at "
                         "every bounce, so the rule needs about %.3g walks at this estimate before it may stop (%s): "
                         "--estimator next-event samples the emitters directly and has no such tail\n",
                      a->scene, a->o.stop.rel_err, r->min_walks, reach);
}

/* Ascending doubles (qsort). */
static int cmp_double(const void *x, const void *y)
{
    double u = *(const double *)x, v = *(const double *)y;
    return (u > v) - (u < v);
}

/* The median and 90% quantile of half-width / B (each patch's worst channel with B > 0) over the
 * lit patches want chooses (NULL: all) into w->half_rel (NaN when none is lit). */
static int final_quantiles(const ulam_scene *s, const unsigned char *want, walked *w)
{
    double *rel = malloc((size_t)s->npatches * sizeof *rel);
    int64_t m = 0;
    if (!rel) return ULAM_ENOMEM;
    for (int64_t p = 0; p < s->npatches; p++) {
        double worst = -1.0;
        for (int c = 0; c < 3 && (!want || want[p]); c++)
            if (w->all[3 * p + c] > 0) worst = fmax(worst, w->half[3 * p + c] / w->all[3 * p + c]);
        if (worst >= 0) rel[m++] = worst;
    }
    qsort(rel, (size_t)m, sizeof *rel, cmp_double);
    for (int k = 0; k < 2; k++) w->half_rel[k] = m ? rel[(int64_t)ceil((k ? 0.9 : 0.5) * (double)m) - 1] : NAN;
    free(rel);
    return ULAM_OK;
}

/* --mode final (ulam_rad_final_some): every patch, or those --patches chose; ULAM_OK or a status
 * (written). */
static int final_walks(const args *a, const ulam_tracer *t, const unsigned char *want, int64_t np, walked *w)
{
    ulam_error err;
    ulam_rad_opts ro = ulam__run_rad_opts(&a->o);
    ulam_rad_final_info in;
    double *half = w->half = malloc((size_t)np * 3 * sizeof *half);
    w->all = malloc((size_t)np * 3 * sizeof *w->all), w->all_se = malloc((size_t)np * 3 * sizeof *w->all_se);
    if (!half || !w->all || !w->all_se) return fail(a, a->scene, ULAM_ENOMEM, "memory for every patch");
    interrupt_on(a, 1);
    int status = ulam_rad_final_some(t, &ro, 0, a->share > 0 ? a->share : 1.0, want, w->all, w->all_se, half, &in, &err);
    interrupt_on(a, 0);
    if (status) return ulam__run_error(a, a->scene, &err);
    if (final_quantiles(ulam__tracer_scene(t), want, w)) return fail(a, a->scene, ULAM_ENOMEM, "memory for the summary");
    int64_t p = a->o.query.index;
    for (int c = 0; c < 3; c++)
        w->B[c] = w->all[3 * p + c], w->se[c] = w->se_walk[c] = w->all_se[3 * p + c],
        w->ci95[c][0] = fmax(0.0, w->B[c] - half[3 * p + c]), w->ci95[c][1] = w->B[c] + half[3 * p + c];
    w->walks = in.samples, w->steps = in.rays + in.particle_rays, w->seconds = in.seconds, w->threads = in.threads;
    w->interrupted = in.interrupted, w->rel_err_met = in.met, w->scene = in.scene;
    w->whole = a->o.stop.rel_err > 0 && !a->patch;
    memcpy(w->unreached, in.unreached, sizeof w->unreached);
    return ULAM_OK;
}

/* Ray walks (gathering, shooting or --mode final); ULAM_OK or a status (written). */
static int ray_walks(const args *a, const ulam_tracer *t, const unsigned char *want, int64_t np, walked *w)
{
    if (a->final) return final_walks(a, t, want, np, w);
    ulam_rad_solver *sv = NULL;
    ulam_error err;
    ulam_rad_opts ro = ulam__run_rad_opts(&a->o);
    int status = ulam_rad_solver_alloc(t, &ro, &sv, &err);
    if (status) return ulam__run_error(a, a->scene, &err);
    w->whole = a->o.mode == ULAM_FORWARD && a->o.stop.rel_err > 0 && !a->patch; /* the whole scene, not patch 1 */
    if (w->whole) ulam_rad_solver_whole(sv, a->share > 0 ? a->share : 1.0);
    interrupt_on(a, 1);
    if (a->progress) a->progress(a->progress_ctx, &a->o, 0, 0, 0, 0);
    ulam_rad_result r;
    for (int round = 0; !status && !ulam_rad_solver_done(sv); round++) {
        status = ulam_rad_solver_iterate(sv);
        ulam_rad_solver_result(sv, &r);
        if (round == 0) rel_err_warning(a, &r);
        if (a->progress) a->progress(a->progress_ctx, &a->o, 1, r.walks, r.radiosity[0], r.std_error[0]); /* the red channel */
    }
    if (a->progress) a->progress(a->progress_ctx, &a->o, 2, 0, 0, 0);
    interrupt_on(a, 0);
    ulam_rad_solver_result(sv, &r);
    memcpy(w->B, r.radiosity, sizeof w->B);
    memcpy(w->se, r.std_error, sizeof w->se);
    memcpy(w->se_walk, r.std_error, sizeof w->se_walk);
    w->walks = r.walks, w->steps = r.rays, w->seconds = r.seconds, w->threads = r.threads;
    w->interrupted = r.interrupted, w->zero = r.zero, w->cut = r.cut;
    w->rel_err_met = r.rel_err_met, w->min_walks = r.min_walks;
    memcpy(w->ci95, r.ci95, sizeof w->ci95);
    if (!status && a->o.mode == ULAM_FORWARD) {
        w->all = malloc((size_t)np * 3 * sizeof *w->all);
        w->all_se = malloc((size_t)np * 3 * sizeof *w->all_se);
        if (!w->all || !w->all_se) status = ULAM_ENOMEM;
        else ulam_rad_solver_vectors(sv, w->all, w->all_se);
        if (w->whole) ulam_rad_solver_scene(sv, &w->scene, w->unreached, 8);
    }
    ulam_rad_solver_free(sv);
    if (status) ulam__run_log(a, "ulam: %s: error: %s\n", a->scene, ulam_strerror(status));
    return status;
}

/* Walks on the assembled M, one channel at a time (at a patch with --rel-err: to the combined
 * rule of ulam_rad_walk_target, given F's error ff and the direct solution Bd there); ULAM_OK
 * or a status (written). */
static int matrix_walks(const args *a, const ulam_scene *s, const ulam_csr *F, const double *ff, const double *Bd,
                        walked *w)
{
    int64_t n = s->npatches;
    double *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x), *e = malloc((size_t)n * sizeof *e);
    if (a->o.mode == ULAM_FORWARD) {
        w->all = malloc((size_t)n * 3 * sizeof *w->all);
        w->all_se = malloc((size_t)n * 3 * sizeof *w->all_se);
    }
    int status = b && x && e && (a->o.mode == ULAM_ADJOINT || (w->all && w->all_se)) ? ULAM_OK : ULAM_ENOMEM;
    ulam_error err = {.status = status};
    w->rel_err_met = a->o.stop.rel_err > 0 && a->o.mode == ULAM_ADJOINT; /* every channel's rule, F's error within */
    interrupt_on(a, 1);
    for (int c = 0; c < 3 && !status && !(a->o.stop.interrupt && *a->o.stop.interrupt); c++) {
        ulam_csr *M = NULL;
        ulam_solver *sv = NULL;
        ulam_walk_opts o = a->o;
        if (a->o.stop.rel_err > 0 && a->o.mode == ULAM_ADJOINT) {
            o.stop.rel_err = ulam_rad_walk_target(a->o.stop.rel_err, ff ? ff[c] : 0, Bd ? Bd[c] : 0, ff && Bd);
            if (!(o.stop.rel_err > 0)) { /* F's noise alone is past the target: walk to it, say it is not met */
                w->ff_limited[c] = 1;
                o.stop.rel_err = a->o.stop.rel_err;
            }
        }
        if ((status = ulam_rad_system(s, F, c, &M, b)) || (status = ulam_solver_alloc(M, b, &o, &sv, &err))) {
            ulam_csr_free(M);
            break;
        }
        while (!status && !ulam_solver_done(sv)) status = ulam_solver_iterate(sv);
        ulam_walk_result r;
        ulam_solver_result(sv, &r);
        w->B[c] = r.estimate, w->se[c] = w->se_walk[c] = r.std_error;
        w->channel_walks[c] = r.walks;
        w->rel_err_met &= r.rel_err_met && !w->ff_limited[c];
        w->walks += r.walks, w->steps += r.steps, w->seconds += r.seconds, w->cut += r.cut;
        w->threads = r.threads, w->interrupted |= r.interrupted;
        if (!status && w->all) {
            ulam_solver_vectors(sv, x, e);
            for (int64_t i = 0; i < n; i++) w->all[3 * i + c] = x[i], w->all_se[3 * i + c] = e[i];
        }
        ulam_solver_free(sv);
        ulam_csr_free(M);
    }
    interrupt_on(a, 0);
    free(b), free(x), free(e);
    w->zero = a->o.stop.rel_err > 0;
    for (int c = 0; c < 3; c++) w->zero &= w->B[c] == 0 && w->se[c] == 0;
    if (!status) return ULAM_OK;
    err.status = status;
    return ulam__run_error(a, a->scene, &err);
}

/* --view-gather: the seen patches' answers into w->all; ULAM_OK or a status (written). */
static int view_walks(const args *a, const ulam_tracer *t, const ulam_scene *s, walked *w, ulam_view_info *vi)
{
    ulam_camera cam = ulam__run_camera(a, s);
    ulam_error err;
    w->all = malloc((size_t)s->npatches * 3 * sizeof *w->all);
    w->all_se = malloc((size_t)s->npatches * 3 * sizeof *w->all_se);
    if (!w->all || !w->all_se) return fail(a, a->scene, ULAM_ENOMEM, "memory for the solution");
    interrupt_on(a, 1);
    ulam_rad_opts ro = ulam__run_rad_opts(&a->o);
    int status = ulam_view_gather(t, &cam, a->width, a->height, a->coverage, &ro, w->all, w->all_se, vi, &err);
    interrupt_on(a, 0);
    if (status) return ulam__run_error(a, a->scene, &err);
    w->walks = vi->walks, w->steps = vi->rays, w->seconds = vi->seconds, w->cut = vi->cut;
    w->interrupted = vi->interrupted, w->threads = vi->threads;
    return ULAM_OK;
}

/* Form F and, if asked, solve directly; ULAM_OK or a status (written). */
static int form_and_solve(ulam_rad_run *run)
{
    const args *a = run->a;
    const ulam_scene *s = run->s;
    report *r = &run->r;
    ulam_error err;
    double t0 = ulam_now();
    if (ulam_ff_estimate(run->t, a->ff_rays, a->o.exec.seed, a->o.exec.threads, &run->F, &err))
        return ulam__run_error(a, a->scene, &err);
    r->ff_seconds = ulam_now() - t0;
    ulam_ff_report_compute(s, run->F, &r->ff);
    r->F = run->F;
    int need = a->direct || a->check, every = a->out || a->all;
    int for_error = a->matrix_walk && (r->patch >= 0 || (every && a->o.mode == ULAM_FORWARD));
    if (!need && !for_error) return ULAM_OK;
    if (!need && ulam_direct_bytes(s->npatches) > a->max_mem) return ULAM_OK; /* the error bar is then labelled */
    if (!(run->Bd = malloc((size_t)s->npatches * 3 * sizeof *run->Bd)))
        return fail(a, a->scene, ULAM_ENOMEM, "memory for the solution");
    ulam_direct_info info;
    if (ulam_rad_direct(s, run->F, a->max_mem, run->Bd, &info, &err)) return ulam__run_error(a, a->scene, &err);
    r->direct_seconds = info.seconds;
    if (need) r->Bdirect = run->Bd;
    if (r->patch >= 0) {
        if (ulam_rad_direct_error(s, run->F, a->ff_rays, run->Bd, r->patch, a->max_mem, r->direct_se, &err))
            return ulam__run_error(a, a->scene, &err);
        r->ff_se_known = 1;
    }
    if (every && (a->direct || a->matrix_walk || a->check)) { /* every patch's error from F's noise */
        if (!(r->direct_se_all = malloc((size_t)s->npatches * 3 * sizeof *r->direct_se_all)))
            return fail(a, a->scene, ULAM_ENOMEM, "memory for the standard errors");
        int st = ulam_rad_direct_errors(s, run->F, a->ff_rays, run->Bd, a->max_mem, r->direct_se_all, &err);
        if (st == ULAM_EMEMLIMIT) free(r->direct_se_all), r->direct_se_all = NULL; /* the rows say unknown */
        else if (st) return ulam__run_error(a, a->scene, &err);
    }
    return ULAM_OK;
}

/* --matrix-walk: the error bar of the answer adds the noise of F (the walks are conditional
 * on the sampled F; the answer's error against the true B is both). */
static void combine_errors(report *r, walked *w)
{
    for (int c = 0; c < 3 && r->ff_se_known; c++)
        w->se[c] = sqrt(w->se_walk[c] * w->se_walk[c] + r->direct_se[c] * r->direct_se[c]);
    if (!w->all_se) return;
    if (!r->direct_se_all) {
        r->w_all_se_conditional = w->all_se;
        return;
    }
    for (int64_t k = 0; k < 3 * r->s->npatches; k++)
        w->all_se[k] = sqrt(w->all_se[k] * w->all_se[k] + r->direct_se_all[k] * r->direct_se_all[k]);
}

/* --at and --grid: the point queries, the luminaires' direct light added; ULAM_OK or a status
 * (written; ULAM_RAD_RUN_USAGE for a point the scene does not hold). */
static int run_points(ulam_rad_run *run)
{
    const args *a = run->a;
    points *q = &run->q;
    q->ngrid = a->grid ? (int64_t)a->g.nu * a->g.nv : 0, q->n = a->nat + q->ngrid;
    q->pts = calloc((size_t)q->n, sizeof *q->pts);
    if (!q->pts) return fail(a, a->scene, ULAM_ENOMEM, "memory for the points");
    ulam_error err;
    double t0 = ulam_now();
    interrupt_on(a, 1);
    ulam_rad_opts po = ulam__run_rad_opts(&a->o);
    if (a->nat && ulam_rad_points_solve(run->t, &po, a->at, a->nat, q->pts, &err)) { /* each point its own walks */
        const double *x = a->at + 6 * err.index;
        ulam__run_log(a, "ulam radiosity: --at %g,%g,%g: %s: %s\n", x[0], x[1], x[2], ulam_strerror(err.status), err.msg);
        interrupt_on(a, 0);
        return err.status == ULAM_EINVAL ? ULAM_RAD_RUN_USAGE : err.status; /* the point itself */
    }
    for (int k = 0; k < a->nat; k++) q->interrupted |= q->pts[k].run.interrupted;
    if (q->ngrid && !q->interrupted) {
        if (ulam_rad_grid_solve(run->t, &po, &a->g, q->pts + a->nat, &err)) {
            interrupt_on(a, 0);
            return ulam__run_error(a, a->scene, &err);
        }
        for (int64_t k = a->nat; k < q->n; k++) q->interrupted |= q->pts[k].run.interrupted || !q->pts[k].run.walks;
    }
    ulam__run_photo_points(run); /* the luminaires' direct light; Ke back */
    q->seconds = ulam_now() - t0;
    interrupt_on(a, 0);
    for (int64_t k = 0; k < q->n && !q->known; k++) /* what is wrong with the scene, when a point reads exactly 0 */
        if (q->pts[k].run.walks > 0 && ulam__run_zero(q->pts[k].irradiance, q->pts[k].irradiance_se))
            q->known = ulam_rad_scene_diagnose(run->t, ULAM__RAD_DIAG_RAYS, a->o.exec.seed, &q->diag) == ULAM_OK;
    return ULAM_OK;
}

/* The patch's mesh error beside its answer: each point to twice the patch's relative error or
 * 1/4 its walks (>= 256), in what the walks left of --time; ULAM_OK or a status (written). */
static int patch_mesh_error(ulam_rad_run *run, double budget)
{
    const args *a = run->a;
    ulam_error err;
    ulam_rad_opts mo = ulam__run_rad_opts(&a->o);
    mo.index = run->r.patch, mo.estimator = ULAM_RAD_NEXT_EVENT, mo.stop.rel_err = 2 * a->o.stop.rel_err;
    if (a->o.stop.max_walks > 0) mo.stop.max_walks = a->o.stop.max_walks / 4 > 256 ? a->o.stop.max_walks / 4 : 256;
    mo.stop.max_seconds = ulam__run_time_left(a, budget);
    interrupt_on(a, 1);
    int st = ulam_rad_mesh_error(run->t, &mo, run->w.B, &run->r.mesh, &err);
    interrupt_on(a, 0);
    if (st) return ulam__run_error(a, a->scene, &err);
    run->r.mesh_known = !run->r.mesh.interrupted;
    return ULAM_OK;
}

/* --mesh-error N: every patch's mesh error against pv->B (3 a patch); ULAM_OK or a status (written). */
static int every_mesh_error(ulam_rad_run *run)
{
    const args *a = run->a;
    ulam_error err;
    if (!(run->mesh_all = malloc((size_t)run->s->npatches * 3 * sizeof *run->mesh_all)))
        return fail(a, a->scene, ULAM_ENOMEM, "memory for the mesh errors");
    ulam_rad_opts o = ulam__run_rad_opts(&a->o);
    o.mode = ULAM_ADJOINT, o.estimator = ULAM_RAD_NEXT_EVENT, o.stop.rel_err = 0, o.stop.max_seconds = 0;
    o.stop.max_walks = a->mesh_walks;
    interrupt_on(a, 1);
    int status = ulam_rad_mesh_errors(run->t, &o, run->r.pv.B, run->mesh_all, &err); /* patch p seeded by its substream */
    interrupt_on(a, 0);
    if (status) return ulam__run_error(a, a->scene, &err);
    run->r.pv.mesh = run->mesh_all;
    return ULAM_OK;
}

/* The walks and solves the options ask (ulam_radiosity_run.h). */
int ulam_rad_run_solve(ulam_rad_run *run, int *interrupted)
{
    args *a = &run->opts;
    report *r = &run->r;
    walked *w = &run->w;
    int rc = ULAM_OK;
    *interrupted = 0;
    if (run->listed) return ULAM_OK;
    double budget = a->o.stop.max_seconds; /* --time counts the whole run: reading, the tracer, the walks, the mesh */
    a->o.stop.max_seconds = ulam__run_time_left(a, budget);
    if (a->nat || a->grid) {
        run->pointed = 1;
        rc = run_points(run);
        *interrupted = run->q.interrupted;
        return rc;
    }
    if ((a->direct || a->check || a->matrix_walk) && (rc = form_and_solve(run))) return rc;
    if (a->view) {
        if ((rc = view_walks(a, run->t, run->s, w, &r->view))) return rc;
        r->w = w;
    } else if (a->patch || a->o.mode == ULAM_FORWARD) {
        rc = a->matrix_walk ? matrix_walks(a, run->s, run->F, r->ff_se_known ? r->direct_se : NULL,
                                           run->Bd && r->patch >= 0 ? run->Bd + 3 * r->patch : NULL, w)
                            : ray_walks(a, run->t, run->want, run->s->npatches, w);
        if (rc) return rc;
        int mesh = a->patch && a->o.mode == ULAM_ADJOINT && !w->interrupted && !a->no_mesh;
        r->mesh_no_time = budget > 0 && mesh && !(budget - (ulam_now() - a->started) > 0);
        if (mesh && !r->mesh_no_time && (rc = patch_mesh_error(run, budget))) return rc;
        if (a->matrix_walk) combine_errors(r, w);
        r->w = w;
        if (r->patch >= 0 && !w->interrupted && ulam__run_zero(w->B, w->se))
            r->diag_known = ulam_rad_scene_diagnose(run->t, ULAM__RAD_DIAG_RAYS, a->o.exec.seed, &r->diag) == ULAM_OK;
    }
    if (w->all)
        r->pv = (patch_values){w->all, w->all_se, (a->direct || a->check) ? run->Bd : NULL, r->direct_se_all, NULL, w->half,
                               run->want};
    else r->pv = (patch_values){run->Bd, r->direct_se_all, NULL, NULL, NULL, NULL, NULL};
    if (a->mesh_walks && r->pv.B && !w->interrupted && (rc = every_mesh_error(run))) return rc;
    *interrupted = w->interrupted;
    return ULAM_OK;
}

/* Free a run. */
void ulam_rad_run_free(ulam_rad_run *r)
{
    if (!r) return;
    free(r->w.all), free(r->w.all_se), free(r->w.half), free(r->want), free(r->Bd), free(r->r.direct_se_all), free(r->mesh_all);
    free(r->L), free(r->Lse), free(r->q.pts);
    ulam_csr_free(r->F);
    ulam_tracer_free(r->t);
    ulam_scene_free(r->s);
    ulam__run_photo_free(&r->ph);
    free(r);
}

/* Metres a scene unit named m, cm, mm, in, ft or km. */
int ulam_rad_unit_metres(const char *name, double *metres)
{
    static const char *const names[] = {"m", "cm", "mm", "in", "ft", "km"};
    static const double m[] = {1.0, 0.01, 0.001, 0.0254, 0.3048, 1000.0};
    for (int k = 0; k < 6; k++)
        if (!strcmp(name, names[k])) return *metres = m[k], ULAM_OK;
    return ULAM_ENOTFOUND;
}
