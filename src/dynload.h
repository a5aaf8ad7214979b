/* The optional libraries ulam opens on first use (dlopen) instead of at every start: LAPACKE (and
 * through it OpenBLAS), ARPACK, UMFPACK, Embree and libpng.  A query that needs none of them
 * does not map and relocate some 25 shared objects (issue 29: ~15 ms a start, twice with the
 * passive-threads re-exec).  Each library is a row of dynload.c's table; each function returns
 * the library's function table, loaded once per process, or NULL with err filled (ULAM_EIO:
 * the library cannot be loaded, naming it and what dlopen said). */
#ifndef ULAM_DYNLOAD_H
#define ULAM_DYNLOAD_H

#include "internal.h"

#include <arpack.h>
#include <lapacke.h>
#ifdef ULAM_UMFPACK
#include <suitesparse/umfpack.h>
#endif
#ifdef ULAM_RADIOSITY
#include <embree3/rtcore.h>
#include <png.h>
#endif

/* Open the first of files (up to 3, NULL-ended) that dlopen loads, for what (messages), and fill
 * api, one function pointer a symbol, with syms (NULL-ended) in order: ULAM_OK, or ULAM_EIO with
 * why (cap bytes) naming the library, what it is for and what dlopen said (dynload.c's rows). */
int ulam__dl_open(const char *const *files, const char *what, const char *const *syms, void *api, char *why, size_t cap);

/* LAPACKE: the dense solves (direct.c, radiosity's formfactor.c) and small eigenproblems (spectral.c). */
typedef struct {
    __typeof__(LAPACKE_dgesv) *dgesv;
    __typeof__(LAPACKE_dgecon) *dgecon;
    __typeof__(LAPACKE_dlange) *dlange;
    __typeof__(LAPACKE_dgeev) *dgeev;
} ulam__lapacke_api;
const ulam__lapacke_api *ulam__lapacke(ulam_error *err);

/* ARPACK-NG: the spectral radius of a large operator (spectral.c). */
typedef struct {
    __typeof__(dnaupd_c) *dnaupd;
    __typeof__(dneupd_c) *dneupd;
} ulam__arpack_api;
const ulam__arpack_api *ulam__arpack(ulam_error *err);

#ifdef ULAM_UMFPACK
/* UMFPACK: the sparse reference solve (sparse_direct.c). */
typedef struct {
    __typeof__(umfpack_dl_defaults) *defaults;
    __typeof__(umfpack_dl_symbolic) *symbolic;
    __typeof__(umfpack_dl_numeric) *numeric;
    __typeof__(umfpack_dl_solve) *solve;
    __typeof__(umfpack_dl_free_symbolic) *free_symbolic;
    __typeof__(umfpack_dl_free_numeric) *free_numeric;
} ulam__umfpack_api;
const ulam__umfpack_api *ulam__umfpack(ulam_error *err);
#endif

#ifdef ULAM_RADIOSITY
/* Embree 3: ray casting (radiosity/rays.c). */
typedef struct {
    __typeof__(rtcNewDevice) *NewDevice;
    __typeof__(rtcReleaseDevice) *ReleaseDevice;
    __typeof__(rtcGetDeviceError) *GetDeviceError;
    __typeof__(rtcNewScene) *NewScene;
    __typeof__(rtcReleaseScene) *ReleaseScene;
    __typeof__(rtcSetSceneFlags) *SetSceneFlags;
    __typeof__(rtcSetSceneBuildQuality) *SetSceneBuildQuality;
    __typeof__(rtcCommitScene) *CommitScene;
    __typeof__(rtcNewGeometry) *NewGeometry;
    __typeof__(rtcReleaseGeometry) *ReleaseGeometry;
    __typeof__(rtcSetNewGeometryBuffer) *SetNewGeometryBuffer;
    __typeof__(rtcSetGeometryIntersectFilterFunction) *SetGeometryIntersectFilterFunction;
    __typeof__(rtcCommitGeometry) *CommitGeometry;
    __typeof__(rtcAttachGeometry) *AttachGeometry;
    __typeof__(rtcIntersect1) *Intersect1;
} ulam__embree_api;
const ulam__embree_api *ulam__embree(ulam_error *err);

/* libpng: writing PNG images (radiosity/image.c). */
typedef struct {
    __typeof__(png_create_write_struct) *create_write_struct;
    __typeof__(png_create_info_struct) *create_info_struct;
    __typeof__(png_destroy_write_struct) *destroy_write_struct;
    __typeof__(png_set_longjmp_fn) *set_longjmp_fn;
    __typeof__(png_init_io) *init_io;
    __typeof__(png_set_IHDR) *set_IHDR;
    __typeof__(png_set_sRGB) *set_sRGB;
    __typeof__(png_write_info) *write_info;
    __typeof__(png_write_row) *write_row;
    __typeof__(png_write_end) *write_end;
} ulam__png_api;
const ulam__png_api *ulam__png(ulam_error *err);
#endif

#endif
