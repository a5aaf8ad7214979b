/* ulam_defaults: one exported call fills any option struct with its defaults, by kind; each
 * struct's one-line wrapper in ulam.h (ulam_walk_defaults() ...) calls it, so a program keeps
 * reading the defaults of the library it runs with. */
#include "defaults.h"

#include <string.h>

/* Fill opts (size bytes) with kind's defaults: ULAM_OK, or ULAM_EINVAL (opts zeroed) for an
 * unknown kind or a size that is not this library's struct. */
int ulam_defaults(int kind, void *opts, size_t size)
{
    if (!opts) return ULAM_EINVAL;
#define ULAM_DEFAULTS_ROW(k, type, fill)                                                           \
    case k:                                                                                      \
        if (size != sizeof(type)) break;                                                         \
        *(type *)opts = fill();                                                                  \
        return ULAM_OK;
    switch (kind) {
        ULAM_DEFAULTS_ROW(ULAM_KIND_WALK, ulam_walk_opts, ulam__walk_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_OUTER, ulam_outer_opts, ulam__outer_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_BIDIR, ulam_bidir_opts, ulam__bidir_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_ANALYSIS, ulam_analysis_opts, ulam__analysis_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_METHOD, ulam_method_opts, ulam__method_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_AUTO, ulam_auto_opts, ulam__auto_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_MM, ulam_mm_opts, ulam__mm_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_SPECTRAL, ulam_spectral_opts, ulam__spectral_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_POWER, ulam_power_opts, ulam__power_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_GUARD, ulam_guard_opts, ulam__guard_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_FPUSH, ulam_fpush_opts, ulam__fpush_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_SHARE, ulam_share, ulam__share_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_SYSTEM_DESC, ulam_system_desc, ulam__system_desc_defaults)
        ULAM_DEFAULTS_ROW(ULAM_KIND_DIST, ulam_dist_opts, ulam__dist_defaults)
    default:
        break;
    }
#undef ULAM_DEFAULTS_ROW
    memset(opts, 0, size);
    return ULAM_EINVAL;
}
