/* rayset.h: building ray sets with the bake's thread count, and
 * their ids (rayset.c). */
#ifndef BB_TRACE_RAYSET_H
#define BB_TRACE_RAYSET_H

#include "bumpbake.h"

#include <stddef.h>

/* Largest |a| or |b| of a ray set's lattice steps (and of what sweep.c takes). */
#define BB__MAX_LATTICE_STEP 128


/* The ray set's layout (bumpbake.h describes what it stands for). */
struct bb_rayset {
  int slice_count;           /* A, 1..BB_MAX_SLICES */
  int basis_count;           /* lobes: the basis' count, 3..BB_MAX_BASIS */
  double power;              /* P >= 1 of the lobes */
  double basis[BB_MAX_BASIS][3]; /* unit lobe directions B_c (the basis' vectors) */
  int *slice_step;           /* 2 per slice: the lattice step (a, b), coprime */
  double *slice_dir;         /* 2 per slice: unit (dx, dy) along (a, b) */
  double *sector;            /* 2 per slice: first and last azimuth, radians */
  double *half_width;        /* per slice: (last - first) / 2 */
  double *table;             /* per slice, the lobes' tables (integrate.c's layout) */
  double total[1 + BB_MAX_BASIS]; /* the whole integrals: pi for ao, then each lobe's */
  char id[64];               /* names the scheme and its parameters, for provenance */
};

/* bb__rayset_new into a struct of the caller's (a bake keeps it on its
 * stack), with the bake's thread count (the tables are built in parallel;
 * the same bits for any count). Release it with bb__rayset_release. */
bb_status bb__rayset_make(int slices, double power, const bb_basis *basis, int threads,
                          bb_rayset *out, bb_error *err);

/* Frees what bb__rayset_make allocated in rs and zeroes it. */
void bb__rayset_release(bb_rayset *rs);

/* The id bb__rayset_new gives a rayset of these parameters, into out
 * (capacity cap), without building it. */
void bb__rayset_id(int slices, double power, const bb_basis *basis, char *out, size_t cap);

/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* Azimuth slices a budget of `rays` rays per texel stands for, as Valve's
 * tool counts rays: round(sqrt(rays)), at least 1 (so -r 250 and 256 both
 * give 16). */
int bb__slices_for_rays(int rays);

/* Builds the slices and their integration tables: slices in
 * 1..BB_MAX_SLICES, power >= 1, one lobe per direction of basis (NULL:
 * "hl2"; copied). The tables cost slices x basis->count x 8 KiB and their
 * build time grows with the same product. On success *out receives the
 * ray set; free it with bb_rayset_free. */
bb_status bb__rayset_new(int slices, double power, const bb_basis *basis, bb_rayset **out,
                         bb_error *err);

#endif /* BB_TRACE_RAYSET_H */
