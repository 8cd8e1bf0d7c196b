/* rayset.h: building ray sets with the bake's thread count, and
 * their ids (rayset.c). */
#ifndef BB_TRACE_RAYSET_H
#define BB_TRACE_RAYSET_H

#include "bumpbake.h"

#include <stddef.h>

/* Largest |a| or |b| of a ray set's lattice steps (and of what sweep.c takes). */
#define BB__MAX_LATTICE_STEP 128


/* bb_rayset_make with the bake's thread count (the tables are built in
 * parallel; the same bits for any count). */
bb_status bb__rayset_make(int slices, double power, const bb_basis *basis, int threads,
                          bb_rayset *out, bb_error *err);

/* The id bb_rayset_make gives a rayset of these parameters, into out
 * (capacity cap), without building it. */
void bb__rayset_id(int slices, double power, const bb_basis *basis, char *out, size_t cap);

#endif /* BB_TRACE_RAYSET_H */
