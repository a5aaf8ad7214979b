/* ulam radiosity: a patch scene's radiosity by walks that sample F by ray casting, checked
 * against the LAPACK solve of the assembled system. */
#include "cli.h"
#include "photometry.h"
#include "ulam_radiosity.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char *const usage =
    "usage: ulam radiosity SCENE.obj [--patch K|LABEL] [--mode gather|shoot|final]\n"
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
    "                    area (0.5: the median by area), and names the patches none reached\n";

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
    "Ctrl-C stops the walks and prints the estimate so far (exit 130); a second Ctrl-C exits.\n";

static const char *const est_names[] = {"collision", "absorption", "next-event"};
static const char *const mis_names[] = {"power", "balance", "none"};
static const char *const chan = "RGB";

/* The JSON key of the answer (the radiosity), in one place so that it can be renamed. */
static const char *const answer_key = "radiosity";

/* Everything the command was asked. */
typedef struct {
    const char *scene, *patch, *image, *out;
    double subdivide, exposure;
    int64_t ff_rays;
    int direct, check, matrix_walk, json, width, height, all, list;
    int est, mis; /* indices into est_names and mis_names (-1: not given) */
    int view;     /* --view-gather */
    int final;    /* --mode final (o.mode ULAM_FORWARD: every patch) */
    int no_mesh;  /* --no-mesh-error */
    int samples, flat; /* --samples N jittered rays a pixel, --flat: one colour a patch */
    char hdr[4096];    /* the PFM beside --image */
    char rgbe[4096];   /* the Radiance .hdr beside --image */
    int64_t mesh_walks; /* --mesh-error N: every patch's mesh error in --out / --all, N walks a point */
    double mesh_target;  /* --mesh-target E: adaptive subdivision to mesh error E (0: none) */
    int64_t max_patches; /* --max-patches N (0: not given) */
    double *at;   /* --at: 6 per point (the normal NaN when not given) */
    int nat;
    int grid;     /* --grid given: g holds it */
    ulam_rad_grid g;
    double coverage;
    double share; /* --share X: shooting's whole-scene rule holds this share of the lit area (0: 1) */
    int camera_given; /* --camera: cam holds it */
    ulam_camera cam;
    size_t max_mem;
    ulam_walk_opts o;
    cli_photo ph; /* --luminaire, --unit, --maintenance, --en12464 (photometry.c) */
} args;

/* The radiosity options of the walk options the command line gave (mode, estimator, patch,
 * stopping rules, seed, threads, processes). */
static ulam_rad_opts rad_opts(const ulam_walk_opts *o)
{
    ulam_rad_opts r = ulam_rad_defaults();
    r.mode = o->mode, r.estimator = o->estimator, r.index = o->query.index, r.stop = o->stop, r.exec = o->exec;
    return r;
}

/* What the walks found. */
typedef struct {
    double B[3], se[3], se_walk[3]; /* se: with --matrix-walk, the walk's and F's noise combined */
    int64_t walks, steps, cut; /* cut: walks stopped at --max-steps */
    int64_t channel_walks[3]; /* --matrix-walk: each channel's walks (walks is their sum) */
    int ff_limited[3];        /* --matrix-walk --rel-err: F's error alone is past the target */
    double seconds;
    int threads, interrupted;
    int zero;    /* --rel-err could never be met: every channel exactly 0, zero variance */
    int rel_err_met;  /* ray walks: the run stopped because the --rel-err rule holds */
    double min_walks; /* ray walks: the walks the rule needs at this estimate */
    double ci95[3][2]; /* ray walks: each channel's 95% interval (NaN: none certified) */
    double *all, *all_se; /* shooting: 3 per patch each */
    int whole;                 /* shooting --rel-err without --patch: the whole scene's rule */
    ulam_rad_scene_rule scene; /* its state at the end */
    int64_t unreached[8];      /* the first patches no particle reached */
} walked;

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
    double *m = realloc(a->at, (size_t)(a->nat + 1) * 6 * sizeof *m);
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
static int parse(int argc, char **argv, args *a)
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
        {0, 0, 0, 0}};
    const char *cmd = "radiosity";
    int c, rc, idx;
    if (cli_check_options("radiosity", argc, argv, longopts)) return EXIT_USAGE;
    optind = 0;
    while ((c = getopt_long(argc, argv, "h", longopts, &idx)) != -1) {
        switch (c) {
        case CLI_WALK: if ((rc = cli_walk_option(cmd, longopts[idx].name, optarg, &a->o))) return rc; break;
        case 'p': a->patch = optarg; break;
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
        case 'Q': if ((rc = cli_photo_option(&a->ph, cmd, longopts[idx].name, optarg))) return rc; break;
        case 'h':
            fputs(usage, stdout), fputs(usage_mesh, stdout), fputs(usage_points, stdout), fputs(cli_photo_usage, stdout);
            return -1;
        default: return cli_usage_error(cmd, "unknown option");
        }
    }
    if (optind != argc - 1) return cli_usage_error(cmd, "expects exactly one scene file");
    a->scene = argv[optind];
    if (a->list) return 0;
    if ((rc = cli_photo_finish(&a->ph, cmd, a->grid, &a->g, &a->grid))) return rc;
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

/* The 0-based patch that --patch names; 0 or an exit code. */
static int find_patch(const ulam_scene *s, const char *arg, int64_t *p)
{
    char *end;
    long long k = strtoll(arg, &end, 10);
    if (end != arg && !*end) {
        if (k < 1 || k > s->npatches)
            return cli_usage_error("radiosity", "--patch %s is out of range 1..%lld", arg, (long long)s->npatches);
        *p = k - 1;
        return 0;
    }
    if (ulam_scene_find(s, arg, p) == ULAM_OK) return 0;
    fprintf(stderr, "ulam radiosity: --patch '%s' is neither a patch number nor a label; labels:", arg);
    for (int64_t g = 0; g < s->ngroups; g++) fprintf(stderr, " %s", s->groups[g]);
    fprintf(stderr, "\n");
    return EXIT_USAGE;
}

/* After the first round: say so when the rel-err rule's minimum walk count (the bound on one
 * walk's score: a bright emitter a walk rarely hits) is out of reach, and name next-event. */
static void rel_err_warning(const args *a, const ulam_rad_result *r)
{
    double limit = a->o.stop.max_walks > 0 && a->o.stop.max_walks < ULAM_REL_ERR_CAP ? (double)a->o.stop.max_walks : 1e8;
    if (!(a->o.stop.rel_err > 0) || !(r->min_walks > limit)) return;
    if (a->o.mode == ULAM_FORWARD || a->o.estimator < ULAM_RAD_COLLISION) { /* next-event or shooting */
        fprintf(stderr, "ulam: %s: warning: --rel-err %g: the rule needs about %.3g walks at this estimate before it "
                        "may stop (%s): one walk's certified score range is wide against the estimate\n",
                a->scene, a->o.stop.rel_err, r->min_walks, limit < 1e8 ? "more than --walks" : "out of reach in practice");
        return;
    }
    fprintf(stderr, "ulam: %s: warning: --rel-err %g: one walk can score up to a bright emitter's radiosity at every "
                    "bounce, so the rule needs about %.3g walks at this estimate before it may stop (%s): "
                    "--estimator next-event samples the emitters directly and has no such tail\n",
            a->scene, a->o.stop.rel_err, r->min_walks, limit < 1e8 ? "more than --walks" : "out of reach in practice");
}

/* --mode final (ulam_rad_final): every patch; 0 or an exit code. */
static int final_walks(const args *a, const ulam_tracer *t, int64_t np, walked *w)
{
    ulam_error err;
    ulam_rad_opts ro = rad_opts(&a->o);
    ulam_rad_final_info in;
    double *half = malloc((size_t)np * 3 * sizeof *half);
    w->all = malloc((size_t)np * 3 * sizeof *w->all), w->all_se = malloc((size_t)np * 3 * sizeof *w->all_se);
    if (!half || !w->all || !w->all_se) return free(half), cli_exit_code(ULAM_ENOMEM);
    cli_catch_sigint();
    int status = ulam_rad_final(t, &ro, 0, a->share > 0 ? a->share : 1.0, w->all, w->all_se, half, &in, &err);
    cli_release_sigint();
    if (status) return free(half), cli_report(a->scene, &err);
    int64_t p = a->o.query.index;
    for (int c = 0; c < 3; c++)
        w->B[c] = w->all[3 * p + c], w->se[c] = w->se_walk[c] = w->all_se[3 * p + c],
        w->ci95[c][0] = fmax(0.0, w->B[c] - half[3 * p + c]), w->ci95[c][1] = w->B[c] + half[3 * p + c];
    w->walks = in.samples, w->steps = in.rays + in.particle_rays, w->seconds = in.seconds, w->threads = in.threads;
    w->interrupted = in.interrupted, w->rel_err_met = in.met, w->scene = in.scene;
    w->whole = a->o.stop.rel_err > 0 && !a->patch;
    memcpy(w->unreached, in.unreached, sizeof w->unreached);
    free(half);
    return 0;
}

/* Ray walks (gathering or shooting); 0 or an exit code. */
static int ray_walks(const args *a, const ulam_tracer *t, int64_t np, walked *w)
{
    if (a->final) return final_walks(a, t, np, w);
    ulam_rad_solver *sv = NULL;
    ulam_error err;
    ulam_rad_opts ro = rad_opts(&a->o);
    int status = ulam_rad_solver_alloc(t, &ro, &sv, &err);
    if (status) return cli_report(a->scene, &err);
    w->whole = a->o.mode == ULAM_FORWARD && a->o.stop.rel_err > 0 && !a->patch; /* the whole scene, not patch 1 */
    if (w->whole) ulam_rad_solver_whole(sv, a->share > 0 ? a->share : 1.0);
    cli_catch_sigint();
    cli_progress pg;
    cli_progress_start(&pg, a->json);
    ulam_rad_result r;
    for (int round = 0; !status && !ulam_rad_solver_done(sv); round++) {
        status = ulam_rad_solver_iterate(sv);
        ulam_rad_solver_result(sv, &r);
        if (round == 0) rel_err_warning(a, &r);
        cli_progress_show(&pg, r.walks, r.radiosity[0], r.std_error[0], &a->o); /* the red channel */
    }
    cli_progress_end(&pg);
    cli_release_sigint();
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
    if (!status) return 0;
    fprintf(stderr, "ulam: %s: error: %s\n", a->scene, ulam_strerror(status));
    return cli_exit_code(status);
}

/* Walks on the assembled M, one channel at a time (at a patch with --rel-err: to the combined
 * rule of ulam_rad_walk_target, given F's error ff and the direct solution Bd there); 0 or an
 * exit code. */
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
    cli_catch_sigint();
    for (int c = 0; c < 3 && !status && !cli_interrupted; c++) {
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
        w->walks += r.walks, w->steps += r.steps, w->seconds += r.seconds, w->cut += r.cut;
        w->threads = r.threads, w->interrupted |= r.interrupted;
        if (!status && w->all) {
            ulam_solver_vectors(sv, x, e);
            for (int64_t i = 0; i < n; i++) w->all[3 * i + c] = x[i], w->all_se[3 * i + c] = e[i];
        }
        ulam_solver_free(sv);
        ulam_csr_free(M);
    }
    cli_release_sigint();
    free(b), free(x), free(e);
    w->zero = a->o.stop.rel_err > 0;
    for (int c = 0; c < 3; c++) w->zero &= w->B[c] == 0 && w->se[c] == 0;
    if (!status) return 0;
    err.status = status;
    return cli_report(a->scene, &err);
}

/* The whole scene's rule after shooting --rel-err without --patch: how many lit patches met it,
 * the worst one, and the patches no particle reached. */
static void print_scene_rule(const args *a, const walked *w)
{
    const ulam_rad_scene_rule *q = &w->scene;
    printf("rel-err      %s on the whole scene: %lld of %lld lit patches (%.4g of the lit area; the rule: %.4g) within "
           "%g;\n             the largest relative standard error %.3g, 95%% half-width %.3g (patch %lld)\n",
           w->rel_err_met ? "met" : "NOT met", (long long)q->met, (long long)q->lit,
           q->lit_area > 0 ? q->met_area / q->lit_area : 0.0, q->share, a->o.stop.rel_err, q->worst_se, q->worst_half,
           (long long)q->worst_patch + 1);
    if (q->unreached) {
        printf("unreached    %lld patches no particle reached in %lld walks (each gets under 3/%lld of the particles, "
               "95%%):", (long long)q->unreached, (long long)w->walks, (long long)w->walks);
        for (int64_t k = 0; k < q->unreached && k < 8; k++) printf(" %lld", (long long)w->unreached[k] + 1);
        printf("%s\n", q->unreached > 8 ? " ..." : "");
    }
}

/* Print a JSON array of three numbers under key. */
static void json_triple(const char *key, const double *v)
{
    printf("\"%s\": [", key);
    for (int c = 0; c < 3; c++) {
        cli_json_value(v[c]);
        printf(c < 2 ? ", " : "], ");
    }
}

/* Every patch's values for --out and --all (NULL arrays: not known): the answer (the walks' if
 * they covered every patch, else the direct one) with its standard error, and the direct
 * answer beside walks. */
typedef struct {
    const double *B, *se, *Bd, *sed;
    const double *mesh; /* --mesh-error: every patch's mesh error (3 each), or NULL */
} patch_values;

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
    fputc('\n', f);
}

/* One patch's row: number, label, face, centroid, area, then (v) the values; an unknown value
 * is an empty CSV field, '-' in the table, null in JSON (which goes to stdout). */
static void row(FILE *f, int fmt, const ulam_scene *s, int64_t p, const patch_values *v)
{
    static const char *const keys[] = {"x", "y", "z", "area", "R", "G", "B", "R_se", "G_se", "B_se",
                                       "direct_R", "direct_G", "direct_B", "direct_R_se", "direct_G_se", "direct_B_se",
                                       "R_mesh", "G_mesh", "B_mesh"};
    double x[19];
    const char *key[19];
    int n = 4;
    ulam_scene_centroid(s, p, x);
    x[3] = s->area[p];
    const double *cols[4] = {v ? v->B : NULL, v ? v->se : NULL, v ? v->Bd : NULL, v ? v->sed : NULL};
    for (int k = 0; k < 4; k++) key[k] = keys[k];
    for (int k = 0; v && k < (v->Bd ? 4 : 2); k++)
        for (int c = 0; c < 3; c++) key[n] = keys[n], x[n++] = cols[k] ? cols[k][3 * p + c] : NAN;
    for (int c = 0; v && v->mesh && c < 3; c++) key[n] = keys[16 + c], x[n++] = v->mesh[3 * p + c];
    int32_t g = s->group[p];
    const char *label = g >= 0 ? s->groups[g] : "";
    if (fmt == ROW_JSON) {
        printf("{\"patch\": %lld, ", (long long)p + 1);
        cli_json_string("label", label, 0);
        printf("\"face\": %lld, ", (long long)s->face[p] + 1);
        for (int k = 0; k < n; k++) cli_json_number(key[k], x[k], k == n - 1);
        printf("}");
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
static void print_list(const args *a, const ulam_scene *s)
{
    if (a->json) {
        printf("{");
        cli_json_string("scene", a->scene, 0);
        printf("\"patches\": [");
    }
    else row_header(stdout, ROW_TEXT, NULL);
    for (int64_t p = 0; p < s->npatches; p++) {
        if (a->json && p) printf(", ");
        row(stdout, a->json ? ROW_JSON : ROW_TEXT, s, p, NULL);
    }
    if (a->json) printf("]}\n");
}

/* --out: every patch as CSV, atomically; 0 or an exit code. */
static int write_csv(const char *path, const ulam_scene *s, const patch_values *v)
{
    ulam_outfile o;
    int status = cli_outfile_open(&o, path);
    if (!status) {
        row_header(o.f, ROW_CSV, v);
        for (int64_t p = 0; p < s->npatches; p++) row(o.f, ROW_CSV, s, p, v);
        status = cli_outfile_commit(&o);
    }
    if (!status) return 0;
    ulam_error err = {.status = status, .msg = "a writable output file"};
    return cli_report(path, &err);
}

/* What the run found, as text or JSON. */
typedef struct {
    const ulam_scene *s;
    int64_t patch, faces;
    const ulam_csr *F;
    ulam_ff_report ff;
    double ff_seconds, direct_seconds, exposure;
    int image_written, out_written;
    patch_values pv;
    const double *Bdirect;
    double direct_se[3]; /* at the patch, from the noise of F (--check, --matrix-walk) */
    int ff_se_known;     /* direct_se was computed (--matrix-walk: unless --max-mem refused it) */
    double *direct_se_all; /* every patch's (--out, --all), NULL when not computed */
    const double *w_all_se_conditional; /* matrix forward walks whose se lack F's noise, or NULL */
    const walked *w;
    ulam_view_info view; /* --view-gather */
    int mesh_known;      /* mesh holds the patch's mesh error (ray gathering at --patch) */
    int mesh_no_time;    /* the mesh error was not estimated: the walks spent --time */
    ulam_rad_mesh mesh;
    int adapted, view_importance; /* --mesh-target: adapt holds what it did (by the view's importance) */
    ulam_rad_adapt_info adapt;
    int64_t adapt_cap; /* the most patches it could make (--max-patches, or what --max-mem holds) */
    int diag_known;    /* the answer is exactly 0 and diag says why (scene_notes) */
    ulam_rad_scene_diag diag;
} report;

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
static void check_side(const args *a, const report *r, int c)
{
    double d = r->Bdirect[3 * r->patch + c], lo = r->w->ci95[c][0], hi = r->w->ci95[c][1];
    printf("check %c      |z| = %.2g: ", chan[c], fabs(zscore(a, r, c)));
    if (a->matrix_walk)
        printf("the walks on the same F disagree with its direct solve: the walks' noise (or a bug)\n");
    else if (isfinite(lo) && isfinite(hi) && (d < lo || d > hi))
        printf("the direct solve, %.6g, lies %s the walks' certified 95%% interval %.6g .. %.6g:\n"
               "             suspect the form factors (%lld rays a patch; raise --ff-rays)\n", d,
               d < lo ? "below" : "above", lo, hi, (long long)a->ff_rays);
    else if (isfinite(lo) && isfinite(hi))
        printf("the direct solve, %.6g, lies inside the walks' certified 95%% interval %.6g .. %.6g:\n"
               "             its form-factor bar is too narrow (raise --ff-rays)\n", d, lo, hi);
    else
        printf("the walks have no certified interval here to tell which side is off\n");
}

/* Nonzero when the mesh error of channel c dominates the Monte Carlo error: larger than twice
 * it, and real (more than 4 standard errors of the difference: the largest of up to 9). */
static int mesh_dominates(const report *r, const walked *w, int c)
{
    double e = r->mesh.error[c], se = sqrt(w->se[c] * w->se[c] + r->mesh.error_se[c] * r->mesh.error_se[c]);
    return e > 2 * w->se[c] && e > 4 * se;
}

/* The mesh error lines of the text report. */
static void print_mesh(const report *r, const walked *w)
{
    int any = 0;
    for (int c = 0; c < 3; c++) {
        double lo = INFINITY, hi = -INFINITY;
        for (int k = 0; k < r->mesh.npoints; k++) lo = fmin(lo, r->mesh.point[k][c]), hi = fmax(hi, r->mesh.point[k][c]);
        printf("mesh error %c %.3g (Monte Carlo %.3g): the surface reads %.8g +- %.3g at the patch's centroid, "
               "%.6g .. %.6g at its %d quadrature points\n", chan[c], r->mesh.error[c], w->se[c], r->mesh.point[0][c],
               r->mesh.point_se[0][c], lo, hi, r->mesh.npoints);
        any |= mesh_dominates(r, w, c);
    }
    if (any)
        printf("warning      the mesh error dominates the Monte Carlo error: this patch's one value stands for a\n"
               "             surface whose radiosity differs from it by more; ask --at a point (no mesh), or\n"
               "             --subdivide finer\n");
}

/* The adaptive mesh's line of the text report. */
static void print_adapt(const args *a, const report *r)
{
    const ulam_rad_adapt_info *d = &r->adapt;
    char why[96];
    int64_t asked = a->max_patches ? a->max_patches : 100000;
    if (asked > r->adapt_cap) snprintf(why, sizeof why, "NOT met (--max-mem holds %lld patches)", (long long)r->adapt_cap);
    else snprintf(why, sizeof why, "NOT met (--max-patches %lld)", (long long)r->adapt_cap);
    if (d->interrupted) snprintf(why, sizeof why, "NOT met (cut by --time, half of it, or Ctrl-C; the last mesh measured whole kept)");
    if (isnan(d->error)) { /* cut inside the first round: the scene as read */
        printf("mesh         adaptive (%s importance): NOT measured (cut in the first round by --time or Ctrl-C); the scene's "
               "%lld patches kept, target %g; %lld point queries, %.3f s\n", r->view_importance ? "the view's" : "area",
               (long long)d->patches, a->mesh_target, (long long)d->points, d->seconds);
        return;
    }
    printf("mesh         adaptive (%s importance): %lld -> %lld patches, %lld split in %lld rounds; mesh error "
           "%.3g -> %.3g, target %g %s; %lld point queries, %lld rays, %.3f s\n", r->view_importance ? "the view's" : "area",
           (long long)d->patches_in, (long long)d->patches, (long long)d->splits, (long long)d->rounds, d->error0,
           d->error, a->mesh_target, d->met ? "met" : why, (long long)d->points, (long long)d->rays, d->seconds);
}

/* Rays cast by scene_diagnosis from the fronts (and as many from the backs). */
enum { DIAG_RAYS = 4096 };

/* Nonzero when every channel of v is exactly 0 with a zero standard error se. */
static int exactly_zero(const double v[3], const double se[3])
{
    for (int c = 0; c < 3; c++)
        if (v[c] != 0.0 || se[c] != 0.0) return 0;
    return 1;
}

/* What is wrong with a scene that answers 0 (ulam_rad_scene_diagnose); 0 when nothing is found. */
static int scene_diagnosis(const ulam_tracer *t, uint64_t seed, ulam_rad_scene_diag *d)
{
    return ulam_rad_scene_diagnose(t, DIAG_RAYS, seed, d) == ULAM_OK;
}

/* scene_notes' finding as a JSON word: no_emitter, inside_out, lamps_face_out or unreached. */
static const char *zero_reason(const ulam_rad_scene_diag *d)
{
    double fr = (double)d->front[0] / DIAG_RAYS, br = (double)d->back[1] / DIAG_RAYS;
    if (!d->emitters) return "no_emitter";
    if (br > 0.25 && br > 2.0 * fr) return "inside_out";
    if (d->lamp[0] + d->lamp[1] + d->lamp[2] > 0 && d->lamp[0] == 0) return "lamps_face_out";
    return "unreached";
}

/* Print what is wrong with a scene whose answer is exactly 0 (label: the first line's label
 * column, indent the next lines'). */
static void scene_notes(const ulam_rad_scene_diag *d, const char *label, const char *indent)
{
    double fr = (double)d->front[0] / DIAG_RAYS, br = (double)d->back[1] / DIAG_RAYS; /* front to front, back to back */
    int64_t lamp = d->lamp[0] + d->lamp[1] + d->lamp[2];
    const char *why = zero_reason(d);
    if (!strcmp(why, "no_emitter"))
        printf("%sthe scene has no emitter: no material has Ke > 0, so no light enters it and every\n"
               "%sradiosity is exactly 0 (give the lamps' material Ke)\n", label, indent);
    else if (!strcmp(why, "inside_out"))
        printf("%sthe faces look inside out: %.0f%% of rays leaving the patches' backs land on another's\n"
               "%sback, %.0f%% of those leaving their fronts on a front (OBJ faces are counter-clockwise seen\n"
               "%sfrom their lit side: reverse each face's vertex order)\n", label, 100.0 * br, indent, 100.0 * fr, indent);
    else if (!strcmp(why, "lamps_face_out"))
        printf("%sno emitter's front faces into the scene: of %lld rays leaving the lamps' fronts, %lld\n"
               "%sleave the scene and %lld land on a back side (turn the lamps' faces around)\n", label,
               (long long)lamp, (long long)d->lamp[2], indent, (long long)d->lamp[1]);
    else
        printf("%sthe scene has %lld emitting patches and its faces face in (%.0f%% of the fronts' rays land\n"
               "%son a front): no emitter's light reaches here\n", label, (long long)d->emitters, 100.0 * fr, indent);
}

/* Nonzero when the walks' interval covers a cut at --max-steps (ray gathering by next-event or
 * collision, whose walks have a certified tail; the library widens the interval by it). */
static int cut_covered(const args *a)
{
    return !a->matrix_walk && a->o.mode == ULAM_ADJOINT && a->o.estimator != ULAM_RAD_ABSORPTION;
}

/* Print the text report. */
static void print_text(const args *a, const report *r)
{
    printf("scene        %s: %lld faces, %lld patches\n", a->scene, (long long)r->faces, (long long)r->s->npatches);
    if (r->adapted) print_adapt(a, r);
    if (r->F)
        printf("form factors %lld rays a patch, %.3f s: reciprocity error %.3g, row sums %.4f .. %.4f "
               "(mean %.4f), %lld nonzeros\n", (long long)a->ff_rays, r->ff_seconds, r->ff.reciprocity,
               r->ff.rowsum_min, r->ff.rowsum_max, r->ff.rowsum_mean, (long long)r->ff.nnz);
    if (r->Bdirect) printf("direct       LAPACKE_dgesv, 3 channels, %.3f s\n", r->direct_seconds);
    if (r->patch >= 0) {
        int32_t g = r->s->group[r->patch];
        double c[3];
        ulam_scene_centroid(r->s, r->patch, c);
        printf("patch        %lld (%s, face %lld, area %.6g, centroid %.6g %.6g %.6g)\n", (long long)r->patch + 1,
               g >= 0 ? r->s->groups[g] : "unlabelled", (long long)r->s->face[r->patch] + 1, r->s->area[r->patch],
               c[0], c[1], c[2]);
    }
    const walked *w = r->w;
    if (w && w->cut) /* before the numbers: they are biased low */
        printf("warning      %lld of %lld walks cut at --max-steps %lld: the estimate is biased low (the light\n"
               "             beyond the cut is lost); %s (raise --max-steps)\n", (long long)w->cut, (long long)w->walks,
               (long long)a->o.stop.max_steps, cut_covered(a) ? "the interval includes the most the cut can miss"
                                                               : "the error bar does not cover the bias");
    if (w && r->patch >= 0) {
        for (int c = 0; c < 3; c++) {
            printf("radiosity %c  %.8g +- %.3g", chan[c], w->B[c], w->se[c]);
            if (a->matrix_walk && r->ff_se_known) printf(" (walk %.3g, form factors %.3g)", w->se_walk[c], r->direct_se[c]);
            else if (a->matrix_walk) printf(" (walk noise only, CONDITIONAL on the sampled F: its noise is unknown)");
            else if (isfinite(w->ci95[c][0])) printf(" (95%% CI %.8g .. %.8g)", w->ci95[c][0], w->ci95[c][1]);
            else printf(" (no 95%% interval: no score range certified)");
            printf("%s\n", w->interrupted ? "  [INTERRUPTED]" : "");
        }
        if (a->o.stop.rel_err > 0 && !a->matrix_walk && !w->zero)
            printf("rel-err      %s (%g; the rule's range term wants %.3g walks)\n", w->rel_err_met ? "met" : "NOT met",
                   a->o.stop.rel_err, w->min_walks);
        if (w->zero)
            printf("note         every channel is exactly 0 with zero variance after %lld walks (no walk scored):\n"
                   "             --rel-err can never be met by a zero estimate, so the walks stopped there; if the\n"
                   "             answer is not exactly 0, a walk scores with probability below 3/%lld = %.2g (95%%)\n",
                   (long long)w->walks, (long long)w->walks, 3.0 / (double)w->walks);
        if (r->diag_known) scene_notes(&r->diag, "note         ", "             ");
        if (r->mesh_known) print_mesh(r, w);
        if (r->mesh_no_time)
            printf("mesh error   not estimated: the walks spent --time (raise it, or --no-mesh-error)\n");
    }
    if (w)
        printf("walks        %lld %s %s walks, %lld %s, %.4f s (%.3g M %s/s, %d threads)%s\n", (long long)w->walks,
               a->matrix_walk ? "matrix" : "ray", ulam_rad_mode_name(a->final ? ULAM_RAD_FINAL : a->o.mode, NULL), (long long)w->steps,
               a->matrix_walk ? "steps" : "rays", w->seconds, w->seconds > 0 ? (double)w->steps / w->seconds / 1e6 : 0.0,
               a->matrix_walk ? "steps" : "rays", w->threads, w->interrupted ? "  [INTERRUPTED]" : "");
    if (w && w->whole) print_scene_rule(a, w);
    for (int c = 0; w && a->matrix_walk && c < 3; c++)
        if (w->ff_limited[c])
            printf("rel-err      NOT met in %c: the form factors' error alone is %.3g, past --rel-err %g of the "
                   "answer; more walks cannot meet it, more --ff-rays can (F's error falls as 1/sqrt(rays))\n",
                   chan[c], r->direct_se[c], a->o.stop.rel_err);
    if (w && a->matrix_walk)
        printf("             (one walk a channel: %lld R + %lld G + %lld B)\n", (long long)w->channel_walks[0],
               (long long)w->channel_walks[1], (long long)w->channel_walks[2]);
    if (a->view)
        printf("view         %lld of %lld patches seen (%lld of %lld pixels), each to %.3g (n_max / n)^%.3g: "
               "%lld camera rays + %lld walk rays, %.4f s%s\n", (long long)r->view.seen, (long long)r->view.npatches,
               (long long)r->view.pixels_hit, (long long)r->view.camera_rays, a->o.stop.rel_err, a->coverage,
               (long long)r->view.camera_rays, (long long)r->view.rays, r->view.seconds,
               r->view.unmet ? "" : ", every seen patch met its target");
    if (a->view && r->view.unmet)
        printf("warning      %lld seen patches stopped short of their target (--walks or --time)\n",
               (long long)r->view.unmet);
    if (r->Bdirect && r->patch >= 0)
        for (int c = 0; c < 3; c++) {
            printf("direct %c     %.8g", chan[c], r->Bdirect[3 * r->patch + c]);
            if (r->ff_se_known) printf(" +- %.3g (form-factor noise)", r->direct_se[c]);
            if (w) printf("  z = %.3f%s", zscore(a, r, c), a->matrix_walk ? " (walk noise: the same F)" : "");
            printf("\n");
        }
    for (int c = 0; r->Bdirect && r->patch >= 0 && w && c < 3; c++)
        if (fabs(zscore(a, r, c)) > 3.0) check_side(a, r, c);
    if (a->out && r->out_written)
        printf("patches      %lld rows written to %s%s\n", (long long)r->s->npatches, a->out,
               r->pv.se == r->w_all_se_conditional ? " (standard errors: walk noise only, CONDITIONAL on the sampled F)" : "");
    else if (a->out && w && w->interrupted) printf("patches      not written: the run was interrupted\n");
    if (a->all) {
        row_header(stdout, ROW_TEXT, &r->pv);
        for (int64_t p = 0; p < r->s->npatches; p++) row(stdout, ROW_TEXT, r->s, p, &r->pv);
    }
    if (a->image && r->image_written) printf("image        %s (exposure %.4g)\n", a->image, r->exposure);
    else if (a->image && w && w->interrupted) printf("image        not written: the run was interrupted\n");
}

/* Print the JSON object. */
static void print_json(const args *a, const report *r)
{
    printf("{");
    cli_json_string("scene", a->scene, 0); /* a path may hold quotes and backslashes */
    printf("\"npatches\": %lld, ", (long long)r->s->npatches);
    if (r->adapted) {
        char e[2][32]; /* null: --time ran out before the first mesh was measured whole */
        for (int k = 0; k < 2; k++)
            if (isnan(k ? r->adapt.error : r->adapt.error0)) snprintf(e[k], sizeof e[k], "null");
            else snprintf(e[k], sizeof e[k], "%.6g", k ? r->adapt.error : r->adapt.error0);
        printf("\"adaptive\": {\"importance\": \"%s\", \"patches_in\": %lld, \"patches\": %lld, \"splits\": %lld, "
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
        printf("\"patch\": %lld, ", (long long)r->patch + 1);
        cli_json_string("label", g >= 0 ? r->s->groups[g] : "", 0);
        json_triple("centroid", c);
    }
    const walked *w = r->w;
    if (w) {
        if (r->patch >= 0) {
            json_triple("estimate", w->B); /* the answer's key in every command */
            json_triple(answer_key, w->B);
            json_triple("stderr", w->se);
            if (!a->matrix_walk) {
                double lo[3] = {w->ci95[0][0], w->ci95[1][0], w->ci95[2][0]};
                double hi[3] = {w->ci95[0][1], w->ci95[1][1], w->ci95[2][1]};
                json_triple("ci95_lo", lo); /* each channel's 95% interval (null: none certified) */
                json_triple("ci95_hi", hi);
            }
            if (r->mesh_known) {
                int dom = 0;
                for (int c = 0; c < 3; c++) dom |= mesh_dominates(r, w, c);
                json_triple("mesh_error", r->mesh.error);
                json_triple("mesh_error_stderr", r->mesh.error_se);
                json_triple("surface_at_centroid", r->mesh.point[0]);
                json_triple("surface_at_centroid_stderr", r->mesh.point_se[0]);
                printf("\"mesh_error_dominates\": %s, ", dom ? "true" : "false");
            }
            if (r->mesh_no_time) cli_json_string("mesh_error_skipped", "the walks spent --time", 0);
            if (a->matrix_walk) {
                json_triple("walk_stderr", w->se_walk);
                if (r->ff_se_known) json_triple("ff_stderr", r->direct_se);
            }
        }
        cli_json_string("mode", ulam_rad_mode_name(a->final ? ULAM_RAD_FINAL : a->o.mode, NULL), 0);
        cli_json_string("estimator", est_names[a->est], 0);
        if (a->est == 2) cli_json_string("mis", mis_names[a->mis > 0 ? a->mis : 0], 0);
        printf("\"matrix_walk\": %s, \"walks\": %lld, \"%s\": %lld, \"cut\": %lld, \"max_steps\": %lld, ",
               a->matrix_walk ? "true" : "false", (long long)w->walks, a->matrix_walk ? "steps" : "rays",
               (long long)w->steps, (long long)w->cut, (long long)a->o.stop.max_steps);
        if (a->matrix_walk) /* walks is their sum: a matrix walk carries one channel */
            printf("\"channel_walks\": [%lld, %lld, %lld], ", (long long)w->channel_walks[0],
                   (long long)w->channel_walks[1], (long long)w->channel_walks[2]);
        cli_json_number("seconds", w->seconds, 0);
        printf("\"interrupted\": %s, \"zero\": %s, ", w->interrupted ? "true" : "false", w->zero ? "true" : "false");
        if (r->diag_known) cli_json_string("zero_reason", zero_reason(&r->diag), 0);
        if (w->whole)
            printf("\"scene_rule\": {\"met\": %s, \"lit\": %lld, \"lit_met\": %lld, \"unreached\": %lld, "
                   "\"share\": %.6g, \"area_met\": %.6g, \"worst_patch\": %lld, \"worst_half\": %.6g, \"worst_se\": %.6g}, ",
                   w->rel_err_met ? "true" : "false", (long long)w->scene.lit, (long long)w->scene.met,
                   (long long)w->scene.unreached, w->scene.share,
                   w->scene.lit_area > 0 ? w->scene.met_area / w->scene.lit_area : 0.0,
                   (long long)w->scene.worst_patch + 1, w->scene.worst_half, w->scene.worst_se);
        if (a->o.stop.rel_err > 0 && !a->matrix_walk && a->o.mode == ULAM_ADJOINT) {
            printf("\"rel_err_met\": %s, ", w->rel_err_met ? "true" : "false");
            cli_json_number("min_walks", w->min_walks, 0);
        }
    }
    if (a->view) {
        printf("\"view\": {\"seen\": %lld, \"npatches\": %lld, \"pixels_hit\": %lld, \"camera_rays\": %lld, "
               "\"walks\": %lld, \"rays\": %lld, \"unmet\": %lld, ", (long long)r->view.seen,
               (long long)r->view.npatches, (long long)r->view.pixels_hit, (long long)r->view.camera_rays,
               (long long)r->view.walks, (long long)r->view.rays, (long long)r->view.unmet);
        cli_json_number("rel_err", a->o.stop.rel_err, 0);
        cli_json_number("coverage", a->coverage, 0);
        cli_json_number("seconds", r->view.seconds, 1);
        printf("}, ");
    }
    if (r->F) {
        printf("\"ff_rays\": %lld, ", (long long)a->ff_rays);
        cli_json_number("ff_seconds", r->ff_seconds, 0);
        cli_json_number("reciprocity", r->ff.reciprocity, 0);
        cli_json_number("rowsum_min", r->ff.rowsum_min, 0);
        cli_json_number("rowsum_max", r->ff.rowsum_max, 0);
    }
    if (r->Bdirect && r->patch >= 0) {
        double z[3];
        for (int c = 0; c < 3; c++) z[c] = w ? zscore(a, r, c) : NAN;
        json_triple("direct", r->Bdirect + 3 * r->patch);
        if (r->ff_se_known) json_triple("direct_stderr", r->direct_se);
        if (w) json_triple("z", z);
        cli_json_number("direct_seconds", r->direct_seconds, 0);
    }
    if (a->image) {
        if (r->image_written) cli_json_string("image", a->image, 0), cli_json_number("exposure", r->exposure, 0);
        else printf("\"image\": null, ");
    }
    if (a->out) {
        if (r->out_written) cli_json_string("out", a->out, 0);
        else printf("\"out\": null, ");
    }
    if (a->all) {
        printf("\"stderr_conditional_on_F\": %s, \"patches\": [", r->pv.se == r->w_all_se_conditional ? "true" : "false");
        for (int64_t p = 0; p < r->s->npatches; p++) {
            if (p) printf(", ");
            row(stdout, ROW_JSON, r->s, p, &r->pv);
        }
        printf("], ");
    }
    cli_photo_report(&a->ph, r->s, NULL, 0, 0, 1, ulam_rad_luma(), NULL, NULL); /* photometric runs: the luminaires */
    printf("\"seed\": %llu}\n", (unsigned long long)a->o.exec.seed);
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
static void point_text(const ulam_scene *s, int k, const ulam_rad_point *r, int interrupted,
                       const ulam_rad_scene_diag *diag)
{
    printf("point %-6d %.6g %.6g %.6g, normal %.4g %.4g %.4g", k + 1, r->x[0], r->x[1], r->x[2], r->n[0], r->n[1],
           r->n[2]);
    if (r->patch >= 0) {
        int32_t g = s->group[r->patch];
        printf(" (patch %lld, %s)\n", (long long)r->patch + 1, g >= 0 ? s->groups[g] : "unlabelled");
    } else {
        printf(" (a sensor on no surface)\n");
    }
    if (r->run.cut)
        printf("  warning    %lld of %lld walks cut at --max-steps: the estimate is biased low; the interval includes\n"
               "             the most the cut can miss (raise --max-steps)\n", (long long)r->run.cut,
               (long long)r->run.walks);
    double lo[3][2], hi[3][2];
    point_ci(s, r, lo, hi);
    for (int c = 0; c < 3; c++) {
        printf("  irradiance %c %.8g +- %.3g", chan[c], r->irradiance[c], r->irradiance_se[c]);
        if (isfinite(lo[c][0])) printf(" (95%% CI %.6g .. %.6g)", lo[c][0], hi[c][0]);
        if (r->patch >= 0) printf("   radiosity %c %.8g +- %.3g", chan[c], r->radiosity[c], r->radiosity_se[c]);
        if (r->patch >= 0 && isfinite(lo[c][1])) printf(" (95%% CI %.6g .. %.6g)", lo[c][1], hi[c][1]);
        printf("%s\n", interrupted ? "  [INTERRUPTED]" : "");
    }
    printf("  walks      %lld, %lld rays, %.4f s\n", (long long)r->run.walks, (long long)r->run.rays, r->run.seconds);
    if (diag && !interrupted && r->run.walks > 0 && exactly_zero(r->irradiance, r->irradiance_se))
        scene_notes(diag, "  note       ", "             ");
}

/* One point's answer as a JSON object. */
static void point_json(const ulam_scene *s, const ulam_rad_point *r, const ulam_rad_scene_diag *diag)
{
    double lo[3][2], hi[3][2], v[4][3];
    point_ci(s, r, lo, hi);
    for (int c = 0; c < 3; c++) v[0][c] = lo[c][0], v[1][c] = hi[c][0], v[2][c] = lo[c][1], v[3][c] = hi[c][1];
    printf("{");
    json_triple("x", r->x);
    json_triple("normal", r->n);
    printf("\"patch\": ");
    if (r->patch >= 0) printf("%lld, ", (long long)r->patch + 1);
    else printf("null, ");
    json_triple("irradiance", r->irradiance);
    json_triple("irradiance_stderr", r->irradiance_se);
    json_triple("irradiance_ci95_lo", v[0]), json_triple("irradiance_ci95_hi", v[1]); /* null: none certified */
    json_triple(answer_key, r->radiosity); /* null off the surfaces */
    json_triple("stderr", r->radiosity_se);
    json_triple("ci95_lo", v[2]), json_triple("ci95_hi", v[3]);
    printf("\"walks\": %lld, \"rays\": %lld, \"cut\": %lld, ", (long long)r->run.walks, (long long)r->run.rays,
           (long long)r->run.cut);
    if (diag && r->run.walks > 0 && exactly_zero(r->irradiance, r->irradiance_se))
        cli_json_string("zero_reason", zero_reason(diag), 0);
    cli_json_number("seconds", r->run.seconds, 1);
    printf("}");
}

/* --grid: the CSV (one row a sensor), atomically; 0 or an exit code. */
static int write_grid_csv(const char *path, const ulam_rad_grid *g, const ulam_rad_point *pts)
{
    ulam_outfile o;
    int status = cli_outfile_open(&o, path);
    if (!status) {
        fprintf(o.f, "i,j,x,y,z,R,G,B,R_se,G_se,B_se,Y,Y_se_bound,walks,ci95_lo,ci95_hi\n");
        for (int j = 0; j < g->nv; j++)
            for (int i = 0; i < g->nu; i++) {
                const ulam_rad_point *r = &pts[(size_t)j * (size_t)g->nu + (size_t)i];
                double Y, se, lo, hi;
                ulam_rad_illuminance(r, &Y, &se);
                ulam_rad_illuminance_ci(r, &lo, &hi);
                fprintf(o.f, "%d,%d,%.17g,%.17g,%.17g", i + 1, j + 1, r->x[0], r->x[1], r->x[2]);
                for (int c = 0; c < 3; c++) fprintf(o.f, ",%.17g", r->irradiance[c]);
                for (int c = 0; c < 3; c++) fprintf(o.f, ",%.17g", r->irradiance_se[c]);
                fprintf(o.f, ",%.17g,%.17g,%lld,%.17g,%.17g\n", Y, se, (long long)r->run.walks, lo, hi);
            }
        status = cli_outfile_commit(&o);
    }
    if (!status) return 0;
    ulam_error err = {.status = status, .msg = "a writable output file"};
    return cli_report(path, &err);
}

/* --grid --image: the false-colour picture of the illuminance, 0 to the largest; 0 or an exit code. */
static int write_grid_png(const char *path, const ulam_rad_grid *g, const ulam_rad_point *pts, double *hi)
{
    size_t n = (size_t)g->nu * (size_t)g->nv;
    double *Y = malloc(n * sizeof *Y), se;
    /* cells in the grid's proportions, the longer side of the picture 480 pixels */
    double lu = sqrt(g->u[0] * g->u[0] + g->u[1] * g->u[1] + g->u[2] * g->u[2]) / g->nu;
    double lv = sqrt(g->v[0] * g->v[0] + g->v[1] * g->v[1] + g->v[2] * g->v[2]) / g->nv;
    double scale = 480.0 / fmax(lu * g->nu, lv * g->nv);
    int cw = (int)fmax(2.0, round(lu * scale)), ch = (int)fmax(2.0, round(lv * scale)), w, h;
    int status = Y ? ULAM_OK : ULAM_ENOMEM;
    *hi = 0.0;
    for (size_t k = 0; Y && k < n; k++) {
        ulam_rad_illuminance(&pts[k], &Y[k], &se);
        *hi = fmax(*hi, Y[k]);
    }
    if (!(*hi > 0)) *hi = 1.0;
    ulam_falsecolour_size(g->nu, g->nv, cw, ch, &w, &h);
    unsigned char *rgb = Y ? malloc((size_t)w * (size_t)h * 3) : NULL;
    if (!status) status = rgb ? ulam_falsecolour(Y, g->nu, g->nv, cw, ch, 0.0, *hi, rgb) : ULAM_ENOMEM;
    if (!status) {
        cli_hold_signals(1); /* its temporary file is the library's: a signal waits until it is gone */
        status = ulam_png_write(path, w, h, rgb);
        cli_hold_signals(0);
    }
    free(Y), free(rgb);
    if (!status) return 0;
    ulam_error err = {.status = status, .msg = "a writable PNG file"};
    return cli_report(path, &err);
}

/* --at and --grid: point queries; 0 or an exit code. */
static int run_points(const args *a, const ulam_tracer *t, const ulam_scene *s)
{
    int64_t ngrid = a->grid ? (int64_t)a->g.nu * a->g.nv : 0, n = a->nat + ngrid;
    ulam_rad_point *pts = calloc((size_t)n, sizeof *pts);
    ulam_error err = {.status = ULAM_ENOMEM, .msg = "memory for the points"};
    if (!pts) return cli_report(a->scene, &err);
    int rc = 0, interrupted = 0;
    double t0 = ulam_now();
    cli_catch_sigint();
    ulam_rad_opts po = rad_opts(&a->o);
    if (a->nat && ulam_rad_points_solve(t, &po, a->at, a->nat, pts, &err)) { /* each point its own walks */
        const double *x = a->at + 6 * err.index;
        fprintf(stderr, "ulam radiosity: --at %g,%g,%g: %s: %s\n", x[0], x[1], x[2], ulam_strerror(err.status), err.msg);
        rc = err.status == ULAM_EINVAL ? EXIT_USAGE : cli_exit_code(err.status); /* the point itself */
        goto done;
    }
    for (int k = 0; k < a->nat; k++) interrupted |= pts[k].run.interrupted;
    if (ngrid && !interrupted) {
        ulam_rad_opts ro = rad_opts(&a->o);
        if (ulam_rad_grid_solve(t, &ro, &a->g, pts + a->nat, &err)) {
            rc = cli_report(a->scene, &err);
            goto done;
        }
        for (int64_t k = a->nat; k < n; k++) interrupted |= pts[k].run.interrupted || !pts[k].run.walks;
    }
    cli_photo_points((cli_photo *)&a->ph, t, (ulam_scene *)s, pts, n); /* the luminaires' direct light; Ke back */
    double seconds = ulam_now() - t0, hi = 0.0;
    cli_release_sigint();
    if (ngrid && !interrupted && a->out && (rc = write_grid_csv(a->out, &a->g, pts + a->nat))) goto done;
    if (ngrid && !interrupted && a->image && (rc = write_grid_png(a->image, &a->g, pts + a->nat, &hi))) goto done;
    ulam_rad_grid_summary gs = {0}, all;
    if (ngrid) ulam_rad_grid_stats(pts + a->nat, ngrid, &gs);
    ulam_rad_grid_stats(pts, n, &all);
    int64_t walks = all.walks, rays = all.rays;
    ulam_rad_scene_diag diag; /* what is wrong with the scene, when a point reads exactly 0 */
    int known = 0;
    for (int64_t k = 0; k < n && !known; k++)
        if (pts[k].run.walks > 0 && exactly_zero(pts[k].irradiance, pts[k].irradiance_se))
            known = scene_diagnosis(t, a->o.exec.seed, &diag);
    if (a->json) {
        printf("{");
        cli_json_string("scene", a->scene, 0);
        printf("\"points\": [");
        for (int k = 0; k < a->nat; k++) {
            if (k) printf(", ");
            point_json(s, &pts[k], known ? &diag : NULL);
        }
        printf("], ");
        if (ngrid) {
            printf("\"grid\": {\"nu\": %d, \"nv\": %d, ", a->g.nu, a->g.nv);
            json_triple("origin", a->g.origin), json_triple("u", a->g.u), json_triple("v", a->g.v);
            json_triple("normal", a->g.normal);
            cli_json_number("illuminance_min", gs.min, 0);
            cli_json_number("illuminance_mean", gs.mean, 0);
            cli_json_number("uniformity", gs.uniformity, 0);
            cli_json_number("worst_rel_stderr_bound", gs.worst, 0);
            if (a->out) cli_json_string("out", interrupted ? "" : a->out, 0);
            if (a->image) cli_json_string("image", interrupted ? "" : a->image, 0);
            printf("\"points\": [");
            for (int64_t k = a->nat; k < n; k++) {
                if (k > a->nat) printf(", ");
                point_json(s, &pts[k], known ? &diag : NULL);
            }
            printf("]}, ");
        }
        cli_json_string("estimator", a->o.estimator == ULAM_RAD_COLLISION ? "collision" : "next-event", 0);
        printf("\"walks\": %lld, \"rays\": %lld, \"interrupted\": %s, ", (long long)walks, (long long)rays,
               interrupted ? "true" : "false");
        cli_json_number("seconds", seconds, 0);
        cli_photo_report(&a->ph, s, pts, a->nat, ngrid, 1, ulam_rad_luma(), ulam_rad_illuminance,
                         ulam_rad_illuminance_ci);
        printf("\"seed\": %llu}\n", (unsigned long long)a->o.exec.seed);
    } else {
        printf("scene        %s: %lld patches\n", a->scene, (long long)s->npatches);
        for (int k = 0; k < a->nat; k++) point_text(s, k, &pts[k], pts[k].run.interrupted, known ? &diag : NULL);
        if (ngrid)
            printf("grid         %d x %d sensors facing %.4g %.4g %.4g: illuminance (0.2126 R + 0.7152 G + 0.0722 B)\n"
                   "             min %.6g, mean %.6g, uniformity min/mean %.4f; worst relative error <= %.3g\n",
                   a->g.nu, a->g.nv, a->g.normal[0], a->g.normal[1], a->g.normal[2], gs.min, gs.mean, gs.uniformity,
                   gs.worst);
        if (ngrid && known && !(gs.mean > 0)) scene_notes(&diag, "note         ", "             ");
        if (ngrid && a->out && !interrupted) printf("grid csv     %s\n", a->out);
        if (ngrid && a->image && !interrupted) printf("grid image   %s (false colour, 0 .. %.4g)\n", a->image, hi);
        printf("walks        %lld point walks (%s), %lld rays, %.4f s%s\n", (long long)walks,
               a->o.estimator == ULAM_RAD_COLLISION ? "collision" : "next-event with MIS", (long long)rays, seconds,
               interrupted ? "  [INTERRUPTED]" : "");
        cli_photo_report(&a->ph, s, pts, a->nat, ngrid, 0, ulam_rad_luma(), ulam_rad_illuminance,
                         ulam_rad_illuminance_ci);
    }
    if (interrupted) rc = EXIT_INTERRUPTED;
done:
    cli_release_sigint();
    free(pts);
    return rc;
}

/* The camera asked for, or the one framing the scene. */
static ulam_camera camera_of(const args *a, const ulam_scene *s)
{
    return a->camera_given ? a->cam : ulam_camera_frame(s, a->width, a->height);
}

/* --view-gather: the seen patches' answers into w->all; 0 or an exit code. */
static int view_walks(const args *a, const ulam_tracer *t, const ulam_scene *s, walked *w, ulam_view_info *vi)
{
    ulam_camera cam = camera_of(a, s);
    ulam_error err;
    w->all = malloc((size_t)s->npatches * 3 * sizeof *w->all);
    w->all_se = malloc((size_t)s->npatches * 3 * sizeof *w->all_se);
    if (!w->all || !w->all_se) {
        err = (ulam_error){.status = ULAM_ENOMEM, .msg = "memory for the solution"};
        return cli_report(a->scene, &err);
    }
    cli_catch_sigint();
    ulam_rad_opts ro = rad_opts(&a->o);
    int status = ulam_view_gather(t, &cam, a->width, a->height, a->coverage, &ro, w->all, w->all_se, vi, &err);
    cli_release_sigint();
    if (status) return cli_report(a->scene, &err);
    w->walks = vi->walks, w->steps = vi->rays, w->seconds = vi->seconds, w->cut = vi->cut;
    w->interrupted = vi->interrupted, w->threads = vi->threads;
    return 0;
}

/* Warn when the picture's patches are noisy: the pixel-weighted mean, over the pixels that see a
 * patch, of its largest relative standard error over the lit channels, above 5%. */
static void noise_warning(const args *a, const ulam_tracer *t, const ulam_scene *s, const ulam_camera *cam,
                          const double *B, const double *se)
{
    int64_t *pix = malloc((size_t)s->npatches * sizeof *pix), seen = 0;
    if (!pix || ulam_view_pixels(t, cam, a->width, a->height, pix)) {
        free(pix);
        return;
    }
    double sum = 0.0, n = 0.0;
    for (int64_t p = 0; p < s->npatches; p++) {
        if (!pix[p]) continue;
        double rel = 0.0;
        for (int c = 0; c < 3; c++)
            if (B[3 * p + c] > 0) rel = fmax(rel, se[3 * p + c] / B[3 * p + c]);
        sum += (double)pix[p] * rel, n += (double)pix[p], seen++;
    }
    free(pix);
    if (n > 0 && sum / n > 0.05 && cli_rank == 0)
        fprintf(stderr, "ulam radiosity: warning: %s: the %lld patches in view carry %.0f%% relative error (pixel-weighted "
                        "mean): the picture will be salt-and-pepper noise; more --walks (the error falls as "
                        "1/sqrt(walks)), or --view-gather --rel-err\n", a->image, (long long)seen, 100.0 * sum / n);
}

/* Render B into a->image, warning when the picture cannot show the light; 0 or an exit code. */
static int write_image(const args *a, const ulam_tracer *t, const ulam_scene *s, const double *B, const double *se,
                       double *used)
{
    size_t np = (size_t)a->width * (size_t)a->height;
    unsigned char *rgb = malloc(np * 3);
    float *hdr = malloc(np * 3 * sizeof *hdr);
    ulam_camera cam = camera_of(a, s);
    ulam_render_info info;
    int status = rgb && hdr ? ulam_render_hdr(t, B, &cam, a->width, a->height, a->samples, !a->flat, a->o.exec.seed,
                                              a->exposure, hdr, rgb, &info)
                            : ULAM_ENOMEM;
    if (!status) { /* its temporary file is the library's: a signal waits until it is gone */
        cli_hold_signals(1);
        status = ulam_png_write(a->image, a->width, a->height, rgb);
        cli_hold_signals(0);
    }
    static const char *const what[] = {"a writable PFM file", "a writable Radiance .hdr file"};
    for (int k = 0; k < 2 && !status; k++) { /* the PFM and the Radiance .hdr beside the PNG */
        cli_hold_signals(1);
        status = k ? ulam_hdr_write(a->rgbe, a->width, a->height, hdr) : ulam_pfm_write(a->hdr, a->width, a->height, hdr);
        cli_hold_signals(0);
        if (status) {
            free(rgb), free(hdr);
            ulam_error err = {.status = status};
            snprintf(err.msg, sizeof err.msg, "%s", what[k]);
            return cli_report(k ? a->rgbe : a->hdr, &err);
        }
    }
    free(rgb), free(hdr);
    if (status == ULAM_ERANGE) {
        ulam_error err = {.status = status, .msg = "--camera: an eye within a million scene sizes of the scene"};
        return cli_report(a->image, &err);
    }
    if (status) {
        ulam_error err = {.status = status, .msg = "a writable PNG file"};
        return cli_report(a->image, &err);
    }
    *used = info.exposure;
    if (se) noise_warning(a, t, s, &cam, B, se);
    if (!info.pixels_hit)
        fprintf(stderr, "ulam radiosity: warning: %s: the camera sees no patch's front (try --camera)\n", a->image);
    else if (!info.pixels_emitter)
        fprintf(stderr, "ulam radiosity: warning: %s: no emitter is in view of the camera\n", a->image);
    if (info.pixels_hit && !info.exposure_set)
        fprintf(stderr, "ulam radiosity: warning: %s: nothing lit is in view, so the exposure cannot be set "
                        "(1 used; give --exposure or --camera)\n", a->image);
    return 0;
}

static double need_counts(const args *a, double n, double tri, double nverts, char *what, size_t len);
static void human(double b, char *out, size_t len);

/* The scene, subdivided if asked; 0 or an exit code. */
static int load_scene(const args *a, ulam_scene **out, int64_t *faces)
{
    ulam_error err;
    ulam_scene *s = NULL;
    ulam_mtl_note *notes = NULL;
    int64_t nnotes = 0;
    if (ulam_scene_read_obj_notes(a->scene, &s, &notes, &nnotes, &err)) return cli_report(a->scene, &err);
    for (int64_t i = 0; i < nnotes && cli_rank == 0; i++) { /* one warning a material */
        int first = 1;
        for (int64_t k = 0; k < i && first; k++) first = strcmp(notes[k].material, notes[i].material) != 0;
        if (!first) continue;
        fprintf(stderr, "ulam radiosity: warning: %s: material '%s' is rendered matte (Kd, Ke): ignored", notes[i].file,
                notes[i].material);
        for (int64_t k = i; k < nnotes; k++)
            if (!strcmp(notes[k].material, notes[i].material))
                fprintf(stderr, "%s %s (%s:%ld)", k == i ? "" : ",", notes[k].keyword, notes[k].file, notes[k].line);
        fprintf(stderr, "\n");
    }
    ulam_mtl_notes_free(notes, nnotes);
    *faces = s->nfaces;
    if (a->subdivide > 0) { /* counted first: --max-mem refuses a mesh before it is built */
        double np = 0, nv = 0, tri = 0, bytes = 0, need;
        char what[512], h[3][32];
        int status = ulam_scene_subdivide_plan(s, a->subdivide, &np, &nv, &tri, &bytes);
        need = bytes + (a->list ? 0.0 : need_counts(a, np, tri, nv, what, sizeof what));
        if ((status == ULAM_OK || status == ULAM_EOVERFLOW) && need > (double)a->max_mem) {
            human(need, h[0], 32), human((double)a->max_mem, h[1], 32), human(bytes, h[2], 32);
            fprintf(stderr, "ulam radiosity: %s: memory limit: --subdivide %g makes %.4g patches (%.4g vertices): "
                            "this run needs about %s, more than --max-mem %s (the patches %s%s%s); refused before "
                            "building them: raise --subdivide or --max-mem\n",
                    a->scene, a->subdivide, np, nv, h[0], h[1], h[2], a->list ? "" : ", ", a->list ? "" : what);
            ulam_scene_free(s);
            return cli_exit_code(ULAM_EMEMLIMIT);
        }
        ulam_scene *d = NULL;
        status = status ? status : ulam_scene_subdivide(s, a->subdivide, &d);
        ulam_scene_free(s);
        if (status) {
            err = (ulam_error){.status = status, .msg = "a subdivision that fits in memory"};
            return cli_report(a->scene, &err);
        }
        s = d;
    }
    *out = s;
    return 0;
}

/* Form F and, if asked, solve directly; 0 or an exit code. */
static int form_and_solve(const args *a, const ulam_tracer *t, const ulam_scene *s, report *r, ulam_csr **F,
                          double **Bd)
{
    ulam_error err;
    double t0 = ulam_now();
    if (ulam_ff_estimate(t, a->ff_rays, a->o.exec.seed, a->o.exec.threads, F, &err)) return cli_report(a->scene, &err);
    r->ff_seconds = ulam_now() - t0;
    ulam_ff_report_compute(s, *F, &r->ff);
    r->F = *F;
    int need = a->direct || a->check, every = a->out || a->all;
    int for_error = a->matrix_walk && (r->patch >= 0 || (every && a->o.mode == ULAM_FORWARD));
    if (!need && !for_error) return 0;
    if (!need && ulam_direct_bytes(s->npatches) > a->max_mem) return 0; /* the error bar is then labelled */
    if (!(*Bd = malloc((size_t)s->npatches * 3 * sizeof **Bd))) {
        err = (ulam_error){.status = ULAM_ENOMEM, .msg = "memory for the solution"};
        return cli_report(a->scene, &err);
    }
    ulam_direct_info info;
    if (ulam_rad_direct(s, *F, a->max_mem, *Bd, &info, &err)) return cli_report(a->scene, &err);
    r->direct_seconds = info.seconds;
    if (need) r->Bdirect = *Bd;
    if (r->patch >= 0) {
        if (ulam_rad_direct_error(s, *F, a->ff_rays, *Bd, r->patch, a->max_mem, r->direct_se, &err))
            return cli_report(a->scene, &err);
        r->ff_se_known = 1;
    }
    if (every && (a->direct || a->matrix_walk || a->check)) { /* every patch's error from F's noise */
        if (!(r->direct_se_all = malloc((size_t)s->npatches * 3 * sizeof *r->direct_se_all))) {
            err = (ulam_error){.status = ULAM_ENOMEM, .msg = "memory for the standard errors"};
            return cli_report(a->scene, &err);
        }
        int st = ulam_rad_direct_errors(s, *F, a->ff_rays, *Bd, a->max_mem, r->direct_se_all, &err);
        if (st == ULAM_EMEMLIMIT) free(r->direct_se_all), r->direct_se_all = NULL; /* the rows say unknown */
        else if (st) return cli_report(a->scene, &err);
    }
    return 0;
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

/* The values of every patch for --out and --all. */
static patch_values every_patch(const args *a, const report *r, const walked *w, const double *Bd)
{
    if (w->all) return (patch_values){w->all, w->all_se, (a->direct || a->check) ? Bd : NULL, r->direct_se_all, NULL};
    return (patch_values){Bd, r->direct_se_all, NULL, NULL, NULL};
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

/* --mesh-target: the scene adaptively subdivided (importance from the camera with --image, else
 * the area), *s replaced; 0 or an exit code. */
static int adapt_scene(const args *a, ulam_scene **s, ulam_rad_adapt_info *info, int *view_importance, int64_t *cap_out)
{
    ulam_error err;
    ulam_tracer *t = NULL;
    ulam_scene *d = NULL;
    double *Y = NULL;
    if (ulam_tracer_alloc(*s, &t, &err)) return cli_report(a->scene, &err);
    int64_t cap = patch_cap(a, *s), walks = 64 * (*s)->npatches > 65536 ? 64 * (*s)->npatches : 65536;
    *cap_out = cap;
    int rc = 0;
    if (a->image) {
        ulam_camera cam = camera_of(a, *s);
        if (!(Y = malloc((size_t)(*s)->npatches * sizeof *Y))) {
            err = (ulam_error){.status = ULAM_ENOMEM, .msg = "memory for the importance"};
            rc = cli_report(a->scene, &err);
        } else if (ulam_rad_importance(t, &cam, a->width, a->height, walks, a->o.exec.seed, Y, &err)) {
            rc = cli_report(a->scene, &err);
        }
        *view_importance = 1;
    }
    ulam_rad_opts o = rad_opts(&a->o); /* the points: next-event, to half the target or 1024 walks each */
    o.mode = ULAM_ADJOINT, o.estimator = ULAM_RAD_NEXT_EVENT + (a->mis > 0 ? a->mis : 0);
    o.stop.rel_err = a->mesh_target / 2, o.stop.max_walks = 1024; /* --time: the mesh half of what is left, the solve the rest */
    o.stop.max_seconds = a->o.stop.max_seconds > 0 ? cli_time_left(a->o.stop.max_seconds) / 2 : 0;
    if (!rc) {
        cli_catch_sigint();
        if (ulam_rad_adapt(t, &o, Y, a->mesh_target, cap, &d, info, &err)) rc = cli_report(a->scene, &err);
        cli_release_sigint();
    }
    free(Y);
    ulam_tracer_free(t);
    if (rc) return rc;
    ulam_scene_free(*s);
    *s = d;
    return 0;
}

/* --mesh-error N: every patch's mesh error against pv->B into a new *out (3 a patch); 0 or an
 * exit code. */
static int every_mesh_error(const args *a, const ulam_tracer *t, const ulam_scene *s, patch_values *pv, double **out)
{
    ulam_error err = {.status = ULAM_ENOMEM, .msg = "memory for the mesh errors"};
    if (!(*out = malloc((size_t)s->npatches * 3 * sizeof **out))) return cli_report(a->scene, &err);
    ulam_rad_opts o = rad_opts(&a->o);
    o.mode = ULAM_ADJOINT, o.estimator = ULAM_RAD_NEXT_EVENT, o.stop.rel_err = 0, o.stop.max_seconds = 0;
    o.stop.max_walks = a->mesh_walks;
    cli_catch_sigint();
    int status = ulam_rad_mesh_errors(t, &o, pv->B, *out, &err); /* patch p seeded by its substream */
    cli_release_sigint();
    if (status) return cli_report(a->scene, &err);
    pv->mesh = *out;
    return 0;
}

/* ulam radiosity. */
int cli_radiosity(int argc, char **argv)
{
    args a = {.est = -1, .mis = -1, .samples = 4, .coverage = 0.25, .ff_rays = 1000, .width = 512, .height = 512, .max_mem = CLI_MAX_MEM, .o = ulam_walk_defaults()};
    a.o.stop.max_walks = 0;
    a.o.stop.interrupt = &cli_interrupted, a.o.exec.share = cli_share;
    int rc = parse(argc, argv, &a);
    if (rc) {
        free(a.at), cli_photo_free(&a.ph);
        return rc < 0 ? 0 : rc;
    }
    ulam_scene *s = NULL;
    ulam_tracer *t = NULL;
    ulam_csr *F = NULL;
    double *Bd = NULL;
    walked w = {0};
    report r = {.patch = -1, .w = NULL};
    double *mesh_all = NULL;
    ulam_error err;
    if (a.est == 2 && a.mis == 2 && cli_rank == 0)
        fprintf(stderr, "ulam radiosity: warning: --mis none (light sampling alone) has infinite variance at a patch "
                        "that shares an edge with a light or nearly touches one: there the error bar can be far too "
                        "small (the edge-lamp scene: z = -4.6); the MIS default is bounded\n");
    if (a.image) { /* the PFM beside the PNG: out.png -> out.pfm */
        size_t len = strlen(a.image);
        int png = len > 4 && !strcmp(a.image + len - 4, ".png");
        if (len + 5 > sizeof a.hdr) {
            rc = cli_usage_error("radiosity", "--image: a path shorter than 4 KiB");
            goto done; /* every early exit frees what parse() made (--at's list: the 48-byte leak) */
        }
        snprintf(a.hdr, sizeof a.hdr, "%.*s.pfm", (int)(png ? len - 4 : len), a.image);
        snprintf(a.rgbe, sizeof a.rgbe, "%.*s.hdr", (int)(png ? len - 4 : len), a.image);
    }
    const cli_file outs[] = {{"--image", a.image}, {"--image's PFM", a.image && !a.grid ? a.hdr : NULL},
                             {"--image's HDR", a.image && !a.grid ? a.rgbe : NULL}, {"--out", a.out}},
                   ins[] = {{"the scene", a.scene}};
    if ((rc = cli_check_outputs("radiosity", outs, 4, ins, 1)) || (rc = load_scene(&a, &s, &r.faces))) goto done;
    if (a.mesh_target > 0 && (rc = adapt_scene(&a, &s, &r.adapt, &r.view_importance, &r.adapt_cap))) goto done;
    r.adapted = a.mesh_target > 0;
    r.s = s;
    if (a.list) {
        print_list(&a, s);
        goto done;
    }
    if (a.patch && (rc = find_patch(s, a.patch, &r.patch))) goto done;
    {
        char what[512], h[2][32];
        double need = need_bytes(&a, s, what, sizeof what);
        if (need > (double)a.max_mem) { /* refused before the first ray */
            human(need, h[0], 32), human((double)a.max_mem, h[1], 32);
            fprintf(stderr, "ulam radiosity: %s: memory limit: this run needs about %s, more than --max-mem %s (%s); refused before "
                            "any work: raise --max-mem, or ask less (--patch or --at walks need no F)\n",
                    a.scene, h[0], h[1], what);
            rc = cli_exit_code(ULAM_EMEMLIMIT);
            goto done;
        }
    }
    a.o.query.index = r.patch >= 0 ? r.patch : 0;
    if (ulam_tracer_alloc(s, &t, &err)) {
        rc = cli_report(a.scene, &err);
        goto done;
    }
    int64_t coarse;
    double res = ulam_tracer_resolution(t, &coarse);
    if (res > 1e-3 && cli_rank == 0)
        fprintf(stderr, "ulam radiosity: warning: %s: patch %lld is only %.0f float steps across where it lies: ray "
                        "casting resolves it to %.2g of its size (move the scene's parts closer together)\n",
                a.scene, (long long)coarse + 1, 1.0 / res, res);
    if ((rc = cli_photo_light(&a.ph, t, s, a.scene, a.o.exec.threads, cli_time_left(a.o.stop.max_seconds))))
        goto done; /* the luminaires light the patches */
    double budget = a.o.stop.max_seconds; /* --time counts the whole run: reading, the tracer, the walks, the mesh */
    a.o.stop.max_seconds = cli_time_left(budget);
    if (a.nat || a.grid) {
        rc = run_points(&a, t, s);
        goto done;
    }
    if ((a.direct || a.check || a.matrix_walk) && (rc = form_and_solve(&a, t, s, &r, &F, &Bd))) goto done;
    if (a.view) {
        if ((rc = view_walks(&a, t, s, &w, &r.view))) goto done;
        r.w = &w;
    } else if (a.patch || a.o.mode == ULAM_FORWARD) {
        rc = a.matrix_walk ? matrix_walks(&a, s, F, r.ff_se_known ? r.direct_se : NULL,
                                          Bd && r.patch >= 0 ? Bd + 3 * r.patch : NULL, &w)
                           : ray_walks(&a, t, s->npatches, &w);
        if (rc) goto done;
        r.mesh_no_time = budget > 0 && a.patch && a.o.mode == ULAM_ADJOINT && !w.interrupted && !a.no_mesh &&
                         !(budget - (ulam_now() - cli_started) > 0);
        if (a.patch && a.o.mode == ULAM_ADJOINT && !w.interrupted && !a.no_mesh && !r.mesh_no_time) { /* the mesh's error beside */
            ulam_rad_opts mo = rad_opts(&a.o); /* each point to twice the patch's relative error or 1/4 its walks (>= 256) */
            mo.index = r.patch, mo.estimator = ULAM_RAD_NEXT_EVENT, mo.stop.rel_err = 2 * a.o.stop.rel_err;
            if (a.o.stop.max_walks > 0) mo.stop.max_walks = a.o.stop.max_walks / 4 > 256 ? a.o.stop.max_walks / 4 : 256;
            mo.stop.max_seconds = cli_time_left(budget); /* what the walks left of --time */
            cli_catch_sigint();
            int st = ulam_rad_mesh_error(t, &mo, w.B, &r.mesh, &err);
            cli_release_sigint();
            if (st) {
                rc = cli_report(a.scene, &err);
                goto done;
            }
            r.mesh_known = !r.mesh.interrupted;
        }
        if (a.matrix_walk) combine_errors(&r, &w);
        r.w = &w;
        if (r.patch >= 0 && !w.interrupted && exactly_zero(w.B, w.se))
            r.diag_known = scene_diagnosis(t, a.o.exec.seed, &r.diag);
    }
    r.pv = every_patch(&a, &r, &w, Bd);
    if (a.mesh_walks && r.pv.B && !w.interrupted && (rc = every_mesh_error(&a, t, s, &r.pv, &mesh_all))) goto done;
    if (a.out && !w.interrupted && cli_rank == 0) {
        if ((rc = write_csv(a.out, s, &r.pv))) goto done;
        r.out_written = 1;
    }
    if (a.image && !w.interrupted && cli_rank == 0) {
        double *L = NULL, *Lse = NULL; /* photometric: the picture's luminance B / pi, cd/m2 (photometry.c) */
        cli_photo_luminance(&a.ph, w.all ? w.all : Bd, w.all ? w.all_se : NULL, s->npatches, &L, &Lse);
        rc = write_image(&a, t, s, L ? L : w.all ? w.all : Bd, Lse ? Lse : w.all ? w.all_se : NULL, &r.exposure);
        free(L), free(Lse);
        if (rc) goto done;
        r.image_written = 1;
    }
    if (a.json) print_json(&a, &r);
    else print_text(&a, &r);
    if (!a.json) cli_photo_report_patch(&a.ph, r.patch < 0 ? NULL : r.w ? w.B : Bd ? Bd + 3 * r.patch : NULL, ulam_rad_luma(),
                                       r.image_written);
    if (w.interrupted) rc = EXIT_INTERRUPTED;
done:
    free(w.all), free(w.all_se), free(Bd), free(r.direct_se_all), free(a.at), free(mesh_all);
    ulam_csr_free(F);
    ulam_tracer_free(t);
    ulam_scene_free(s);
    cli_photo_free(&a.ph);
    return rc;
}
