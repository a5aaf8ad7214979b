/* ulam radiosity: a patch scene's radiosity by walks that sample F by ray casting, checked
 * against the LAPACK solve of the assembled system. */
#include "cli.h"
#include "photometry.h"
#include "ulam_radiosity_run.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char *const usage =
    "usage: ulam radiosity SCENE.obj [--patch K|LABEL] [--mode gather|shoot|final] [--patches LIST]\n"
    "                      [--estimator collision|absorption|next-event] [--mis power|balance|none]\n"
    "                      [--walks N] [--rel-err E] [--time S]\n"
    "                      [--seed S] [--threads T] [--max-steps K] [--subdivide L] [--ff-rays K]\n"
    "                      [--direct] [--check] [--matrix-walk] [--max-mem SIZE]\n"
    "                      [--image out.png] [--size WxH] [--exposure X] [--camera C]\n"
    "                      [--view-gather] [--coverage X]\n"
    "                      [--out patches.csv] [--all] [--list] [--json]\n"
    "       ulam radiosity SCENE.obj --at x,y,z[,nx,ny,nz] ... [--grid C0:C1:S[:n]] [walk options]\n"
    "\n"
    "Radiosity B = E + diag(rho) F B of a scene of diffuse patches (Wavefront OBJ + MTL: Kd is\n"
    "the reflectance, Ke the emission), per RGB channel.\n"
    "\n"
    "  --patch K|LABEL   the patch to answer: 1-based number, or an o/g label (the label's patch\n"
    "                    that contains the label's area centroid; else the one whose centroid is\n"
    "                    nearest it)\n"
    "  --list            print the patches (number, label, face, centroid, area) and stop\n"
    "  --mode gather     walks from the patch that gather emission (default; needs --patch):\n"
    "                    one patch without forming F\n"
    "  --mode shoot      particles from the emitters, tallied on every patch (for --image)\n"
    "  --estimator E     next-event (gathering by rays and points, the default there): at every\n"
    "                    patch or point a walk visits, one shadow ray to a point on an emitter\n"
    "                    (drawn by power and area); collision (score at every patch; the default\n"
    "                    for --mode shoot and --matrix-walk) or absorption (where it stops)\n"
    "  --mis H           next-event with the walk's own emitter hits by multiple importance\n"
    "                    sampling: power (default) or balance heuristic; none: light sampling\n"
    "                    alone (infinite variance at a patch sharing an edge with a light)\n"
    "  --walks N         stop after N walks (default 100000 when no rule is given)\n"
    "  --rel-err E, --time S, --seed S (default 1), --threads T (default: all cores),\n"
    "  --max-steps K (default 10^6): as in ulam solve\n"
    "                    (--rel-err: every nonzero channel)\n"
    "  --subdivide L     split faces into patches no longer than L on a side (default: none,\n"
    "                    a patch per face)\n"
    "  --ff-rays K       rays per patch when forming F (default 1000)\n"
    "  --direct          form F by ray casting and solve M = diag(rho_c) F with LAPACKE_dgesv\n"
    "  --check           with --patch: also the direct solve, and z = (walk - direct) / stderr\n"
    "  --matrix-walk     walk on the assembled M (ulam solve's engine) instead of casting rays:\n"
    "                    walks and LAPACK then share the very same F\n"
    "  --max-mem SIZE    refuse, before any ray, a run whose estimate (ray tracer, F, dense\n"
    "                    matrices, tallies, pictures) is more (default 4G)\n"
    "  --image out.png   render the shooting (or else direct) solution\n"
    "  --view-gather     with --image and --rel-err E: gather only the patches the camera sees,\n"
    "                    each to E (n_max / n)^X on every channel, n its pixels, n_max the most\n"
    "                    any patch has (--walks: a cap\n"
    "                    per patch, --time: for all)\n"
    "  --coverage X      that exponent, in [0, 1] (default 0.25, the fewest walks for a given\n"
    "                    pixel-summed squared error; 0: every seen patch to E)\n"
    "  --camera C        ex,ey,ez,ax,ay,az,ux,uy,uz,fov: eye, look-at point, up and horizontal\n"
    "                    field of view in degrees; 'cornell' for the Cornell box camera; default:\n"
    "                    frame the scene's bounding box, looking along +z\n"
    "  --size WxH        image size (default 512x512)\n"
    "  --exposure X      radiosity scale before the sRGB curve (default: auto)\n"
    "  --out FILE.csv    every patch: number, label, face, centroid, area, R G B and standard\n"
    "                    errors (and the direct values with --check or --direct); needs --mode\n"
    "                    shoot or --direct\n"
    ;

/* The usage's third part. */
static const char *const usage_mesh =
    "  --samples N       jittered rays a pixel (default 4); the linear picture is written as PFM\n"
    "                    and Radiance RGBE beside the PNG (out.png -> out.pfm, out.hdr)\n"
    "  --flat            one colour a patch (default: radiosity interpolated from the patch corners\n"
    "                    across each face's patches, creases between faces kept)\n"
    "  --all             print every patch too (a table; with --json a patches array)\n"
    "  --no-mesh-error   --patch: skip the mesh error (by default point queries on the continuous\n"
    "                    surfaces at the patch's centroid and half way to each vertex, each to\n"
    "                    twice --rel-err or with a quarter of --walks, print how far the patch's one value is\n"
    "                    from the surface's, beside the Monte Carlo error, and warn when it\n"
    "                    dominates)\n"
    "  --mesh-error N    with --out or --all (--mode shoot or --direct): every patch's mesh error as\n"
    "                    R_mesh G_mesh B_mesh columns, point queries of N walks each at the\n"
    "                    patch's quadrature points (cost: up to 5 N walks a patch)\n"
    "  --mesh-target E   adaptive subdivision instead of --subdivide (--mode shoot, --direct or\n"
    "                    --view-gather): split the patches where point queries show the surface's\n"
    "                    radiosity varies and (with --image) the camera's importance is high, until\n"
    "                    the importance-weighted mesh error is at most E (relative, e.g. 0.05);\n"
    "                    with --time S it takes at most half of S (what it measured whole is kept)\n"
    "  --max-patches N   stop splitting before the mesh passes N patches (default 100000, and what\n"
    "                    --max-mem allows)\n"
    "  --share X         --mode shoot --rel-err E without --patch runs until every lit patch meets E\n"
    "                    (a particle reached it), or with X the lit patches holding X of the lit\n"
    "                    area (0.5: the median by area), and names the patches none reached\n"
    "  --patches LIST    --mode final (and --list) on these patches only: comma-separated o/g\n"
    "                    labels (all of the label's patches), numbers K and ranges K-L as --list\n"
    "                    numbers them (e.g. floor or 1-100,200); --rel-err, --share, the summary,\n"
    "                    --all and --out count and show the chosen only\n";

/* The usage's second half (a literal each stays within C99's 4095 characters). */
static const char *const usage_points =
    "  --at x,y,z        a point query on the continuous surfaces (no mesh in the answer): the\n"
    "                    irradiance H arriving there and the radiosity B = E + rho H of the\n"
    "                    surface it lies on, by walks from the point itself (next-event with MIS\n"
    "                    at every vertex, Russian roulette); repeat for more points\n"
    "  --at x,y,z,nx,ny,nz  a sensor facing (nx, ny, nz) anywhere (irradiance only off the surfaces)\n"
    "  --grid x0,y0,z0:x1,y1,z1:S[:nx,ny,nz]  a sensor grid on a work plane: the rectangle with\n"
    "                    opposite corners C0 and C1 (equal in one coordinate: the plane), cells\n"
    "                    of about S, or S = NUxNV cells (the sensors at their centres), facing\n"
    "                    + that axis or n;\n"
    "                    irradiance per point with its error to --out CSV, a false-colour PNG with\n"
    "                    a scale bar to --image; --walks and --rel-err per point, --time for all\n"
    "  --json            print one JSON object\n"
    "\n"
    "A --rel-err target the report says is NOT met (or can never be met) exits 5, as in ulam solve.\n"
    "Ctrl-C stops the walks and prints the estimate so far (exit 130); a second Ctrl-C exits.\n";

static const char *const est_names[] = {"collision", "absorption", "next-event"};
static const char *const mis_names[] = {"power", "balance", "none"};
/* Everything the command was asked: the run's options (ulam_radiosity_run.h). */
typedef ulam_rad_run_opts args;

/* Parse --camera: 'cornell', or ex,ey,ez,ax,ay,az,ux,uy,uz,fov (degrees, horizontal). */
static int parse_camera(const char *cmd, const char *arg, ulam_camera *cam)
{
    if (!strcmp(arg, "cornell")) {
        *cam = ulam_camera_cornell();
        return 0;
    }
    double x[10];
    int used = 0;
    if (sscanf(arg, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf%n", &x[0], &x[1], &x[2], &x[3], &x[4], &x[5], &x[6], &x[7],
               &x[8], &x[9], &used) == 10 && !arg[used]) {
        double d[3] = {x[3] - x[0], x[4] - x[1], x[5] - x[2]}, dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        double c[3] = {d[1] * x[8] - d[2] * x[7], d[2] * x[6] - d[0] * x[8], d[0] * x[7] - d[1] * x[6]};
        int finite = 1;
        for (int k = 0; k < 10; k++) finite &= isfinite(x[k]);
        if (finite && dd > 0 && c[0] * c[0] + c[1] * c[1] + c[2] * c[2] > 1e-12 * dd * (x[6] * x[6] + x[7] * x[7] + x[8] * x[8]) &&
            x[9] > 0 && x[9] < 180) {
            *cam = (ulam_camera){.eye = {x[0], x[1], x[2]}, .dir = {d[0], d[1], d[2]}, .up = {x[6], x[7], x[8]},
                                 .focal = 1.0, .film = 2.0 * tan(x[9] * M_PI / 360.0)};
            return 0;
        }
    }
    return cli_usage_error(cmd, "--camera expects 'cornell' or ex,ey,ez,ax,ay,az,ux,uy,uz,fov (eye, look-at point "
                                "apart from it, an up not along the view, fov in (0, 180) degrees), got '%s'", arg);
}

/* Parse --at x,y,z[,nx,ny,nz] onto a's list. */
static int parse_at(const char *cmd, const char *arg, args *a)
{
    double x[6];
    int n = cli_parse_numbers(arg, 6, x) == 0 ? 6 : cli_parse_numbers(arg, 3, x) == 0 ? 3 : 0;
    if (!n || (n == 6 && !(x[3] * x[3] + x[4] * x[4] + x[5] * x[5] > 0)))
        return cli_usage_error(cmd, "--at expects x,y,z or x,y,z,nx,ny,nz (finite, a nonzero normal), got '%s'", arg);
    double *m = realloc((double *)a->at, (size_t)(a->nat + 1) * 6 * sizeof *m);
    if (!m) return cli_usage_error(cmd, "no memory for --at %s", arg);
    a->at = m;
    for (int k = 0; k < 6; k++) m[6 * a->nat + k] = k < n ? x[k] : NAN;
    a->nat++;
    return 0;
}

/* Parse --grid x0,y0,z0:x1,y1,z1:S[:nx,ny,nz]: corners equal in exactly one coordinate. */
static int parse_grid(const char *cmd, const char *arg, ulam_rad_grid *g)
{
    char buf[512];
    double c0[3], c1[3], S = 1.0, n[3];
    char *part[4] = {0};
    int np = 0;
    if (strlen(arg) < sizeof buf) {
        strcpy(buf, arg);
        for (char *t = strtok(buf, ":"); t && np < 4; t = strtok(NULL, ":")) part[np++] = t;
    }
    int cu = 0, cv = 0, used = 0; /* S may be counts NUxNV instead of a spacing */
    int counts = np >= 3 && sscanf(part[2], "%dx%d%n", &cu, &cv, &used) == 2 && !part[2][used];
    int ok = (np == 3 || np == 4) && !cli_parse_numbers(part[0], 3, c0) && !cli_parse_numbers(part[1], 3, c1) &&
             (counts ? cu >= 1 && cv >= 1 : !cli_parse_numbers(part[2], 1, &S) && S > 0) &&
             (np == 3 || !cli_parse_numbers(part[3], 3, n));
    int flat = -1, eq = 0;
    for (int k = 0; ok && k < 3; k++)
        if (c0[k] == c1[k]) flat = k, eq++;
    if (!ok || eq != 1)
        return cli_usage_error(cmd, "--grid expects x0,y0,z0:x1,y1,z1:S[:nx,ny,nz], opposite corners of a rectangle "
                                    "equal in exactly one coordinate (its plane) and a spacing S > 0 or counts NUxNV, "
                                    "got '%s'", arg);
    int ax[2], m = 0;
    for (int k = 0; k < 3; k++)
        if (k != flat) ax[m++] = k;
    memset(g, 0, sizeof *g);
    for (int k = 0; k < 3; k++) g->origin[k] = c0[k];
    g->u[ax[0]] = c1[ax[0]] - c0[ax[0]], g->v[ax[1]] = c1[ax[1]] - c0[ax[1]];
    double nu = counts ? cu : fmax(1.0, round(fabs(g->u[ax[0]]) / S));
    double nv = counts ? cv : fmax(1.0, round(fabs(g->v[ax[1]]) / S));
    if (nu * nv > ULAM_RAD_GRID_MAX)
        return cli_usage_error(cmd, "--grid %s makes %.0f x %.0f points, more than %d", arg, nu, nv, ULAM_RAD_GRID_MAX);
    g->nu = (int)nu, g->nv = (int)nv;
    double len = 0.0, big = 0.0;
    for (int k = 0; k < 3; k++) g->normal[k] = np == 4 ? n[k] : k == flat, big = fmax(big, fabs(g->normal[k]));
    for (int k = 0; k < 3 && big > 0; k++) g->normal[k] /= big, len += g->normal[k] * g->normal[k]; /* 1e200^2 overflowed */
    if (!(len > 0)) return cli_usage_error(cmd, "--grid: the normal must not be zero, got '%s'", arg);
    for (int k = 0; k < 3; k++) g->normal[k] /= sqrt(len);
    return 0;
}

/* Parse the options into a; 0, or an exit code (with -1 meaning: --help printed). */
static int parse(int argc, char **argv, args *a, cli_photo *ph)
{
    static const struct option longopts[] = {
        {"patch", required_argument, 0, 'p'},     {"mode", required_argument, 0, 'm'},
        {"estimator", required_argument, 0, 'e'}, CLI_WALK_OPTION("walks"),
        CLI_WALK_OPTION("rel-err"),               CLI_WALK_OPTION("time"),
        CLI_WALK_OPTION("seed"),                  CLI_WALK_OPTION("threads"),
        CLI_WALK_OPTION("max-steps"),             {"subdivide", required_argument, 0, 'L'},
        {"ff-rays", required_argument, 0, 'f'},   {"direct", no_argument, 0, 'd'},
        {"check", no_argument, 0, 'c'},           {"matrix-walk", no_argument, 0, 'M'},
        {"max-mem", required_argument, 0, 'x'},   {"image", required_argument, 0, 'i'},
        {"size", required_argument, 0, 'z'},      {"exposure", required_argument, 0, 'X'},
        {"json", no_argument, 0, 'J'},            {"help", no_argument, 0, 'h'},
        {"out", required_argument, 0, 'o'},       {"all", no_argument, 0, 'A'},
        {"list", no_argument, 0, 'l'},            {"camera", required_argument, 0, 'C'},
        {"mis", required_argument, 0, 'H'},       {"view-gather", no_argument, 0, 'V'},
        {"coverage", required_argument, 0, 'G'},  {"at", required_argument, 0, 'P'},
        {"grid", required_argument, 0, 'R'},     {"no-mesh-error", no_argument, 0, 'N'},
        {"mesh-error", required_argument, 0, 'W'},  {"samples", required_argument, 0, 'S'},
        {"flat", no_argument, 0, 'F'},           {"mesh-target", required_argument, 0, 'T'},
        {"max-patches", required_argument, 0, 'K'}, {"share", required_argument, 0, 'Y'},
        {"luminaire", required_argument, 0, 'Q'}, {"unit", required_argument, 0, 'Q'},
        {"maintenance", required_argument, 0, 'Q'}, {"en12464", required_argument, 0, 'Q'},
        {"patches", required_argument, 0, 'U'},
        {0, 0, 0, 0}};
    const char *cmd = "radiosity";
    int c, rc, idx;
    if (cli_check_options("radiosity", argc, argv, longopts)) return EXIT_USAGE;
    optind = 0;
    while ((c = getopt_long(argc, argv, "h", longopts, &idx)) != -1) {
        switch (c) {
        case CLI_WALK: if ((rc = cli_walk_option(cmd, longopts[idx].name, optarg, &a->o))) return rc; break;
        case 'p': a->patch = optarg; break;
        case 'U': a->patches = optarg; break; /* resolved on the scene (ulam_rad_run_alloc) */
        case 'Y': if ((rc = cli_parse_real(cmd, "--share", optarg, 1e-9, 1.0, &a->share))) return rc; break;
        case 'm':
            if ((a->o.mode = ulam_rad_mode_find(optarg)) < 0) /* the library's table of modes */
                return cli_usage_error(cmd, "--mode expects gather, shoot or final, got '%s'", optarg);
            if ((a->final = a->o.mode == ULAM_RAD_FINAL)) a->o.mode = ULAM_FORWARD; /* every patch, as shoot */
            break;
        case 'e':
            if ((a->est = cli_lookup(optarg, est_names, 3)) < 0)
                return cli_usage_error(cmd, "--estimator expects collision, absorption or next-event, got '%s'", optarg);
            break;
        case 'H':
            if ((a->mis = cli_lookup(optarg, mis_names, 3)) < 0)
                return cli_usage_error(cmd, "--mis expects power, balance or none, got '%s'", optarg);
            break;
        case 'L': if ((rc = cli_parse_real(cmd, "--subdivide", optarg, 1e-9, 1e300, &a->subdivide))) return rc; break;
        case 'f': if ((rc = cli_parse_int(cmd, "--ff-rays", optarg, 1, INT32_MAX, &a->ff_rays))) return rc; break;
        case 'd': a->direct = 1; break;
        case 'c': a->check = 1; break;
        case 'M': a->matrix_walk = 1; break;
        case 'x': if ((rc = cli_parse_bytes(cmd, "--max-mem", optarg, &a->max_mem))) return rc; break;
        case 'i': a->image = optarg; break;
        case 'z':
            if (sscanf(optarg, "%dx%d", &a->width, &a->height) != 2 || a->width < 1 || a->height < 1 ||
                a->width > 16384 || a->height > 16384)
                return cli_usage_error(cmd, "--size expects WxH from 1x1 to 16384x16384, got '%s'", optarg);
            break;
        case 'X': if ((rc = cli_parse_real(cmd, "--exposure", optarg, 1e-300, 1e300, &a->exposure))) return rc; break;
        case 'J': a->json = 1; break;
        case 'V': a->view = 1; break;
        case 'G': if ((rc = cli_parse_real(cmd, "--coverage", optarg, 0.0, 1.0, &a->coverage))) return rc; break;
        case 'o': a->out = optarg; break;
        case 'A': a->all = 1; break;
        case 'l': a->list = 1; break;
        case 'C': if ((rc = parse_camera(cmd, optarg, &a->cam))) return rc; a->camera_given = 1; break;
        case 'N': a->no_mesh = 1; break;
        case 'F': a->flat = 1; break;
        case 'S': {
            int64_t v;
            if ((rc = cli_parse_int(cmd, "--samples", optarg, 1, 1024, &v))) return rc;
            a->samples = (int)v;
            break;
        }
        case 'T': if ((rc = cli_parse_real(cmd, "--mesh-target", optarg, 1e-6, 10.0, &a->mesh_target))) return rc; break;
        case 'K': if ((rc = cli_parse_int(cmd, "--max-patches", optarg, 1, INT32_MAX, &a->max_patches))) return rc; break;
        case 'W': if ((rc = cli_parse_int(cmd, "--mesh-error", optarg, 1, INT32_MAX, &a->mesh_walks))) return rc; break;
        case 'P': if ((rc = parse_at(cmd, optarg, a))) return rc; break;
        case 'R': if ((rc = parse_grid(cmd, optarg, &a->g))) return rc; a->grid = 1; break;
        case 'Q': if ((rc = cli_photo_option(ph, a, cmd, longopts[idx].name, optarg))) return rc; break;
        case 'h':
            fputs(usage, stdout), fputs(usage_mesh, stdout), fputs(usage_points, stdout), fputs(cli_photo_usage, stdout);
            return -1;
        default: return cli_usage_error(cmd, "unknown option");
        }
    }
    if (optind != argc - 1) return cli_usage_error(cmd, "expects exactly one scene file");
    a->scene = argv[optind];
    if (a->list) return 0;
    if ((rc = cli_photo_finish(ph, a, cmd))) return rc;
    if (a->max_patches && !(a->mesh_target > 0)) return cli_usage_error(cmd, "--max-patches needs --mesh-target E");
    if (a->mesh_target > 0 && (a->subdivide > 0 || a->nat || a->grid || a->patch ||
                               (a->o.mode != ULAM_FORWARD && !a->direct && !a->view)))
        return cli_usage_error(cmd, "--mesh-target is for whole-scene and image runs (--mode shoot, --direct or "
                                    "--view-gather; not with --subdivide, --patch, --at or --grid, whose point "
                                    "queries have no mesh)");
    if (a->nat || a->grid) {
        if (a->patch || a->o.mode != ULAM_ADJOINT || a->direct || a->check || a->matrix_walk || a->view || a->all ||
            (a->est >= 0 && a->est != 2 && a->est != 0) || ((a->out || a->image) && !a->grid))
            return cli_usage_error(cmd, "--at and --grid are point queries by gathering walks (no --patch, --mode "
                                        "shoot, --direct, --check, --matrix-walk, --view-gather, --all, --estimator "
                                        "absorption; --out and --image with --grid)");
        a->o.estimator = a->est == 0 ? ULAM_RAD_COLLISION : ULAM_RAD_NEXT_EVENT + (a->mis > 0 ? a->mis : 0);
        if (a->mis >= 0 && a->est == 0) return cli_usage_error(cmd, "--mis needs --estimator next-event");
        cli_walk_budget(&a->o);
        return 0;
    }
    if (a->est < 0) a->est = a->o.mode == ULAM_FORWARD || a->matrix_walk ? 0 : 2; /* next-event where it applies */
    if (a->view && (!a->image || !(a->o.stop.rel_err > 0) || a->o.mode != ULAM_ADJOINT || a->direct || a->matrix_walk ||
                    a->patch || a->check || a->out || a->all))
        return cli_usage_error(cmd, "--view-gather needs --image and --rel-err, and gathers by rays only (no --mode "
                                    "shoot, --direct, --matrix-walk, --patch, --check, --out or --all)");
    if (a->mis >= 0 && a->est != 2) return cli_usage_error(cmd, "--mis needs --estimator next-event");
    if (a->est == 2 && (a->o.mode != ULAM_ADJOINT || a->matrix_walk))
        return cli_usage_error(cmd, "--estimator next-event is for gathering by rays (not --mode shoot or "
                                    "--matrix-walk)");
    /* matrix walks take ulam.h's enum, ray walks enum ulam_rad_estimator */
    a->o.estimator = a->matrix_walk ? a->est : a->est == 0 ? ULAM_RAD_COLLISION : a->est == 1 ? ULAM_RAD_ABSORPTION
                                                             : ULAM_RAD_NEXT_EVENT + (a->mis > 0 ? a->mis : 0);
    if ((a->out || a->all) && a->o.mode == ULAM_ADJOINT && !a->direct)
        return cli_usage_error(cmd, "%s needs --mode shoot or --direct (gathering answers one patch)",
                               a->out ? "--out" : "--all");
    if (a->patches && !a->final && !a->list)
        return cli_usage_error(cmd, "--patches chooses the patches of --mode final (or of --list)");
    if (!a->patch && a->o.mode == ULAM_ADJOINT && !a->direct && !a->view)
        return cli_usage_error(cmd, "needs --patch K (gathering answers one patch), --mode shoot or --direct");
    if (a->check && !a->patch) return cli_usage_error(cmd, "--check needs --patch K");
    if (a->mesh_walks && !a->out && !a->all) return cli_usage_error(cmd, "--mesh-error N needs --out or --all");
    if (a->image && a->o.mode == ULAM_ADJOINT && !a->direct && !a->view)
        return cli_usage_error(cmd, "--image needs --mode shoot, --direct or --view-gather (gathering answers one "
                                    "patch)");
    cli_walk_budget(&a->o);
    return 0;
}


/* The progress line of ray walks (ulam_rad_run_opts.progress): 0 start, 1 show, 2 end. */
static void progress(void *ctx, const ulam_walk_opts *o, int what, int64_t walks, double estimate, double se)
{
    static cli_progress pg;
    if (what == 0) cli_progress_start(&pg, *(const int *)ctx);
    else if (what == 1) cli_progress_show(&pg, walks, estimate, se, o);
    else cli_progress_end(&pg);
}

/* Catch Ctrl-C (the walks stop) or release it. */
static void interrupt_hook(int on)
{
    on ? cli_catch_sigint() : cli_release_sigint();
}

/* --out: the run's rows as CSV, atomically; 0 or an exit code. */
static int write_csv(ulam_rad_run *run, const char *path)
{
    ulam_outfile o;
    int status = cli_outfile_open(&o, path);
    if (!status) {
        ulam_rad_run_write(run, ULAM_RAD_RUN_CSV, o.f);
        status = cli_outfile_commit(&o);
    }
    if (!status) return 0;
    ulam_error err = {.status = status, .msg = "a writable output file"};
    return cli_report(path, &err);
}

/* A run's status as an exit code (its line already written). */
static int exit_code(int status)
{
    return status == ULAM_RAD_RUN_USAGE ? EXIT_USAGE : status == ULAM_RAD_RUN_INTERRUPTED ? EXIT_INTERRUPTED
                                                                                        : cli_exit_code(status);
}

/* ulam radiosity. */
int cli_radiosity(int argc, char **argv)
{
    args a = ulam_rad_run_defaults();
    cli_photo ph = {0};
    char hdr[4096], rgbe[4096]; /* the PFM and the Radiance .hdr beside --image */
    a.o.stop.interrupt = &cli_interrupted, a.o.exec.share = cli_share;
    a.log = cli_rank == 0 ? stderr : NULL, a.rank = cli_rank, a.started = cli_started;
    a.catch_interrupt = interrupt_hook, a.hold_signals = cli_hold_signals, a.progress = progress, a.progress_ctx = &a.json;
    int rc = parse(argc, argv, &a, &ph), interrupted = 0;
    ulam_rad_run *run = NULL;
    if (rc) goto done;
    if (a.est == 2 && a.mis == 2 && cli_rank == 0)
        fprintf(stderr, "ulam radiosity: warning: --mis none (light sampling alone) has infinite variance at a patch "
                        "that shares an edge with a light or nearly touches one: there the error bar can be far too "
                        "small (the edge-lamp scene: z = -4.6); the MIS default is bounded\n");
    if (a.image) { /* the PFM beside the PNG: out.png -> out.pfm */
        size_t len = strlen(a.image);
        int png = len > 4 && !strcmp(a.image + len - 4, ".png");
        if (len + 5 > sizeof hdr) {
            rc = cli_usage_error("radiosity", "--image: a path shorter than 4 KiB");
            goto done; /* every early exit frees what parse() made (--at's list: the 48-byte leak) */
        }
        snprintf(hdr, sizeof hdr, "%.*s.pfm", (int)(png ? len - 4 : len), a.image);
        snprintf(rgbe, sizeof rgbe, "%.*s.hdr", (int)(png ? len - 4 : len), a.image);
        a.pfm = hdr, a.hdr = rgbe;
    }
    const cli_file outs[] = {{"--image", a.image}, {"--image's PFM", a.image && !a.grid ? a.pfm : NULL},
                             {"--image's HDR", a.image && !a.grid ? a.hdr : NULL}, {"--out", a.out}},
                   ins[] = {{"the scene", a.scene}};
    if ((rc = cli_check_outputs("radiosity", outs, 4, ins, 1))) goto done;
    int st = ulam_rad_run_alloc(&a, &run);
    if (!st) st = ulam_rad_run_solve(run, &interrupted);
    if (st) {
        rc = exit_code(st);
        goto done;
    }
    int write = !interrupted && !a.list && (a.nat || a.grid ? a.grid : cli_rank == 0); /* the files, then the report */
    if (a.out && write && (rc = write_csv(run, a.out))) goto done;
    if (a.image && write && (st = ulam_rad_run_write(run, ULAM_RAD_RUN_IMAGE, NULL))) {
        rc = exit_code(st);
        goto done;
    }
    ulam_rad_run_print(run, stdout);
    cli_json_done = a.json;
    if (interrupted) rc = EXIT_INTERRUPTED;
    else if (ulam_rad_run_rel_err_met(run) == 0) rc = EXIT_TARGET; /* printed "NOT met" (or "never"), as solve */
done:
    ulam_rad_run_free(run);
    free((double *)a.at);
    cli_photo_free(&ph);
    return rc < 0 ? 0 : rc;
}
