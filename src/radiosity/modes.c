/* The radiosity modes, one row each: the name the command line and the bindings take, the mode
 * value of ulam_rad_opts, and a one-line summary. */
#include "rad.h"

#include <string.h>

/* One mode. */
typedef struct {
    const char *name;
    int mode;
    const char *summary;
} rad_mode;

static const rad_mode modes[] = {
    {"gather", ULAM_ADJOINT, "walks from one patch that gather emission (patchwalk.c)"},
    {"shoot", ULAM_FORWARD, "particles from the emitters, tallied on every patch (patchwalk.c)"},
    {"final", ULAM_RAD_FINAL, "every patch gathers over a shooting pilot: light sampling and the pilot's "
                              "reflected light at each cosine ray's landing (final.c)"},
};

/* The mode named name, or -1. */
int ulam_rad_mode_find(const char *name)
{
    for (size_t k = 0; name && k < sizeof modes / sizeof *modes; k++)
        if (!strcmp(modes[k].name, name)) return modes[k].mode;
    return -1;
}

/* A mode's name and summary, or NULL. */
const char *ulam_rad_mode_name(int mode, const char **summary)
{
    for (size_t k = 0; k < sizeof modes / sizeof *modes; k++)
        if (modes[k].mode == mode) {
            if (summary) *summary = modes[k].summary;
            return modes[k].name;
        }
    return NULL;
}
