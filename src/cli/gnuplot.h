/* Charts for the programs around the library (ulam study, examples/, tests/bench/): gnuplot
 * (pngcairo) fed a script on a pipe, the PNG renamed into place when done.  An application
 * helper, not library code: it starts a process. */
#ifndef ULAM_GNUPLOT_H
#define ULAM_GNUPLOT_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ulam.h"

/* Draw DIR/NAME.png (width x height pixels) from script, gnuplot run in DIR with the data files'
 * separator ',' and a grid; written under a temporary name and renamed into place.  ULAM_OK,
 * ULAM_EINVAL (a quote in dir or name), ULAM_ENOMEM, or ULAM_EIO when gnuplot is missing or
 * fails (nothing is left behind). */
static inline int gnuplot_draw(const char *dir, const char *name, int width, int height, const char *script)
{
    if (!dir || !name || !script || strchr(dir, '\'') || strchr(name, '\'')) return ULAM_EINVAL;
    size_t len = strlen(dir) + strlen(name) + 64;
    char *png = malloc(len), *tmp = malloc(len), *cmd = malloc(len);
    int status = ULAM_ENOMEM;
    if (png && tmp && cmd) {
        snprintf(png, len, "%s/%s.png", dir, name);
        snprintf(tmp, len, "%s/%s.png.tmp.png", dir, name);
        snprintf(cmd, len, "cd '%s' && gnuplot 2>/dev/null", dir);
        FILE *g = popen(cmd, "w");
        status = ULAM_EIO;
        if (g) {
            fprintf(g, "set terminal pngcairo size %d,%d font 'sans,10'\nset output '%s.png.tmp.png'\n"
                       "set datafile separator ','\nset grid\n%s\nset output\n",
                    width, height, name, script);
            int rc = pclose(g);
            status = rc == 0 && rename(tmp, png) == 0 ? ULAM_OK : ULAM_EIO;
        }
        if (status) remove(tmp);
    }
    free(png), free(tmp), free(cmd);
    return status;
}

#endif
