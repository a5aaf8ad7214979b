/* Wavefront OBJ and MTL reader: planar convex faces with diffuse reflectance and emission.
 * Every error names the file and line and says what was expected; nothing is read past it. */
#include "rad.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The largest vertex coordinate read: Embree traces in float (the scene centred first), and a
 * face's area, the square of its size, must stay finite in double. */
#define ULAM__OBJ_MAX_COORD 1e30

/* The longest OBJ or MTL line read: past it the file is refused, never buffered whole (a 600 MB
 * comment, /dev/zero as an MTL file). */
enum { OBJ_LINE_MAX = 1 << 20 };

/* The end of a line read (next_line): a line, the end of the file, or why the reading stopped. */
enum { LINE_OK, LINE_EOF, LINE_LONG, LINE_NUL, LINE_NOMEM, LINE_EIO };

/* The next line of f into *buf (growing it, never past OBJ_LINE_MAX bytes), NUL-terminated with
 * its newline: LINE_OK, LINE_EOF at the end, or a failure (a read error or no memory is never
 * taken for the end of the file). */
static int next_line(FILE *f, char **buf, size_t *cap, size_t *len)
{
    size_t n = 0;
    int c;
    while ((c = getc(f)) != EOF) {
        if (n + 2 > *cap) {
            if (*cap >= OBJ_LINE_MAX) return LINE_LONG;
            size_t want = *cap ? 2 * *cap : 256;
            char *nb = realloc(*buf, want);
            if (!nb) return LINE_NOMEM;
            *buf = nb, *cap = want;
        }
        if (c == 0) return LINE_NUL; /* a binary file: said at once, not read on to the bound */
        (*buf)[n++] = (char)c;
        if (c == '\n') break;
    }
    if (c == EOF && ferror(f)) return LINE_EIO;
    if (n == 0) return LINE_EOF;
    (*buf)[n] = '\0';
    *len = n;
    return LINE_OK;
}

/* The status of a failed next_line (got) at line of the OBJ or MTL file, err filled. */
static int line_fail(ulam_error *err, int got, long line)
{
    if (got == LINE_LONG)
        return ulam__fail(err, ULAM_ESYNTAX, line, -1, "a text line of at most %d bytes (this one is longer)", OBJ_LINE_MAX);
    if (got == LINE_NUL) return ulam__fail(err, ULAM_ESYNTAX, line, -1, "text (this line holds a NUL byte)");
    if (got == LINE_NOMEM) return ulam__fail(err, ULAM_ENOMEM, line, -1, "memory for line %ld", line);
    return ulam__fail(err, ULAM_EIO, line, -1, "a readable file (%s)", strerror(errno));
}

/* Open path for reading when it is a regular file: a FIFO, device or directory is refused without
 * blocking on it (NULL, *what saying what it is; errno for an open that failed, *what NULL). */
static FILE *open_regular(const char *path, const char **what)
{
    *what = NULL;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return NULL;
    struct stat st;
    if (fstat(fd, &st) || !S_ISREG(st.st_mode)) {
        *what = S_ISDIR(st.st_mode) ? "a directory" : S_ISFIFO(st.st_mode) ? "a FIFO" : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device" : "not a regular file";
        close(fd);
        return NULL;
    }
    int fl = fcntl(fd, F_GETFL);
    FILE *f = fl >= 0 && !fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) ? fdopen(fd, "r") : NULL;
    if (!f) close(fd);
    return f;
}

/* A material: its name and the two colours ulam uses. */
typedef struct {
    char *name, *file; /* file and line of its newmtl */
    long line;
    long kd_line, ke_line; /* where its Kd and Ke were given (0: not yet) */
    double kd[3], ke[3];
} mtl;

/* A face: where its vertex list starts, its material and group. */
typedef struct {
    int64_t start;
    int32_t mat, group;
} objface;

/* Reader state: growable arrays of vertices, faces, materials and groups. */
typedef struct {
    double *v;
    int64_t nv, cap_v;
    int32_t *idx;
    int64_t nidx, cap_idx;
    objface *faces;
    int64_t nf, cap_f;
    mtl *mats;
    int64_t nmats, cap_mats;
    char **groups;
    int64_t ngroups, cap_groups;
    int32_t cur_mat, cur_group;
    ulam_mtl_note *notes; /* non-diffuse MTL statements ignored, the first of each keyword a material */
    int64_t nnotes, cap_notes;
    char **mtl_names; /* the mtllib files read, as written, and the OBJ lines that read them */
    long *mtl_lines;
    int64_t nmtl, cap_mtl, cap_mtl_lines;
    char *dir; /* the OBJ file's folder, with a trailing slash, or "" */
    ulam_error *err;
} objr;

/* A copy of the string s (NULL when out of memory). */
static char *dup_str(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

/* Free everything the reader holds. */
static void objr_free(objr *o)
{
    for (int64_t i = 0; i < o->nmats; i++) free(o->mats[i].name), free(o->mats[i].file);
    for (int64_t i = 0; i < o->ngroups; i++) free(o->groups[i]);
    for (int64_t i = 0; i < o->nmtl; i++) free(o->mtl_names[i]);
    free(o->mtl_names), free(o->mtl_lines);
    free(o->v), free(o->idx), free(o->faces);
    free(o->mats), free(o->groups), free(o->dir);
    ulam_mtl_notes_free(o->notes, o->nnotes);
}

/* Free notes; accepts NULL. */
void ulam_mtl_notes_free(ulam_mtl_note *notes, int64_t n)
{
    for (int64_t i = 0; notes && i < n; i++) free(notes[i].file), free(notes[i].material);
    free(notes);
}

/* Strip a comment and trailing white space (including a CR) in place. */
static void trim(char *line)
{
    char *hash = strchr(line, '#');
    if (hash) *hash = '\0';
    size_t n = strlen(line);
    while (n && strchr(" \t\r\n\f\v", line[n - 1])) line[--n] = '\0';
}

/* The rest of the line after the keyword, leading blanks skipped. */
static char *rest_of(char *s)
{
    while (*s == ' ' || *s == '\t') s++;
    return s;
}

/* Split a line in place into its keyword (returned; NULL for a blank or comment line) and the
 * rest (*args), after cutting the comment and trailing white space. */
static char *statement(char *line, char **args)
{
    trim(line);
    char *s = rest_of(line);
    if (!*s) return NULL;
    char *sp = s + strcspn(s, " \t");
    *args = *sp ? (*sp = '\0', sp + 1) : sp;
    return s;
}

/* Parse up to max finite numbers from s into x; the count, or -1 on a token that is not a
 * number, -2 on a non-finite one, -3 on more than max. */
static int parse_numbers(char *s, double *x, int max)
{
    int k = 0;
    char *tok, *save = NULL;
    for (tok = strtok_r(s, " \t", &save); tok; tok = strtok_r(NULL, " \t", &save)) {
        if (k == max) return -3;
        char *end;
        errno = 0;
        double v = strtod(tok, &end);
        if (end == tok || *end) return -1;
        if (!isfinite(v)) return -2;
        x[k++] = v;
    }
    return k;
}

/* The material called name, or -1. */
static int64_t find_mat(const objr *o, const char *name)
{
    for (int64_t i = 0; i < o->nmats; i++)
        if (!strcmp(o->mats[i].name, name)) return i;
    return -1;
}

/* The group called name, or -1. */
static int64_t find_group(const objr *o, const char *name)
{
    for (int64_t i = 0; i < o->ngroups; i++)
        if (!strcmp(o->groups[i], name)) return i;
    return -1;
}

/* Fail at line of an MTL file: like ulam__fail, naming the file. */
static int mtl_fail(objr *o, const char *path, int status, long line, const char *fmt, const char *arg)
{
    ulam__fail(o->err, status, line, -1, fmt, arg);
    if (o->err) snprintf(o->err->file, sizeof o->err->file, "%s", path);
    return status;
}

/* Read one RGB statement (Kd or Ke) of an MTL file into c. */
static int mtl_colour(objr *o, const char *path, long line, char *args, int is_kd, double c[3])
{
    const char *what = is_kd ? "Kd r g b: a reflectance in [0, 1) per channel"
                             : "Ke r g b: a finite emission >= 0 per channel";
    char *a = rest_of(args);
    if (!strncmp(a, "spectral", 8))
        return mtl_fail(o, path, ULAM_EUNSUPPORTED, line,
                        is_kd ? "Kd r g b (RGB only): this file gives a spectral curve, 'Kd spectral %.100s'"
                              : "Ke r g b (RGB only): this file gives a spectral curve, 'Ke spectral %.100s'",
                        rest_of(a + 8));
    if (!strncmp(a, "xyz", 3))
        return mtl_fail(o, path, ULAM_EUNSUPPORTED, line,
                        is_kd ? "Kd r g b (RGB only): this file gives CIE XYZ, 'Kd xyz %.100s'"
                              : "Ke r g b (RGB only): this file gives CIE XYZ, 'Ke xyz %.100s'",
                        rest_of(a + 3));
    int k = parse_numbers(a, c, 3);
    if (k == -2) return mtl_fail(o, path, ULAM_ENONFINITE, line, "%s", what);
    if (k != 1 && k != 3) return mtl_fail(o, path, ULAM_ESYNTAX, line, "%s (1 or 3 numbers)", what);
    if (k == 1) c[1] = c[2] = c[0];
    for (int i = 0; i < 3; i++)
        if (c[i] < 0 || (is_kd && c[i] >= 1))
            return mtl_fail(o, path, ULAM_ERANGE, line, "%s", what);
    for (int i = 0; !is_kd && i < 3; i++) /* the walks square their scores: 2^(+-256) keeps every square a
                                            normal double (1e-300 printed '+- 0', 1e300 '+- inf') */
        if (c[i] > 0 && !(c[i] >= 0x1p-256 && c[i] <= 0x1p256))
            return mtl_fail(o, path, ULAM_ERANGE, line, "%s",
                            "Ke r g b: each nonzero emission within [2^-256, 2^256], about [8.6e-78, 1.2e77] (the walks square their scores; "
                            "radiosity is linear in Ke: scale the scene's emission)");
    return ULAM_OK;
}

/* Nonzero when MTL statement s with args leaves a diffuse material as it is: Ka (ambient, not
 * physical), Ni (matters only with transparency), and the matte values Ks 0 0 0, Ns 0, d 1,
 * Tr 0, illum 0, 1 or 2, Tf 1 1 1. */
static int matte_statement(const char *s, char *args)
{
    double x[3];
    int n = parse_numbers(args, x, 3);
    if (!strcmp(s, "Ka") || !strcmp(s, "Ni")) return 1;
    if (!strcmp(s, "Ks")) return n >= 1 && x[0] == 0 && (n < 2 || x[1] == 0) && (n < 3 || x[2] == 0);
    if (!strcmp(s, "d")) return n == 1 && x[0] == 1;
    if (!strcmp(s, "Ns")) return n == 1 && x[0] == 0;
    if (!strcmp(s, "Tr")) return n == 1 && x[0] == 0;
    if (!strcmp(s, "illum")) return n == 1 && (x[0] == 0 || x[0] == 1 || x[0] == 2);
    if (!strcmp(s, "Tf")) return n >= 1 && x[0] == 1 && (n < 2 || x[1] == 1) && (n < 3 || x[2] == 1);
    return 0;
}

/* Note an ignored non-diffuse statement s of material cur at path:line (once a keyword a
 * material); ULAM_OK or ULAM_ENOMEM. */
static int note_ignored(objr *o, const mtl *cur, const char *path, long line, const char *s)
{
    for (int64_t i = 0; i < o->nnotes; i++)
        if (!strcmp(o->notes[i].material, cur->name) && !strncmp(o->notes[i].keyword, s, sizeof o->notes[i].keyword - 1))
            return ULAM_OK;
    if (ulam__grow(&o->notes, &o->cap_notes, o->nnotes + 1, sizeof *o->notes)) return ULAM_ENOMEM;
    ulam_mtl_note *n = &o->notes[o->nnotes];
    *n = (ulam_mtl_note){.file = dup_str(path), .material = dup_str(cur->name), .line = line};
    snprintf(n->keyword, sizeof n->keyword, "%s", s);
    o->nnotes++;
    return n->file && n->material ? ULAM_OK : ULAM_ENOMEM;
}

/* Read the MTL file name (relative to the OBJ's folder); obj_line is the mtllib line. */
static int read_mtl(objr *o, const char *name, long obj_line)
{
    size_t len = strlen(o->dir) + strlen(name) + 1;
    char *path = malloc(len);
    if (!path) return ulam__fail(o->err, ULAM_ENOMEM, obj_line, -1, "memory for a file name");
    snprintf(path, len, "%s%s", name[0] == '/' ? "" : o->dir, name);
    const char *what;
    FILE *f = open_regular(path, &what);
    if (!f) {
        int e = errno;
        if (what) ulam__fail(o->err, ULAM_EIO, obj_line, -1, "a regular MTL file: %s is %s", path, what);
        else ulam__fail(o->err, ULAM_EIO, obj_line, -1, "a readable MTL file %s (%s)", path, strerror(e));
        free(path);
        return ULAM_EIO;
    }
    char *buf = NULL;
    size_t cap = 0, got_len;
    long line = 0;
    int status = ULAM_OK, got;
    mtl *cur = NULL;
    while (!status && (got = next_line(f, &buf, &cap, &got_len)) != LINE_EOF) {
        line++;
        if (got != LINE_OK) {
            status = line_fail(o->err, got, line);
            if (o->err) snprintf(o->err->file, sizeof o->err->file, "%s", path);
            break;
        }
        char *args, *s = statement(buf, &args);
        if (!s) continue;
        if (!strcmp(s, "newmtl")) {
            char *nm = rest_of(args);
            if (!*nm) {
                status = mtl_fail(o, path, ULAM_ESYNTAX, line, "%s", "newmtl NAME");
                break;
            }
            int64_t i = find_mat(o, nm);
            if (i >= 0) { /* a second definition would silently reset the first (a lamp loses its Ke) */
                char what[600];
                snprintf(what, sizeof what, "a new material name in newmtl: '%.100s' is already defined at %.200s:%ld",
                         nm, o->mats[i].file, o->mats[i].line);
                status = mtl_fail(o, path, ULAM_ESYNTAX, line, "%s", what);
                break;
            }
            if (ulam__grow(&o->mats, &o->cap_mats, o->nmats + 1, sizeof(mtl))) {
                status = mtl_fail(o, path, ULAM_ENOMEM, line, "%s", "memory for a material");
                break;
            }
            cur = &o->mats[o->nmats];
            *cur = (mtl){.name = dup_str(nm), .file = dup_str(path), .line = line};
            o->nmats++;
            if (!cur->name || !cur->file) {
                status = mtl_fail(o, path, ULAM_ENOMEM, line, "%s", "memory for a material");
                break;
            }
        } else if (!strcmp(s, "Kd") || !strcmp(s, "Ke")) {
            if (!cur) {
                status = mtl_fail(o, path, ULAM_ESYNTAX, line, "%s", "newmtl before the first colour");
                break;
            }
            int kd = s[1] == 'd';
            long *given = kd ? &cur->kd_line : &cur->ke_line;
            if (*given) { /* a second one would silently override the first */
                char what[400];
                snprintf(what, sizeof what, "one %s per material: '%.100s' has one at line %ld", s, cur->name, *given);
                status = mtl_fail(o, path, ULAM_ESYNTAX, line, "%s", what);
                break;
            }
            double c[3];
            status = mtl_colour(o, path, line, args, kd, c);
            if (!status) memcpy(kd ? cur->kd : cur->ke, c, sizeof c), *given = line;
        } else if (cur && !matte_statement(s, args) && note_ignored(o, cur, path, line, s)) {
            /* every other statement (Ks, Ns, d, illum, map_*, ...) is ignored: noted, unless matte */
            status = mtl_fail(o, path, ULAM_ENOMEM, line, "%s", "memory for a note");
        }
    }
    free(buf);
    fclose(f);
    free(path);
    return status;
}

/* The index of the mtllib file name read before, or -1. */
static int64_t mtl_read_before(const objr *o, const char *name)
{
    for (int64_t i = 0; i < o->nmtl; i++)
        if (!strcmp(o->mtl_names[i], name)) return i;
    return -1;
}

/* Remember that the OBJ's line read the MTL file name. */
static int mtl_remember(objr *o, const char *name, long line)
{
    if (ulam__grow(&o->mtl_names, &o->cap_mtl, o->nmtl + 1, sizeof(char *)) ||
        ulam__grow(&o->mtl_lines, &o->cap_mtl_lines, o->nmtl + 1, sizeof(long)) ||
        !(o->mtl_names[o->nmtl] = dup_str(name)))
        return ulam__fail(o->err, ULAM_ENOMEM, line, -1, "memory for an MTL file name");
    o->mtl_lines[o->nmtl++] = line;
    return ULAM_OK;
}

/* mtllib: one or more MTL files. */
static int do_mtllib(objr *o, char *args, long line)
{
    char *tok, *save = NULL;
    int any = 0;
    for (tok = strtok_r(args, " \t", &save); tok; tok = strtok_r(NULL, " \t", &save)) {
        int64_t seen = mtl_read_before(o, tok);
        if (seen >= 0)
            return ulam__fail(o->err, ULAM_ESYNTAX, line, -1, "an MTL file not read before; %.200s was read at line %ld",
                              tok, o->mtl_lines[seen]);
        int status = read_mtl(o, tok, line);
        if (!status) status = mtl_remember(o, tok, line);
        if (status) return status;
        any = 1;
    }
    return any ? ULAM_OK : ulam__fail(o->err, ULAM_ESYNTAX, line, -1, "mtllib FILE.mtl");
}

/* o / g: the label of the faces that follow. */
static int do_group(objr *o, char *args, long line)
{
    char *nm = rest_of(args);
    if (!*nm) {
        o->cur_group = -1;
        return ULAM_OK;
    }
    int64_t i = find_group(o, nm);
    if (i < 0) {
        if (o->ngroups >= INT32_MAX || ulam__grow(&o->groups, &o->cap_groups, o->ngroups + 1, sizeof(char *)) ||
            !(o->groups[o->ngroups] = dup_str(nm)))
            return ulam__fail(o->err, ULAM_ENOMEM, line, -1, "memory for a group name");
        i = o->ngroups++;
    }
    o->cur_group = (int32_t)i;
    return ULAM_OK;
}

/* usemtl NAME: the material of the faces that follow. */
static int do_usemtl(objr *o, char *args, long line)
{
    char *nm = rest_of(args);
    if (!*nm) return ulam__fail(o->err, ULAM_ESYNTAX, line, -1, "usemtl NAME");
    int64_t i = find_mat(o, nm);
    if (i < 0)
        return ulam__fail(o->err, ULAM_ENOTFOUND, line, -1,
                          "a material defined by an earlier mtllib file; '%.100s' is not", nm);
    o->cur_mat = (int32_t)i;
    return ULAM_OK;
}

/* v x y z [w | r g b]. */
static int do_vertex(objr *o, char *args, long line)
{
    double x[6];
    int k = parse_numbers(args, x, 6);
    if (k == -2) return ulam__fail(o->err, ULAM_ENONFINITE, line, -1, "finite vertex coordinates");
    if (k != 3 && k != 4 && k != 6)
        return ulam__fail(o->err, ULAM_ESYNTAX, line, -1, "v x y z (three numbers, optionally w or r g b)");
    if (k == 4 && x[3] != 1.0) /* w weighs rational curves; a polygon's vertex is the point x y z */
        return ulam__fail(o->err, ULAM_ERANGE, line, -1, "v x y z [w] with w = 1 (polygon vertices are not "
                          "weighted); got w = %.6g", x[3]);
    for (int d = 0; d < 3; d++)
        if (fabs(x[d]) > ULAM__OBJ_MAX_COORD)
            return ulam__fail(o->err, ULAM_ERANGE, line, -1, "vertex coordinates within +-%g (rays are traced in "
                              "single precision); got %.6g", ULAM__OBJ_MAX_COORD, x[d]);
    if (o->nv >= INT32_MAX || ulam__grow(&o->v, &o->cap_v, 3 * (o->nv + 1), sizeof(double)))
        return ulam__fail(o->err, ULAM_ENOMEM, line, -1, "memory for the vertices");
    memcpy(o->v + 3 * o->nv++, x, 3 * sizeof(double));
    return ULAM_OK;
}

/* One face vertex token: v, v/t, v/t/n or v//n; the 0-based vertex or -1 (error set). */
static int64_t face_index(objr *o, const char *tok, long line)
{
    char *end;
    errno = 0;
    long long i = strtoll(tok, &end, 10);
    if (end == tok || (*end && *end != '/') || errno == ERANGE) {
        ulam__fail(o->err, ULAM_ESYNTAX, line, -1, "a face vertex v, v/t, v/t/n or v//n; got '%.40s'", tok);
        return -1;
    }
    for (const char *c = end; *c; c++)
        if (!strchr("0123456789-/", *c)) {
            ulam__fail(o->err, ULAM_ESYNTAX, line, -1, "a face vertex v, v/t, v/t/n or v//n; got '%.40s'", tok);
            return -1;
        }
    long long k = i > 0 ? i - 1 : i < 0 ? o->nv + i : -1;
    if (o->nv == 0) {
        ulam__fail(o->err, ULAM_EINDEX, line, -1, "a 'v' line before the first face (no vertex is defined yet)");
        return -1;
    }
    if (k < 0 || k >= o->nv) {
        ulam__fail(o->err, ULAM_EINDEX, line, -1,
                    "a vertex index from 1 to %lld or -1 to -%lld (vertices defined so far); got %lld",
                    (long long)o->nv, (long long)o->nv, i);
        return -1;
    }
    return k;
}

/* Check that face f's polygon is a proper planar convex polygon. */
static int check_face(objr *o, const int32_t *idx, int64_t n, long line)
{
    double N[3], L;
    for (int64_t a = 0; a < n; a++)
        if (idx[a] == idx[(a + 1) % n])
            return ulam__fail(o->err, ULAM_EGEOMETRY, line, -1, "distinct consecutive vertices (a degenerate face)");
    ulam__polygon_normal(o->v, idx, n, N, &L);
    double len = sqrt(ulam__dot3(N, N));
    if (!(L > 0) || !(len > 1e-12 * L * L))
        return ulam__fail(o->err, ULAM_EGEOMETRY, line, -1, "a face with nonzero area (this one is degenerate)");
    double u[3] = {N[0] / len, N[1] / len, N[2] / len}, c[3] = {0, 0, 0};
    for (int64_t a = 0; a < n; a++)
        for (int d = 0; d < 3; d++) c[d] += o->v[3 * idx[a] + d] / (double)n;
    double turn = 0.0;
    for (int64_t a = 0; a < n; a++) {
        double dv[3], e1[3], e2[3], x[3];
        ulam__sub3(o->v + 3 * idx[a], c, dv);
        if (fabs(ulam__dot3(dv, u)) > 1e-5 * L)
            return ulam__fail(o->err, ULAM_EGEOMETRY, line, -1,
                              "a planar face (vertex %lld is %.3g off its plane; split it into triangles)",
                              (long long)a + 1, fabs(ulam__dot3(dv, u)));
        ulam__sub3(o->v + 3 * idx[(a + 1) % n], o->v + 3 * idx[a], e1);
        ulam__sub3(o->v + 3 * idx[(a + 2) % n], o->v + 3 * idx[(a + 1) % n], e2);
        ulam__cross3(e1, e2, x);
        double s = ulam__dot3(x, u);
        if (s < -1e-9 * L * L)
            return ulam__fail(o->err, ULAM_EGEOMETRY, line, -1, "a convex face (it turns back at vertex %lld)",
                              (long long)(a + 1) % n + 1);
        turn += atan2(s, ulam__dot3(e1, e2));
    }
    if (fabs(turn - 2 * M_PI) > 1e-6)
        return ulam__fail(o->err, ULAM_EGEOMETRY, line, -1, "a simple convex face (this one winds around twice)");
    return ULAM_OK;
}

/* f v1 v2 v3 ...: a face. */
static int do_face(objr *o, char *args, long line)
{
    if (o->cur_mat < 0)
        return ulam__fail(o->err, ULAM_ENOTFOUND, line, -1, "a usemtl line before the first face");
    int64_t n0 = o->nidx;
    char *tok, *save = NULL;
    for (tok = strtok_r(args, " \t", &save); tok; tok = strtok_r(NULL, " \t", &save)) {
        int64_t k = face_index(o, tok, line);
        if (k < 0) return o->err ? o->err->status : ULAM_ESYNTAX;
        if (ulam__grow(&o->idx, &o->cap_idx, o->nidx + 1, sizeof(int32_t)))
            return ulam__fail(o->err, ULAM_ENOMEM, line, -1, "memory for the faces");
        o->idx[o->nidx++] = (int32_t)k;
    }
    int64_t n = o->nidx - n0;
    if (n < 3) return ulam__fail(o->err, ULAM_ESYNTAX, line, -1, "a face with at least 3 vertices");
    int status = check_face(o, o->idx + n0, n, line);
    if (status) return status;
    if (ulam__grow(&o->faces, &o->cap_f, o->nf + 1, sizeof(objface)))
        return ulam__fail(o->err, ULAM_ENOMEM, line, -1, "memory for the faces");
    o->faces[o->nf++] = (objface){.start = n0, .mat = o->cur_mat, .group = o->cur_group};
    return ULAM_OK;
}

/* OBJ statements ulam reads past: texture and normal data, smoothing, lines, points and
 * display attributes.  The one list: the unknown-statement message is made from it. */
static const char *const skip[] = {"vt", "vn", "vp", "s", "l", "p", "mg", "lod", "usemap", "maplib",
                                   "shadow_obj", "trace_obj", "bevel", "c_interp", "d_interp"};
enum { NSKIP = sizeof skip / sizeof *skip };

/* Nonzero when kw is a statement ulam reads past. */
static int ignored(const char *kw)
{
    for (size_t i = 0; i < NSKIP; i++)
        if (!strcmp(kw, skip[i])) return 1;
    return 0;
}

/* The error for an OBJ statement ulam neither reads nor ignores. */
static int unknown_statement(objr *o, const char *kw, long line)
{
    char list[256] = "";
    size_t n = 0;
    for (size_t i = 0; i < NSKIP && n < sizeof list; i++)
        n += (size_t)snprintf(list + n, sizeof list - n, "%s%s", i ? ", " : "", skip[i]);
    return ulam__fail(o->err, ULAM_ESYNTAX, line, -1,
                      "an OBJ statement ulam reads (v, f, o, g, usemtl, mtllib; %s ignored), not '%.40s'", list, kw);
}

/* Read the statements of an open OBJ file. */
static int read_statements(objr *o, FILE *f)
{
    char *buf = NULL;
    size_t cap = 0, len;
    long line = 0;
    int status = ULAM_OK, got;
    while (!status && (got = next_line(f, &buf, &cap, &len)) != LINE_EOF) {
        line++;
        if (got != LINE_OK) {
            status = line_fail(o->err, got, line);
            break;
        }
        char *args, *s = statement(buf, &args);
        if (!s) continue;
        if (!strcmp(s, "v")) status = do_vertex(o, args, line);
        else if (!strcmp(s, "f")) status = do_face(o, args, line);
        else if (!strcmp(s, "o") || !strcmp(s, "g")) status = do_group(o, args, line);
        else if (!strcmp(s, "usemtl")) status = do_usemtl(o, args, line);
        else if (!strcmp(s, "mtllib")) status = do_mtllib(o, args, line);
        else if (!ignored(s)) status = unknown_statement(o, s, line);
    }
    if (!status && o->nf == 0) status = ulam__fail(o->err, ULAM_EEMPTY, line, -1, "at least one face");
    free(buf);
    return status;
}

/* The scene: one patch per face. */
static int build_scene(objr *o, ulam_scene **out)
{
    ulam_scene *s = ulam__scene_alloc(o->nf, o->nv, o->nidx, o->ngroups);
    if (!s) return ULAM_ENOMEM;
    memcpy(s->vert, o->v, (size_t)(3 * o->nv) * sizeof(double));
    memcpy(s->vidx, o->idx, (size_t)o->nidx * sizeof(int32_t));
    for (int64_t p = 0; p < o->nf; p++) {
        const mtl *m = &o->mats[o->faces[p].mat];
        s->start[p] = o->faces[p].start;
        memcpy(s->rho + 3 * p, m->kd, sizeof m->kd);
        memcpy(s->emit + 3 * p, m->ke, sizeof m->ke);
        s->face[p] = p;
        s->group[p] = o->faces[p].group;
    }
    s->start[o->nf] = o->nidx;
    for (int64_t g = 0; g < o->ngroups; g++) {
        s->groups[g] = o->groups[g];
        o->groups[g] = NULL;
    }
    s->ngroups = o->ngroups;
    s->nfaces = o->nf;
    o->ngroups = 0;
    ulam__scene_geometry(s);
    *out = s;
    return ULAM_OK;
}

/* Read an OBJ scene. */
int ulam_scene_read_obj(const char *path, ulam_scene **out, ulam_error *err)
{
    return ulam_scene_read_obj_notes(path, out, NULL, NULL, err);
}

/* Read an OBJ scene and the MTL statements it ignored. */
int ulam_scene_read_obj_notes(const char *path, ulam_scene **out, ulam_mtl_note **notes, int64_t *nnotes,
                              ulam_error *err)
{
    ulam__clear(err);
    if (notes) *notes = NULL;
    if (nnotes) *nnotes = 0;
    if (!path || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a path and an output");
    *out = NULL;
    objr o = {.cur_mat = -1, .cur_group = -1, .err = err};
    const char *slash = strrchr(path, '/');
    size_t dl = slash ? (size_t)(slash - path) + 1 : 0;
    if (!(o.dir = malloc(dl + 1))) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a file name");
    memcpy(o.dir, path, dl);
    o.dir[dl] = '\0';
    FILE *f = fopen(path, "r");
    if (!f) {
        int e = errno;
        objr_free(&o);
        return ulam__fail(err, ULAM_EIO, 0, -1, "a readable OBJ file (%s)", strerror(e));
    }
    int status = read_statements(&o, f);
    fclose(f);
    if (!status && (status = build_scene(&o, out)))
        ulam__fail(err, status, 0, -1, "memory for the scene");
    if (!status && notes && nnotes) *notes = o.notes, *nnotes = o.nnotes, o.notes = NULL, o.nnotes = 0;
    objr_free(&o);
    return status;
}
