/* The optional libraries, opened on first use (see dynload.h): one row a library, naming the
 * files to try (its soname first) and the symbols its function table holds, in order. */
#include "dynload.h"

#include <dlfcn.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

#define STR_(x) #x
#define STR(x) STR_(x)

/* One library: what it is for (messages), the files tried in turn, the symbols, their table. */
typedef struct {
    const char *what;
    const char *files[3];
    const char *const *syms;
    void *api;
    _Atomic int state; /* 0: not tried, 1: loaded, -1: failed (why says so) */
    char why[320];
} lib_row;

/* Serialises the loads: a row is filled once, by whichever thread comes first. */
static pthread_mutex_t load_lock = PTHREAD_MUTEX_INITIALIZER;

/* Open the first of files (up to 3, NULL-ended) that loads and fill api with its syms. */
int ulam__dl_open(const char *const *files, const char *what, const char *const *syms, void *api, char *why, size_t cap)
{
    void *h = NULL;
    const char *said = "";
    for (int k = 0; k < 3 && files[k] && !h; k++)
        if (!(h = dlopen(files[k], RTLD_NOW | RTLD_LOCAL)) && k == 0) said = dlerror();
    if (!h) {
        snprintf(why, cap, "%s for %s (dlopen: %s)", files[0], what, said ? said : "?");
        return ULAM_EIO;
    }
    for (size_t k = 0; syms[k]; k++) {
        void *f = dlsym(h, syms[k]);
        if (!f) {
            snprintf(why, cap, "%s for %s (it has no %s)", files[0], what, syms[k]);
            return ULAM_EIO; /* h stays open: harmless, and closing it could unload what others use */
        }
        memcpy((char *)api + k * sizeof f, &f, sizeof f); /* POSIX: a function pointer is a void * */
    }
    return ULAM_OK;
}

/* Row L's table, loading it on first use; NULL with err filled when it cannot be loaded. */
static const void *load(lib_row *L, ulam_error *err)
{
    int s = atomic_load_explicit(&L->state, memory_order_acquire);
    if (!s) {
        pthread_mutex_lock(&load_lock);
        if (!(s = atomic_load_explicit(&L->state, memory_order_relaxed))) {
            s = ulam__dl_open(L->files, L->what, L->syms, L->api, L->why, sizeof L->why) ? -1 : 1;
            atomic_store_explicit(&L->state, s, memory_order_release);
        }
        pthread_mutex_unlock(&load_lock);
    }
    if (s > 0) return L->api;
    ulam__fail(err, ULAM_EIO, 0, -1, "a loadable %s", L->why);
    return NULL;
}

static ulam__lapacke_api lapacke_api;
static const char *const lapacke_syms[] = {"LAPACKE_dgesv", "LAPACKE_dgecon", "LAPACKE_dlange", "LAPACKE_dgeev", NULL};
_Static_assert(sizeof lapacke_api == (sizeof lapacke_syms / sizeof *lapacke_syms - 1) * sizeof(void *), "one slot a symbol");
static lib_row lapacke_row = {"dense LU and eigenvalues (Debian: liblapacke)", {"liblapacke.so.3", "liblapacke.so"},
                              lapacke_syms, &lapacke_api, 0, ""};

/* LAPACKE's table. */
const ulam__lapacke_api *ulam__lapacke(ulam_error *err)
{
    return load(&lapacke_row, err);
}

static ulam__arpack_api arpack_api;
static const char *const arpack_syms[] = {"dnaupd_c", "dneupd_c", NULL};
_Static_assert(sizeof arpack_api == (sizeof arpack_syms / sizeof *arpack_syms - 1) * sizeof(void *), "one slot a symbol");
static lib_row arpack_row = {"the spectral radius of a large matrix (Debian: libarpack2)",
                             {"libarpack.so.2", "libarpack.so"}, arpack_syms, &arpack_api, 0, ""};

/* ARPACK's table. */
const ulam__arpack_api *ulam__arpack(ulam_error *err)
{
    return load(&arpack_row, err);
}

#ifdef ULAM_UMFPACK
static ulam__umfpack_api umfpack_api;
static const char *const umfpack_syms[] = {"umfpack_dl_defaults",      "umfpack_dl_symbolic",     "umfpack_dl_numeric",
                                           "umfpack_dl_solve",         "umfpack_dl_free_symbolic", "umfpack_dl_free_numeric",
                                           NULL};
_Static_assert(sizeof umfpack_api == (sizeof umfpack_syms / sizeof *umfpack_syms - 1) * sizeof(void *), "one slot a symbol");
static lib_row umfpack_row = {"the sparse LU (Debian: libumfpack" STR(UMFPACK_MAIN_VERSION) ")",
                              {"libumfpack.so." STR(UMFPACK_MAIN_VERSION), "libumfpack.so"}, umfpack_syms, &umfpack_api, 0, ""};

/* UMFPACK's table. */
const ulam__umfpack_api *ulam__umfpack(ulam_error *err)
{
    return load(&umfpack_row, err);
}
#endif

#ifdef ULAM_RADIOSITY
static ulam__embree_api embree_api;
static const char *const embree_syms[] = {
    "rtcNewDevice",     "rtcReleaseDevice",     "rtcGetDeviceError",       "rtcNewScene",
    "rtcReleaseScene",  "rtcSetSceneFlags",     "rtcSetSceneBuildQuality", "rtcCommitScene",
    "rtcNewGeometry",   "rtcReleaseGeometry",   "rtcSetNewGeometryBuffer", "rtcSetGeometryIntersectFilterFunction",
    "rtcCommitGeometry", "rtcAttachGeometry",   "rtcIntersect1",           NULL};
_Static_assert(sizeof embree_api == (sizeof embree_syms / sizeof *embree_syms - 1) * sizeof(void *), "one slot a symbol");
static lib_row embree_row = {"ray casting (Debian: libembree3-3)",
                             {"libembree3.so." STR(RTC_VERSION_MAJOR), "libembree3.so"}, embree_syms, &embree_api, 0, ""};

/* Embree's table. */
const ulam__embree_api *ulam__embree(ulam_error *err)
{
    return load(&embree_row, err);
}

static ulam__png_api png_api;
static const char *const png_syms[] = {"png_create_write_struct", "png_create_info_struct", "png_destroy_write_struct",
                                       "png_set_longjmp_fn",      "png_init_io",            "png_set_IHDR",
                                       "png_set_sRGB",            "png_write_info",         "png_write_row",
                                       "png_write_end",           NULL};
_Static_assert(sizeof png_api == (sizeof png_syms / sizeof *png_syms - 1) * sizeof(void *), "one slot a symbol");
static lib_row png_row = {"PNG images (Debian: libpng16-16)",
                          {"libpng" STR(PNG_LIBPNG_VER_DLLNUM) ".so." STR(PNG_LIBPNG_VER_SONUM), "libpng.so"}, png_syms,
                          &png_api, 0, ""};

/* libpng's table. */
const ulam__png_api *ulam__png(ulam_error *err)
{
    return load(&png_row, err);
}
#endif
