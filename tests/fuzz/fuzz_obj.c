/* libFuzzer target: the OBJ/MTL reader.  The input is an OBJ file, optionally followed by a
 * line "%%MTL" and the MTL file that "mtllib f.mtl" names; both are written to a private
 * temporary folder and read back.  A scene that parses is also subdivided. */
#include "ulam.h"

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
    if (ulam_scene_read_obj(path, &s, &err) == ULAM_OK && s->nverts < 1000 && s->npatches < 1000) {
        ulam_scene_subdivide(s, 1.0, &d); /* the scene's own scale, capped by the patch count */
        ulam_scene_free(d);
    }
    ulam_scene_free(s);
    return 0;
}
