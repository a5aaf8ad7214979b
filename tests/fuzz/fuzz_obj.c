/* libFuzzer target: the OBJ/MTL reader.  The input is an OBJ file, optionally followed by a
 * line "%%MTL" and the MTL file that "mtllib f.mtl" names; both are written to a private
 * temporary folder and read back.  A scene that parses is also subdivided. */
#include "ulam_radiosity.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Write n bytes to dir/name; 0 on success. */
static int put(const char *dir, const char *name, const uint8_t *p, size_t n)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    int bad = fwrite(p, 1, n, f) != n;
    return fclose(f) != 0 || bad;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char dir[64];
    if (!dir[0]) {
        snprintf(dir, sizeof dir, "/tmp/ulam_fuzz_obj.XXXXXX");
        if (!mkdtemp(dir)) return 0;
    }
    const uint8_t *sep = NULL;
    for (size_t k = 0; k + 6 <= size && !sep; k++)
        if (!memcmp(data + k, "\n%%MTL", 6)) sep = data + k;
    size_t objn = sep ? (size_t)(sep - data) + 1 : size;
    if (put(dir, "f.obj", data, objn)) return 0;
    if (sep && put(dir, "f.mtl", sep + 6, size - objn - 5)) return 0;
    if (!sep) {
        char path[512];
        snprintf(path, sizeof path, "%s/f.mtl", dir);
        remove(path);
    }
    char path[512];
    snprintf(path, sizeof path, "%s/f.obj", dir);
    ulam_scene *s = NULL, *d = NULL;
    ulam_error err;
    if (ulam_scene_read_obj(path, &s, &err) == ULAM_OK && s->npatches < 1000) {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, d2 = 0;
        for (int64_t v = 0; v < s->nverts; v++)
            for (int c = 0; c < 3; c++)
                lo[c] = fmin(lo[c], s->vert[3 * v + c]), hi[c] = fmax(hi[c], s->vert[3 * v + c]);
        for (int c = 0; c < 3; c++) d2 += (hi[c] - lo[c]) * (hi[c] - lo[c]);
        if (d2 > 0 && isfinite(d2)) ulam_scene_subdivide(s, sqrt(d2) / 4, &d); /* a few pieces a face */
        ulam_scene_free(d);
    }
    ulam_scene_free(s);
    return 0;
}
