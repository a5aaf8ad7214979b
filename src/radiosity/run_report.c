/* A radiosity run's reports (ulam_radiosity_run.h): the text a person reads, one JSON object,
 * the patch rows (table, CSV, JSON) and the point queries' answers, each into the caller's FILE *. */
#include "runstate.h"

#include "rad.h"

#include <string.h>

static const char *const est_names[] = {"collision", "absorption", "next-event"};
static const char *const mis_names[] = {"power", "balance", "none"};
static const char *const chan = "RGB";

/* The JSON key of the answer (the radiosity), in one place so that it can be renamed. */
static const char *const answer_key = "radiosity";

/* The whole scene's rule after shooting --rel-err without --patch: how many lit patches met it,
 * the worst one, and the patches no particle reached. */
static void print_scene_rule(FILE *f, const args *a, const walked *w)
{
    const ulam_rad_scene_rule *q = &w->scene;
    fprintf(f, "rel-err      %s on the %s: %lld of %lld lit patches (%.4g of the lit area; the rule: %.4g) within "
           "%g;\n             the largest relative standard error %.3g, 95%% half-width / B %.3g (patch %lld)\n",
           w->rel_err_met ? "met" : "NOT met", a->patches ? "chosen patches" : "whole scene", (long long)q->met, (long long)q->lit,
           q->lit_area > 0 ? q->met_area / q->lit_area : 0.0, q->share, a->o.stop.rel_err, q->worst_se, q->worst_half,
           (long long)q->worst_patch + 1);
    if (q->unreached && !a->final) { /* the final gather's: print_final */
        fprintf(f, "unreached    %lld patches no particle reached in %lld walks (each gets under 3/%lld of the particles, "
               "95%%):", (long long)q->unreached, (long long)w->walks, (long long)w->walks);
        for (int64_t k = 0; k < q->unreached && k < 8; k++) fprintf(f, " %lld", (long long)w->unreached[k] + 1);
        fprintf(f, "%s\n", q->unreached > 8 ? " ..." : "");
    }
}

/* --mode final's summary over the patches it answered (every patch, or --patches'): half-width /
 * B's median and 90% quantile, the worst, and the patches no sample lit. */
static void print_final(FILE *f, const ulam_rad_run *run)
{
    const walked *w = &run->w;
    const ulam_rad_scene_rule *q = &w->scene;
    const char *which = run->want ? " chosen" : "";
    if (q->lit)
        fprintf(f, "half-width   95%% half-width / B over the %lld lit%s patches: median %.3g, 90%% %.3g, largest %.3g "
                   "(patch %lld)\n", (long long)q->lit, which, w->half_rel[0], w->half_rel[1], q->worst_half,
                (long long)q->worst_patch + 1);
    if (!q->unreached) return;
    fprintf(f, "unreached    %lld%s patches that reflect got no light from the gather (none reaches them, or the stop "
               "came first):", (long long)q->unreached, which);
    for (int64_t k = 0; k < q->unreached && k < 8; k++) fprintf(f, " %lld", (long long)w->unreached[k] + 1);
    fprintf(f, "%s\n", q->unreached > 8 ? " ..." : "");
}

/* Print a JSON array of three numbers under key. */
static void json_triple(FILE *f, const char *key, const double *v)
{
    fprintf(f, "\"%s\": [", key);
    for (int c = 0; c < 3; c++) {
        ulam_json_number(f, NULL, v[c], 1);
        fprintf(f, c < 2 ? ", " : "], ");
    }
}

enum { ROW_TEXT, ROW_CSV, ROW_JSON };

/* The header of the patch rows (text and CSV); v NULL: geometry only (--list). */
static void row_header(FILE *f, int fmt, const patch_values *v)
{
    static const char *const geo[] = {"x", "y", "z", "area"}, *const val[] = {"R", "G", "B", "R_se", "G_se", "B_se"};
    fprintf(f, fmt == ROW_CSV ? "patch,label,face" : "%6s %-16s %6s", "patch", "label", "face");
    for (int k = 0; k < 4; k++) fprintf(f, fmt == ROW_CSV ? ",%s" : " %12s", geo[k]);
    for (int k = 0; v && k < 6; k++) fprintf(f, fmt == ROW_CSV ? ",%s" : " %12s", val[k]);
    for (int k = 0; v && v->Bd && k < 6; k++) fprintf(f, fmt == ROW_CSV ? ",direct_%s" : " direct_%-5s", val[k]);
    for (int k = 0; v && v->mesh && k < 3; k++) fprintf(f, fmt == ROW_CSV ? ",%s_mesh" : " %7s_mesh", val[k]);
    for (int k = 0; v && v->half && k < 3; k++) fprintf(f, fmt == ROW_CSV ? ",%s_half" : " %7s_half", val[k]);
    fputc('\n', f);
}

/* One patch's row: number, label, face, centroid, area, then (v) the values; an unknown value
 * is an empty CSV field, '-' in the table, null in JSON. */
static void row(FILE *f, int fmt, const ulam_scene *s, int64_t p, const patch_values *v)
{
    static const char *const keys[] = {"x", "y", "z", "area", "R", "G", "B", "R_se", "G_se", "B_se",
                                       "direct_R", "direct_G", "direct_B", "direct_R_se", "direct_G_se", "direct_B_se",
                                       "R_mesh", "G_mesh", "B_mesh", "R_half", "G_half", "B_half"};
    double x[22];
    const char *key[22];
    int n = 4;
    ulam_scene_centroid(s, p, x);
    x[3] = s->area[p];
    const double *cols[4] = {v ? v->B : NULL, v ? v->se : NULL, v ? v->Bd : NULL, v ? v->sed : NULL};
    for (int k = 0; k < 4; k++) key[k] = keys[k];
    for (int k = 0; v && k < (v->Bd ? 4 : 2); k++)
        for (int c = 0; c < 3; c++) key[n] = keys[n], x[n++] = cols[k] ? cols[k][3 * p + c] : NAN;
    for (int c = 0; v && v->mesh && c < 3; c++) key[n] = keys[16 + c], x[n++] = v->mesh[3 * p + c];
    for (int c = 0; v && v->half && c < 3; c++) key[n] = keys[19 + c], x[n++] = v->half[3 * p + c];
    int32_t g = s->group[p];
    const char *label = g >= 0 ? s->groups[g] : "";
    if (fmt == ROW_JSON) {
        fprintf(f, "{\"patch\": %lld, ", (long long)p + 1);
        ulam_json_string(f, "label", label, 0);
        fprintf(f, "\"face\": %lld, ", (long long)s->face[p] + 1);
        for (int k = 0; k < n; k++) ulam_json_number(f, key[k], x[k], k == n - 1);
        fprintf(f, "}");
        return;
    }
    if (fmt == ROW_CSV) {
        fprintf(f, "%lld,\"", (long long)p + 1); /* the label quoted, quotes doubled (RFC 4180) */
        for (const char *c = label; *c; c++) fputs(*c == '"' ? "\"\"" : (char[2]){*c, 0}, f);
        fprintf(f, "\",%lld", (long long)s->face[p] + 1);
    } else {
        fprintf(f, "%6lld %-16s %6lld", (long long)p + 1, *label ? label : "-", (long long)s->face[p] + 1);
    }
    for (int k = 0; k < n; k++) {
        if (fmt == ROW_CSV) fputc(',', f);
        if (isfinite(x[k])) fprintf(f, fmt == ROW_CSV ? "%.17g" : " %12.6g", x[k]);
        else if (fmt == ROW_TEXT) fprintf(f, " %12s", "-");
    }
    fputc('\n', f);
}

/* --list: the patches after subdivision, as a table or a JSON array. */
static void print_list(FILE *f, const args *a, const ulam_scene *s, const unsigned char *want)
{
    int first = 1;
    if (a->json) {
        fprintf(f, "{");
        ulam_json_string(f, "scene", a->scene, 0);
        fprintf(f, "\"patches\": [");
    }
    else row_header(f, ROW_TEXT, NULL);
    for (int64_t p = 0; p < s->npatches; p++) {
        if (want && !want[p]) continue;
        if (a->json && !first) fprintf(f, ", ");
        row(f, a->json ? ROW_JSON : ROW_TEXT, s, p, NULL), first = 0;
    }
    if (a->json) fprintf(f, "]}\n");
}

/* (walk - direct) / the standard error of the difference at the patch, channel c: matrix walks
 * share F with the direct solve (walk noise alone), ray walks sample the exact F (both). */
static double zscore(const args *a, const report *r, int c)
{
    double d = r->Bdirect[3 * r->patch + c], sw = r->w->se_walk[c], sf = a->matrix_walk ? 0.0 : r->direct_se[c];
    double diff = r->w->B[c] - d, se = sqrt(sw * sw + sf * sf);
    if (se == 0) return diff == 0 ? 0.0 : copysign(INFINITY, diff); /* both exact: agree, or not at all */
    return diff / se;
}

/* Which side of a --check disagreement (|z| > 3) in channel c is suspect: ray walks carry a
 * certified interval, the direct solve a first-order bar from F's sampled noise, so a direct
 * answer outside the walks' interval points at F (--ff-rays), one inside it at the walks;
 * matrix walks share the sampled F, so only the walks' noise can be at fault. */
static void check_side(FILE *f, const args *a, const report *r, int c)
{
    double d = r->Bdirect[3 * r->patch + c], lo = r->w->ci95[c][0], hi = r->w->ci95[c][1];
    fprintf(f, "check %c      |z| = %.2g: ", chan[c], fabs(zscore(a, r, c)));
    if (a->matrix_walk)
        fprintf(f, "the walks on the same F disagree with its direct solve: the walks' noise (or a bug)\n");
    else if (isfinite(lo) && isfinite(hi) && (d < lo || d > hi))
        fprintf(f, "the direct solve, %.6g, lies %s the walks' certified 95%% interval %.6g .. %.6g:\n"
               "             suspect the form factors (%lld rays a patch; raise --ff-rays)\n", d,
               d < lo ? "below" : "above", lo, hi, (long long)a->ff_rays);
    else if (isfinite(lo) && isfinite(hi))
        fprintf(f, "the direct solve, %.6g, lies inside the walks' certified 95%% interval %.6g .. %.6g:\n"
               "             its form-factor bar is too narrow (raise --ff-rays)\n", d, lo, hi);
    else
        fprintf(f, "the walks have no certified interval here to tell which side is off\n");
}

/* Nonzero when the mesh error of channel c dominates the Monte Carlo error: larger than twice
 * it, and real (more than 4 standard errors of the difference: the largest of up to 9). */
static int mesh_dominates(const report *r, const walked *w, int c)
{
    double e = r->mesh.error[c], se = sqrt(w->se[c] * w->se[c] + r->mesh.error_se[c] * r->mesh.error_se[c]);
    return e > 2 * w->se[c] && e > 4 * se;
}

/* The mesh error lines of the text report. */
static void print_mesh(FILE *f, const report *r, const walked *w)
{
    int any = 0;
    for (int c = 0; c < 3; c++) {
        double lo = INFINITY, hi = -INFINITY;
        for (int k = 0; k < r->mesh.npoints; k++) lo = fmin(lo, r->mesh.point[k][c]), hi = fmax(hi, r->mesh.point[k][c]);
        fprintf(f, "mesh error %c %.3g (Monte Carlo %.3g): the surface reads %.8g +- %.3g at the patch's centroid, "
               "%.6g .. %.6g at its %d quadrature points\n", chan[c], r->mesh.error[c], w->se[c], r->mesh.point[0][c],
               r->mesh.point_se[0][c], lo, hi, r->mesh.npoints);
        any |= mesh_dominates(r, w, c);
    }
    if (any)
        fprintf(f, "warning      the mesh error dominates the Monte Carlo error: this patch's one value stands for a\n"
               "             surface whose radiosity differs from it by more; ask --at a point (no mesh), or\n"
               "             --subdivide finer\n");
}

/* The adaptive mesh's line of the text report. */
static void print_adapt(FILE *f, const args *a, const report *r)
{
    const ulam_rad_adapt_info *d = &r->adapt;
    char why[96];
    int64_t asked = a->max_patches ? a->max_patches : 100000;
    if (asked > r->adapt_cap) snprintf(why, sizeof why, "NOT met (--max-mem holds %lld patches)", (long long)r->adapt_cap);
    else snprintf(why, sizeof why, "NOT met (--max-patches %lld)", (long long)r->adapt_cap);
    if (d->interrupted) snprintf(why, sizeof why, "NOT met (cut by --time, half of it, or Ctrl-C; the last mesh measured whole kept)");
    if (isnan(d->error)) { /* cut inside the first round: the scene as read */
        fprintf(f, "mesh         adaptive (%s importance): NOT measured (cut in the first round by --time or Ctrl-C); the scene's "
               "%lld patches kept, target %g; %lld point queries, %.3f s\n", r->view_importance ? "the view's" : "area",
               (long long)d->patches, a->mesh_target, (long long)d->points, d->seconds);
        return;
    }
    fprintf(f, "mesh         adaptive (%s importance): %lld -> %lld patches, %lld split in %lld rounds; mesh error "
           "%.3g -> %.3g, target %g %s; %lld point queries, %lld rays, %.3f s\n", r->view_importance ? "the view's" : "area",
           (long long)d->patches_in, (long long)d->patches, (long long)d->splits, (long long)d->rounds, d->error0,
           d->error, a->mesh_target, d->met ? "met" : why, (long long)d->points, (long long)d->rays, d->seconds);
}

/* scene_notes' finding as a JSON word: no_emitter, inside_out, lamps_face_out or unreached. */
static const char *zero_reason(const ulam_rad_scene_diag *d)
{
    double fr = (double)d->front[0] / ULAM__RAD_DIAG_RAYS, br = (double)d->back[1] / ULAM__RAD_DIAG_RAYS;
    if (!d->emitters) return "no_emitter";
    if (br > 0.25 && br > 2.0 * fr) return "inside_out";
    if (d->lamp[0] + d->lamp[1] + d->lamp[2] > 0 && d->lamp[0] == 0) return "lamps_face_out";
    return "unreached";
}

/* Print what is wrong with a scene whose answer is exactly 0 (label: the first line's label
 * column, indent the next lines'). */
static void scene_notes(FILE *f, const ulam_rad_scene_diag *d, const char *label, const char *indent)
{
    double fr = (double)d->front[0] / ULAM__RAD_DIAG_RAYS, br = (double)d->back[1] / ULAM__RAD_DIAG_RAYS; /* front to front, back to back */
    int64_t lamp = d->lamp[0] + d->lamp[1] + d->lamp[2];
    const char *why = zero_reason(d);
    if (!strcmp(why, "no_emitter"))
        fprintf(f, "%sthe scene has no emitter: no material has Ke > 0, so no light enters it and every\n"
               "%sradiosity is exactly 0 (give the lamps' material Ke)\n", label, indent);
    else if (!strcmp(why, "inside_out"))
        fprintf(f, "%sthe faces look inside out: %.0f%% of rays leaving the patches' backs land on another's\n"
               "%sback, %.0f%% of those leaving their fronts on a front (OBJ faces are counter-clockwise seen\n"
               "%sfrom their lit side: reverse each face's vertex order)\n", label, 100.0 * br, indent, 100.0 * fr, indent);
    else if (!strcmp(why, "lamps_face_out"))
        fprintf(f, "%sno emitter's front faces into the scene: of %lld rays leaving the lamps' fronts, %lld\n"
               "%sleave the scene and %lld land on a back side (turn the lamps' faces around)\n", label,
               (long long)lamp, (long long)d->lamp[2], indent, (long long)d->lamp[1]);
    else
        fprintf(f, "%sthe scene has %lld emitting patches and its faces face in (%.0f%% of the fronts' rays land\n"
               "%son a front): no emitter's light reaches here\n", label, (long long)d->emitters, 100.0 * fr, indent);
}

/* Nonzero when the walks' interval covers a cut at --max-steps (ray gathering by next-event or
 * collision, whose walks have a certified tail; the library widens the interval by it). */
static int cut_covered(const args *a)
{
    return !a->matrix_walk && a->o.mode == ULAM_ADJOINT && a->o.estimator != ULAM_RAD_ABSORPTION;
}

/* The answer of a patch's walks: its three channels, each with its interval. */
static void patch_answer(FILE *f, const args *a, const report *r, const walked *w)
{
    for (int c = 0; c < 3; c++) {
        fprintf(f, "radiosity %c  %.8g +- %.3g", chan[c], w->B[c], w->se[c]);
        if (a->matrix_walk && r->ff_se_known) fprintf(f, " (walk %.3g, form factors %.3g)", w->se_walk[c], r->direct_se[c]);
        else if (a->matrix_walk) fprintf(f, " (walk noise only, CONDITIONAL on the sampled F: its noise is unknown)");
        else if (isfinite(w->ci95[c][0])) fprintf(f, " (95%% CI %.8g .. %.8g)", w->ci95[c][0], w->ci95[c][1]);
        else fprintf(f, " (no 95%% interval: no score range certified)");
        fprintf(f, "%s\n", w->interrupted ? "  [INTERRUPTED]" : "");
    }
}

/* Print the text report: a patch's answer first, then the scene and the rest. */
static void print_text(FILE *f, const ulam_rad_run *run)
{
    const args *a = run->a;
    const report *r = &run->r;
    if (r->w && r->patch >= 0) patch_answer(f, a, r, r->w);
    fprintf(f, "scene        %s: %lld faces, %lld patches\n", a->scene, (long long)r->faces, (long long)r->s->npatches);
    if (run->want)
        fprintf(f, "chosen       %lld of %lld patches (--patches %s)\n", (long long)run->nwant, (long long)r->s->npatches,
                a->patches);
    if (r->adapted) print_adapt(f, a, r);
    if (r->F)
        fprintf(f, "form factors %lld rays a patch, %.3f s: reciprocity error %.3g, row sums %.4f .. %.4f "
               "(mean %.4f), %lld nonzeros\n", (long long)a->ff_rays, r->ff_seconds, r->ff.reciprocity,
               r->ff.rowsum_min, r->ff.rowsum_max, r->ff.rowsum_mean, (long long)r->ff.nnz);
    if (r->Bdirect) fprintf(f, "direct       LAPACKE_dgesv, 3 channels, %.3f s\n", r->direct_seconds);
    if (r->patch >= 0) {
        int32_t g = r->s->group[r->patch];
        double c[3];
        ulam_scene_centroid(r->s, r->patch, c);
        fprintf(f, "patch        %lld (%s, face %lld, area %.6g, centroid %.6g %.6g %.6g)\n", (long long)r->patch + 1,
               g >= 0 ? r->s->groups[g] : "unlabelled", (long long)r->s->face[r->patch] + 1, r->s->area[r->patch],
               c[0], c[1], c[2]);
    }
    const walked *w = r->w;
    if (w && w->cut) /* next to the numbers: they are biased low */
        fprintf(f, "warning      %lld of %lld walks cut at --max-steps %lld: the estimate is biased low (the light\n"
               "             beyond the cut is lost); %s (raise --max-steps)\n", (long long)w->cut, (long long)w->walks,
               (long long)a->o.stop.max_steps, cut_covered(a) ? "the interval includes the most the cut can miss"
                                                               : "the error bar does not cover the bias");
    if (w && r->patch >= 0) {
        if (a->o.stop.rel_err > 0 && !a->matrix_walk && !w->zero)
            fprintf(f, "rel-err      %s (%g; the rule's range term wants %.3g walks)\n", w->rel_err_met ? "met" : "NOT met",
                   a->o.stop.rel_err, w->min_walks);
        else if (a->o.stop.rel_err > 0 && a->o.mode == ULAM_ADJOINT && !w->zero && !w->rel_err_met &&
                 !(w->ff_limited[0] || w->ff_limited[1] || w->ff_limited[2])) /* (F's error past it: a line below) */
            fprintf(f, "rel-err      NOT met (%g; every channel's walks to its target: %s)\n", a->o.stop.rel_err,
                   w->interrupted ? "cut short" : "stopped by --walks, --time or the walk cap");
        if (w->zero)
            fprintf(f, "note         every channel is exactly 0 with zero variance after %lld walks (no walk scored):\n"
                   "             --rel-err can never be met by a zero estimate, so the walks stopped there; if the\n"
                   "             answer is not exactly 0, a walk scores with probability below 3/%lld = %.2g (95%%)\n",
                   (long long)w->walks, (long long)w->walks, 3.0 / (double)w->walks);
        if (r->diag_known) scene_notes(f, &r->diag, "note         ", "             ");
        if (r->mesh_known) print_mesh(f, r, w);
        if (r->mesh_no_time)
            fprintf(f, "mesh error   not estimated: the walks spent --time (raise it, or --no-mesh-error)\n");
    }
    if (w)
        fprintf(f, "walks        %lld %s %s walks, %lld %s, %.4f s (%.3g M %s/s, %d threads)%s\n", (long long)w->walks,
               a->matrix_walk ? "matrix" : "ray", ulam_rad_mode_name(a->final ? ULAM_RAD_FINAL : a->o.mode, NULL),
               (long long)w->steps,
               a->matrix_walk ? "steps" : "rays", w->seconds, w->seconds > 0 ? (double)w->steps / w->seconds / 1e6 : 0.0,
               a->matrix_walk ? "steps" : "rays", w->threads, w->interrupted ? "  [INTERRUPTED]" : "");
    if (w && w->whole) print_scene_rule(f, a, w);
    if (w && a->final) print_final(f, run);
    for (int c = 0; w && a->matrix_walk && c < 3; c++)
        if (w->ff_limited[c])
            fprintf(f, "rel-err      NOT met in %c: the form factors' error alone is %.3g, past --rel-err %g of the "
                   "answer; more walks cannot meet it, more --ff-rays can (F's error falls as 1/sqrt(rays))\n",
                   chan[c], r->direct_se[c], a->o.stop.rel_err);
    if (w && a->matrix_walk)
        fprintf(f, "             (one walk a channel: %lld R + %lld G + %lld B)\n", (long long)w->channel_walks[0],
               (long long)w->channel_walks[1], (long long)w->channel_walks[2]);
    if (a->view)
        fprintf(f, "view         %lld of %lld patches seen (%lld of %lld pixels), each to %.3g (n_max / n)^%.3g: "
               "%lld camera rays + %lld walk rays, %.4f s%s\n", (long long)r->view.seen, (long long)r->view.npatches,
               (long long)r->view.pixels_hit, (long long)r->view.camera_rays, a->o.stop.rel_err, a->coverage,
               (long long)r->view.camera_rays, (long long)r->view.rays, r->view.seconds,
               r->view.unmet ? "" : ", every seen patch met its target");
    if (a->view && r->view.unmet)
        fprintf(f, "warning      %lld seen patches stopped short of their target (--walks or --time)\n",
               (long long)r->view.unmet);
    if (r->Bdirect && r->patch >= 0)
        for (int c = 0; c < 3; c++) {
            fprintf(f, "direct %c     %.8g", chan[c], r->Bdirect[3 * r->patch + c]);
            if (r->ff_se_known) fprintf(f, " +- %.3g (form-factor noise)", r->direct_se[c]);
            if (w) fprintf(f, "  z = %.3f%s", zscore(a, r, c), a->matrix_walk ? " (walk noise: the same F)" : "");
            fprintf(f, "\n");
        }
    for (int c = 0; r->Bdirect && r->patch >= 0 && w && c < 3; c++)
        if (fabs(zscore(a, r, c)) > 3.0) check_side(f, a, r, c);
    if (a->out && r->out_written)
        fprintf(f, "patches      %lld rows written to %s%s\n", (long long)(run->want ? run->nwant : r->s->npatches), a->out,
               r->pv.se == r->w_all_se_conditional ? " (standard errors: walk noise only, CONDITIONAL on the sampled F)" : "");
    else if (a->out && w && w->interrupted) fprintf(f, "patches      not written: the run was interrupted\n");
    if (a->all) {
        row_header(f, ROW_TEXT, &r->pv);
        for (int64_t p = 0; p < r->s->npatches; p++)
            if (!run->want || run->want[p]) row(f, ROW_TEXT, r->s, p, &r->pv);
    }
    if (a->image && r->image_written) fprintf(f, "image        %s (exposure %.4g)\n", a->image, r->exposure);
    else if (a->image && w && w->interrupted) fprintf(f, "image        not written: the run was interrupted\n");
}

/* Print the JSON object. */
static void print_json(FILE *f, const ulam_rad_run *run)
{
    const args *a = run->a;
    const report *r = &run->r;
    fprintf(f, "{");
    ulam_json_string(f, "scene", a->scene, 0); /* a path may hold quotes and backslashes */
    fprintf(f, "\"npatches\": %lld, ", (long long)r->s->npatches);
    if (run->want) {
        fprintf(f, "\"chosen\": {");
        ulam_json_string(f, "patches", a->patches, 0);
        fprintf(f, "\"count\": %lld}, ", (long long)run->nwant);
    }
    if (r->adapted) {
        char e[2][32]; /* null: --time ran out before the first mesh was measured whole */
        for (int k = 0; k < 2; k++)
            if (isnan(k ? r->adapt.error : r->adapt.error0)) snprintf(e[k], sizeof e[k], "null");
            else snprintf(e[k], sizeof e[k], "%.6g", k ? r->adapt.error : r->adapt.error0);
        fprintf(f, "\"adaptive\": {\"importance\": \"%s\", \"patches_in\": %lld, \"patches\": %lld, \"splits\": %lld, "
               "\"rounds\": %lld, \"mesh_error_initial\": %s, \"mesh_error\": %s, \"target\": %g, \"met\": %s, "
               "\"interrupted\": %s, \"points\": %lld, \"rays\": %lld, \"seconds\": %.6g}, ", r->view_importance ? "view" : "area",
               (long long)r->adapt.patches_in, (long long)r->adapt.patches, (long long)r->adapt.splits,
               (long long)r->adapt.rounds, e[0], e[1], a->mesh_target, r->adapt.met ? "true" : "false",
               r->adapt.interrupted ? "true" : "false", (long long)r->adapt.points, (long long)r->adapt.rays, r->adapt.seconds);
    }
    if (r->patch >= 0) {
        int32_t g = r->s->group[r->patch];
        double c[3];
        ulam_scene_centroid(r->s, r->patch, c);
        fprintf(f, "\"patch\": %lld, ", (long long)r->patch + 1);
        ulam_json_string(f, "label", g >= 0 ? r->s->groups[g] : "", 0);
        json_triple(f, "centroid", c);
    }
    const walked *w = r->w;
    if (w) {
        if (r->patch >= 0) {
            json_triple(f, "estimate", w->B); /* the answer's key in every command */
            json_triple(f, answer_key, w->B);
            json_triple(f, "stderr", w->se);
            if (!a->matrix_walk) {
                double lo[3] = {w->ci95[0][0], w->ci95[1][0], w->ci95[2][0]};
                double hi[3] = {w->ci95[0][1], w->ci95[1][1], w->ci95[2][1]};
                json_triple(f, "ci95_lo", lo); /* each channel's 95% interval (null: none certified) */
                json_triple(f, "ci95_hi", hi);
            }
            if (r->mesh_known) {
                int dom = 0;
                for (int c = 0; c < 3; c++) dom |= mesh_dominates(r, w, c);
                json_triple(f, "mesh_error", r->mesh.error);
                json_triple(f, "mesh_error_stderr", r->mesh.error_se);
                json_triple(f, "surface_at_centroid", r->mesh.point[0]);
                json_triple(f, "surface_at_centroid_stderr", r->mesh.point_se[0]);
                fprintf(f, "\"mesh_error_dominates\": %s, ", dom ? "true" : "false");
            }
            if (r->mesh_no_time) ulam_json_string(f, "mesh_error_skipped", "the walks spent --time", 0);
            if (a->matrix_walk) {
                json_triple(f, "walk_stderr", w->se_walk);
                if (r->ff_se_known) json_triple(f, "ff_stderr", r->direct_se);
            }
        }
        ulam_json_string(f, "mode", ulam_rad_mode_name(a->final ? ULAM_RAD_FINAL : a->o.mode, NULL), 0);
        ulam_json_string(f, "estimator", est_names[a->est], 0);
        if (a->est == 2) ulam_json_string(f, "mis", mis_names[a->mis > 0 ? a->mis : 0], 0);
        fprintf(f, "\"matrix_walk\": %s, \"walks\": %lld, \"%s\": %lld, \"cut\": %lld, \"max_steps\": %lld, ",
               a->matrix_walk ? "true" : "false", (long long)w->walks, a->matrix_walk ? "steps" : "rays",
               (long long)w->steps, (long long)w->cut, (long long)a->o.stop.max_steps);
        if (a->matrix_walk) /* walks is their sum: a matrix walk carries one channel */
            fprintf(f, "\"channel_walks\": [%lld, %lld, %lld], ", (long long)w->channel_walks[0],
                   (long long)w->channel_walks[1], (long long)w->channel_walks[2]);
        ulam_json_number(f, "seconds", w->seconds, 0);
        fprintf(f, "\"interrupted\": %s, \"zero\": %s, ", w->interrupted ? "true" : "false", w->zero ? "true" : "false");
        if (r->diag_known) ulam_json_string(f, "zero_reason", zero_reason(&r->diag), 0);
        if (w->whole)
            fprintf(f, "\"scene_rule\": {\"met\": %s, \"lit\": %lld, \"lit_met\": %lld, \"unreached\": %lld, "
                   "\"share\": %.6g, \"area_met\": %.6g, \"worst_patch\": %lld, \"worst_half\": %.6g, \"worst_se\": %.6g}, ",
                   w->rel_err_met ? "true" : "false", (long long)w->scene.lit, (long long)w->scene.met,
                   (long long)w->scene.unreached, w->scene.share,
                   w->scene.lit_area > 0 ? w->scene.met_area / w->scene.lit_area : 0.0,
                   (long long)w->scene.worst_patch + 1, w->scene.worst_half, w->scene.worst_se);
        if (a->final) { /* over the patches it answered (print_final) */
            fprintf(f, "\"final\": {\"lit\": %lld, \"unreached\": %lld, ", (long long)w->scene.lit,
                    (long long)w->scene.unreached);
            ulam_json_number(f, "half_rel_median", w->half_rel[0], 0);
            ulam_json_number(f, "half_rel_q90", w->half_rel[1], 0);
            ulam_json_number(f, "half_rel_max", w->scene.lit ? w->scene.worst_half : NAN, 0);
            fprintf(f, "\"unreached_patches\": [");
            for (int64_t k = 0; k < w->scene.unreached && k < 8; k++) fprintf(f, "%s%lld", k ? ", " : "", (long long)w->unreached[k] + 1);
            fprintf(f, "]}, ");
        }
        if (a->o.stop.rel_err > 0 && !a->matrix_walk && a->o.mode == ULAM_ADJOINT) {
            fprintf(f, "\"rel_err_met\": %s, ", w->rel_err_met ? "true" : "false");
            ulam_json_number(f, "min_walks", w->min_walks, 0);
        }
    }
    if (a->view) {
        fprintf(f, "\"view\": {\"seen\": %lld, \"npatches\": %lld, \"pixels_hit\": %lld, \"camera_rays\": %lld, "
               "\"walks\": %lld, \"rays\": %lld, \"unmet\": %lld, ", (long long)r->view.seen,
               (long long)r->view.npatches, (long long)r->view.pixels_hit, (long long)r->view.camera_rays,
               (long long)r->view.walks, (long long)r->view.rays, (long long)r->view.unmet);
        ulam_json_number(f, "rel_err", a->o.stop.rel_err, 0);
        ulam_json_number(f, "coverage", a->coverage, 0);
        ulam_json_number(f, "seconds", r->view.seconds, 1);
        fprintf(f, "}, ");
    }
    if (r->F) {
        fprintf(f, "\"ff_rays\": %lld, ", (long long)a->ff_rays);
        ulam_json_number(f, "ff_seconds", r->ff_seconds, 0);
        ulam_json_number(f, "reciprocity", r->ff.reciprocity, 0);
        ulam_json_number(f, "rowsum_min", r->ff.rowsum_min, 0);
        ulam_json_number(f, "rowsum_max", r->ff.rowsum_max, 0);
    }
    if (r->Bdirect && r->patch >= 0) {
        double z[3];
        for (int c = 0; c < 3; c++) z[c] = w ? zscore(a, r, c) : NAN;
        json_triple(f, "direct", r->Bdirect + 3 * r->patch);
        if (r->ff_se_known) json_triple(f, "direct_stderr", r->direct_se);
        if (w) json_triple(f, "z", z);
        ulam_json_number(f, "direct_seconds", r->direct_seconds, 0);
    }
    if (a->image) {
        if (r->image_written) ulam_json_string(f, "image", a->image, 0), ulam_json_number(f, "exposure", r->exposure, 0);
        else fprintf(f, "\"image\": null, ");
    }
    if (a->out) {
        if (r->out_written) ulam_json_string(f, "out", a->out, 0);
        else fprintf(f, "\"out\": null, ");
    }
    if (a->all) {
        fprintf(f, "\"stderr_conditional_on_F\": %s, \"patches\": [", r->pv.se == r->w_all_se_conditional ? "true" : "false");
        for (int64_t p = 0, first = 1; p < r->s->npatches; p++) {
            if (run->want && !run->want[p]) continue;
            if (!first) fprintf(f, ", ");
            row(f, ROW_JSON, r->s, p, &r->pv), first = 0;
        }
        fprintf(f, "], ");
    }
    ulam__run_photo_report(f, run, 1); /* photometric runs: the luminaires */
    fprintf(f, "\"seed\": %llu}\n", (unsigned long long)a->o.exec.seed);
}

/* A point's 95% intervals per channel from its run's (src/stop.c's construction on the certified
 * range, held on the irradiance H): [c][0] H's, [c][1] B = E + rho H's (rho >= 0 maps the
 * interval), NaN where none is certified or off the surfaces. */
static void point_ci(const ulam_scene *s, const ulam_rad_point *r, double lo[3][2], double hi[3][2])
{
    for (int c = 0; c < 3; c++) {
        lo[c][0] = r->run.ci95[c][0], hi[c][0] = r->run.ci95[c][1];
        lo[c][1] = hi[c][1] = NAN;
        if (r->patch < 0 || !isfinite(lo[c][0]) || !isfinite(hi[c][0])) continue;
        double E = s->emit[3 * r->patch + c], rho = s->rho[3 * r->patch + c];
        lo[c][1] = E + rho * lo[c][0], hi[c][1] = E + rho * hi[c][0];
    }
}

/* One point's answer as text. */
static void point_text(FILE *f, const ulam_scene *s, int k, const ulam_rad_point *r, int interrupted,
                       const ulam_rad_scene_diag *diag)
{
    fprintf(f, "point %-6d %.6g %.6g %.6g, normal %.4g %.4g %.4g", k + 1, r->x[0], r->x[1], r->x[2], r->n[0], r->n[1],
           r->n[2]);
    if (r->patch >= 0) {
        int32_t g = s->group[r->patch];
        fprintf(f, " (patch %lld, %s)\n", (long long)r->patch + 1, g >= 0 ? s->groups[g] : "unlabelled");
    } else {
        fprintf(f, " (a sensor on no surface)\n");
    }
    if (r->run.cut)
        fprintf(f, "  warning    %lld of %lld walks cut at --max-steps: the estimate is biased low; the interval includes\n"
               "             the most the cut can miss (raise --max-steps)\n", (long long)r->run.cut,
               (long long)r->run.walks);
    double lo[3][2], hi[3][2];
    point_ci(s, r, lo, hi);
    for (int c = 0; c < 3; c++) {
        fprintf(f, "  irradiance %c %.8g +- %.3g", chan[c], r->irradiance[c], r->irradiance_se[c]);
        if (isfinite(lo[c][0])) fprintf(f, " (95%% CI %.6g .. %.6g)", lo[c][0], hi[c][0]);
        if (r->patch >= 0) fprintf(f, "   radiosity %c %.8g +- %.3g", chan[c], r->radiosity[c], r->radiosity_se[c]);
        if (r->patch >= 0 && isfinite(lo[c][1])) fprintf(f, " (95%% CI %.6g .. %.6g)", lo[c][1], hi[c][1]);
        fprintf(f, "%s\n", interrupted ? "  [INTERRUPTED]" : "");
    }
    fprintf(f, "  walks      %lld, %lld rays, %.4f s\n", (long long)r->run.walks, (long long)r->run.rays, r->run.seconds);
    if (diag && !interrupted && r->run.walks > 0 && ulam__run_zero(r->irradiance, r->irradiance_se))
        scene_notes(f, diag, "  note       ", "             ");
}

/* One point's answer as a JSON object. */
static void point_json(FILE *f, const ulam_scene *s, const ulam_rad_point *r, const ulam_rad_scene_diag *diag)
{
    double lo[3][2], hi[3][2], v[4][3];
    point_ci(s, r, lo, hi);
    for (int c = 0; c < 3; c++) v[0][c] = lo[c][0], v[1][c] = hi[c][0], v[2][c] = lo[c][1], v[3][c] = hi[c][1];
    fprintf(f, "{");
    json_triple(f, "x", r->x);
    json_triple(f, "normal", r->n);
    fprintf(f, "\"patch\": ");
    if (r->patch >= 0) fprintf(f, "%lld, ", (long long)r->patch + 1);
    else fprintf(f, "null, ");
    json_triple(f, "irradiance", r->irradiance);
    json_triple(f, "irradiance_stderr", r->irradiance_se);
    json_triple(f, "irradiance_ci95_lo", v[0]), json_triple(f, "irradiance_ci95_hi", v[1]); /* null: none certified */
    json_triple(f, answer_key, r->radiosity); /* null off the surfaces */
    json_triple(f, "stderr", r->radiosity_se);
    json_triple(f, "ci95_lo", v[2]), json_triple(f, "ci95_hi", v[3]);
    fprintf(f, "\"walks\": %lld, \"rays\": %lld, \"cut\": %lld, ", (long long)r->run.walks, (long long)r->run.rays,
           (long long)r->run.cut);
    if (diag && r->run.walks > 0 && ulam__run_zero(r->irradiance, r->irradiance_se))
        ulam_json_string(f, "zero_reason", zero_reason(diag), 0);
    ulam_json_number(f, "seconds", r->run.seconds, 1);
    fprintf(f, "}");
}

/* The point queries' report (--at, --grid), text or JSON. */
static void print_points(FILE *f, const ulam_rad_run *run)
{
    const args *a = run->a;
    const ulam_scene *s = run->s;
    const points *q = &run->q;
    const ulam_rad_point *pts = q->pts;
    int64_t ngrid = q->ngrid, n = q->n;
    int interrupted = q->interrupted;
    const ulam_rad_scene_diag *diag = q->known ? &q->diag : NULL;
    ulam_rad_grid_summary gs = {0}, all;
    if (ngrid) ulam_rad_grid_stats(pts + a->nat, ngrid, &gs);
    ulam_rad_grid_stats(pts, n, &all);
    int64_t walks = all.walks, rays = all.rays;
    if (a->json) {
        fprintf(f, "{");
        ulam_json_string(f, "scene", a->scene, 0);
        fprintf(f, "\"points\": [");
        for (int k = 0; k < a->nat; k++) {
            if (k) fprintf(f, ", ");
            point_json(f, s, &pts[k], diag);
        }
        fprintf(f, "], ");
        if (ngrid) {
            fprintf(f, "\"grid\": {\"nu\": %d, \"nv\": %d, ", a->g.nu, a->g.nv);
            json_triple(f, "origin", a->g.origin), json_triple(f, "u", a->g.u), json_triple(f, "v", a->g.v);
            json_triple(f, "normal", a->g.normal);
            ulam_json_number(f, "illuminance_min", gs.min, 0);
            ulam_json_number(f, "illuminance_mean", gs.mean, 0);
            ulam_json_number(f, "uniformity", gs.uniformity, 0);
            ulam_json_number(f, "worst_rel_stderr_bound", gs.worst, 0);
            if (a->out) ulam_json_string(f, "out", interrupted ? "" : a->out, 0);
            if (a->image) ulam_json_string(f, "image", interrupted ? "" : a->image, 0);
            fprintf(f, "\"points\": [");
            for (int64_t k = a->nat; k < n; k++) {
                if (k > a->nat) fprintf(f, ", ");
                point_json(f, s, &pts[k], diag);
            }
            fprintf(f, "]}, ");
        }
        ulam_json_string(f, "estimator", a->o.estimator == ULAM_RAD_COLLISION ? "collision" : "next-event", 0);
        fprintf(f, "\"walks\": %lld, \"rays\": %lld, \"interrupted\": %s, ", (long long)walks, (long long)rays,
                interrupted ? "true" : "false");
        ulam_json_number(f, "seconds", q->seconds, 0);
        ulam__run_photo_report(f, run, 1);
        fprintf(f, "\"seed\": %llu}\n", (unsigned long long)a->o.exec.seed);
        return;
    }
    fprintf(f, "scene        %s: %lld patches\n", a->scene, (long long)s->npatches);
    for (int k = 0; k < a->nat; k++) point_text(f, s, k, &pts[k], pts[k].run.interrupted, diag);
    if (ngrid)
        fprintf(f, "grid         %d x %d sensors facing %.4g %.4g %.4g: illuminance (0.2126 R + 0.7152 G + 0.0722 B)\n"
                   "             min %.6g, mean %.6g, uniformity min/mean %.4f; worst relative error <= %.3g\n",
                a->g.nu, a->g.nv, a->g.normal[0], a->g.normal[1], a->g.normal[2], gs.min, gs.mean, gs.uniformity,
                gs.worst);
    if (ngrid && diag && !(gs.mean > 0)) scene_notes(f, diag, "note         ", "             ");
    if (ngrid && a->out && !interrupted) fprintf(f, "grid csv     %s\n", a->out);
    if (ngrid && a->image && !interrupted) fprintf(f, "grid image   %s (false colour, 0 .. %.4g)\n", a->image, q->hi);
    fprintf(f, "walks        %lld point walks (%s), %lld rays, %.4f s%s\n", (long long)walks,
            a->o.estimator == ULAM_RAD_COLLISION ? "collision" : "next-event with MIS", (long long)rays, q->seconds,
            interrupted ? "  [INTERRUPTED]" : "");
    ulam__run_photo_report(f, run, 0);
}

/* The report (ulam_radiosity_run.h). */
int ulam_rad_run_rel_err_met(const ulam_rad_run *run)
{
    const args *a = run ? run->a : NULL;
    const walked *w = run ? run->r.w : NULL;
    if (!a || !(a->o.stop.rel_err > 0) || run->listed || run->pointed) return -1; /* points: no rule stated */
    if (a->view) return run->r.view.unmet ? 0 : 1; /* "stopped short of their target" */
    if (!w) return -1;
    if (w->zero) return 0;                                              /* "--rel-err can never be met" */
    if (w->whole) return w->rel_err_met;                                /* the whole scene's (or --patches') rule */
    if (run->r.patch >= 0 && (!a->matrix_walk || a->o.mode == ULAM_ADJOINT)) return w->rel_err_met;
    return -1;
}

void ulam_rad_run_print(const ulam_rad_run *r, FILE *f)
{
    if (r->listed) print_list(f, r->a, r->s, r->want);
    else if (r->pointed) print_points(f, r);
    else if (r->a->json) print_json(f, r);
    else print_text(f, r);
    const double *Bd = r->Bd, *B = r->r.patch < 0 ? NULL : r->r.w ? r->w.B : Bd ? Bd + 3 * r->r.patch : NULL;
    if (!r->listed && !r->pointed && !r->a->json) ulam__run_photo_report_patch(f, r, B);
}

/* The CSV rows for --out: one a sensor of the grid, or one a patch. */
void ulam__run_write_csv(ulam_rad_run *run, FILE *f)
{
    if (!run->pointed) {
        row_header(f, ROW_CSV, &run->r.pv);
        for (int64_t p = 0; p < run->s->npatches; p++)
            if (!run->want || run->want[p]) row(f, ROW_CSV, run->s, p, &run->r.pv);
        run->r.out_written = 1;
        return;
    }
    const ulam_rad_grid *g = &run->a->g;
    const ulam_rad_point *pts = run->q.pts + run->a->nat;
    fprintf(f, "i,j,x,y,z,R,G,B,R_se,G_se,B_se,Y,Y_se_bound,walks,ci95_lo,ci95_hi\n");
    for (int j = 0; j < g->nv; j++)
        for (int i = 0; i < g->nu; i++) {
            const ulam_rad_point *r = &pts[(size_t)j * (size_t)g->nu + (size_t)i];
            double Y, se, lo, hi;
            ulam_rad_illuminance(r, &Y, &se);
            ulam_rad_illuminance_ci(r, &lo, &hi);
            fprintf(f, "%d,%d,%.17g,%.17g,%.17g", i + 1, j + 1, r->x[0], r->x[1], r->x[2]);
            for (int c = 0; c < 3; c++) fprintf(f, ",%.17g", r->irradiance[c]);
            for (int c = 0; c < 3; c++) fprintf(f, ",%.17g", r->irradiance_se[c]);
            fprintf(f, ",%.17g,%.17g,%lld,%.17g,%.17g\n", Y, se, (long long)r->run.walks, lo, hi);
        }
}
