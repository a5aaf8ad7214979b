/* A luminaire file read by its format: the one caller of both readers (ies.c, ldt.c), above them
 * and gonio.c's table, so no reader calls back into a file that calls it. */
#include "photo.h"

#include <string.h>

/* EULUMDAT by the name's .ldt ending, else IES. */
int ulam_gonio_read(const char *path, ulam_gonio **out, ulam_error *err)
{
    size_t n = path ? strlen(path) : 0;
    int ldt = n > 4 && path[n - 4] == '.' && (path[n - 3] | 32) == 'l' && (path[n - 2] | 32) == 'd' &&
              (path[n - 1] | 32) == 't';
    return ldt ? ulam_gonio_read_ldt(path, out, err) : ulam_gonio_read_ies(path, out, err);
}
