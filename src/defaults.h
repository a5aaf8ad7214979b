/* The option structs' defaults (src/defaults.c): each module fills its own struct, and
 * ulam_defaults, the one exported call, picks the filler by kind (ulam.h's wrappers,
 * ulam_walk_defaults() ..., call it). */
#ifndef ULAM_DEFAULTS_H
#define ULAM_DEFAULTS_H

#include "internal.h"
#include "ulam_dist.h"

/* Each returns its struct with every field at its default (the public wrapper's comment in
 * ulam.h says which values). */
ulam_walk_opts ulam__walk_defaults(void);         /* src/solve.c */
ulam_outer_opts ulam__outer_defaults(void);       /* src/mcsa.c */
ulam_bidir_opts ulam__bidir_defaults(void);       /* src/bidir.c */
ulam_analysis_opts ulam__analysis_defaults(void); /* src/analysis.c */
ulam_method_opts ulam__method_defaults(void);     /* src/method.c */
ulam_auto_opts ulam__auto_defaults(void);         /* src/auto.c */
ulam_mm_opts ulam__mm_defaults(void);             /* src/mmio.c */
ulam_spectral_opts ulam__spectral_defaults(void); /* src/spectral.c */
ulam_power_opts ulam__power_defaults(void);       /* src/spectral.c */
ulam_guard_opts ulam__guard_defaults(void);       /* src/guard.c */
ulam_fpush_opts ulam__fpush_defaults(void);       /* src/fpush.c */
ulam_share ulam__share_defaults(void);            /* src/round.c */
ulam_system_desc ulam__system_desc_defaults(void); /* src/cache.c */
ulam_dist_opts ulam__dist_defaults(void);         /* src/dist.c */

#endif
