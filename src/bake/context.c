/* context.c: what a long-running caller keeps warm between bakes
 * (bb_bake_context, bumpbake serve): the ray set of the last bake, reused
 * while its parameters are the same (rayset.c builds the same bits every
 * time, so a bake with it is a cold bake's bits), and the process's heap
 * kept from handing the bake's freed buffers back to the system, so the
 * next bake of the same size finds them mapped (no page faults, no
 * zeroing by the kernel). With bb_bake_context_keep, it also holds what
 * the last bake made, for the next to bake again only what an edit
 * reaches (rebake.c). */
#include "bake/bake_internal.h"
#include "core/internal.h"
#include "trace/rayset.h"

#include <malloc.h>
#include <stdlib.h>
#include <string.h>

struct bb_bake_context {
  bb_rayset rays; /* the last ray set built, when have_rays */
  int have_rays;
  int slices;
  double power;
  bb_basis basis;
  long rayset_builds; /* ray sets built through the context (tests) */
  int keep;           /* bb_bake_context_keep's */
  bb__kept *kept;     /* what the last bake made, while keep (rebake.c's) */
  void (*kept_free)(bb__kept *); /* and how it goes: rebake.c's, which
                                    this file does not call by name (the
                                    kept bake is rebake.c's business) */
  bb_region changed;  /* what the last bake changed (bb_bake_context_changed) */
};

bb_status bb_bake_context_new(bb_bake_context **out, bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "bake context: out is NULL");
  *out = calloc(1, sizeof **out);
  if (!*out)
    return bb__fail(err, BB_ERR_MEMORY, "bake context: out of memory");
  /* glibc: buffers up to 32 MiB (its largest threshold: 1024 x 1024 x 8
   * channels of floats) from the heap, not mmap, and a heap that is not
   * trimmed, so they stay mapped from one bake to the next. */
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  return BB_OK;
}

void bb_bake_context_free(bb_bake_context *c) {
  if (!c)
    return;
  if (c->have_rays)
    bb__rayset_release(&c->rays);
  bb__context_hold(c, NULL, NULL);
  free(c);
}

void bb_bake_context_keep(bb_bake_context *c, int keep) {
  if (!c)
    return;
  c->keep = keep != 0;
  if (!c->keep)
    bb__context_hold(c, NULL, NULL);
}

int bb__context_keeps(const bb_bake_context *c) {
  return c && c->keep;
}

bb__kept *bb__context_kept(const bb_bake_context *c) {
  return c->kept;
}

void bb__context_hold(bb_bake_context *c, bb__kept *kept, void (*kept_free)(bb__kept *)) {
  if (c->kept && c->kept != kept)
    c->kept_free(c->kept);
  c->kept = kept;
  c->kept_free = kept_free;
}

void bb__context_set_changed(bb_bake_context *c, bb_region changed) {
  if (c)
    c->changed = changed;
}

bb_region bb_bake_context_changed(const bb_bake_context *c) {
  return c ? c->changed : (bb_region){0, 0, 0, 0};
}

int bb__same_basis(const bb_basis *a, const bb_basis *b) {
  return a->count == b->count && strcmp(a->name, b->name) == 0 &&
         memcmp(a->vector, b->vector, sizeof a->vector) == 0;
}

bb_status bb__context_rayset(bb_bake_context *c, int slices, double power,
                             const bb_basis *basis, int threads, bb_rayset *rays, int *owned,
                             bb_error *err) {
  *owned = 1;
  if (!c)
    return bb__rayset_make(slices, power, basis, threads, rays, err);
  if (!(c->have_rays && c->slices == slices && c->power == power &&
        bb__same_basis(&c->basis, basis))) {
    bb_rayset made = {0};
    bb_status st = bb__rayset_make(slices, power, basis, threads, &made, err);
    if (st != BB_OK)
      return st;
    if (c->have_rays)
      bb__rayset_release(&c->rays);
    c->rays = made;
    c->have_rays = 1;
    c->slices = slices;
    c->power = power;
    c->basis = *basis;
    c->rayset_builds++;
  }
  *rays = c->rays; /* lent: the context frees it */
  *owned = 0;
  return BB_OK;
}

long bb__context_rayset_builds(const bb_bake_context *c) { return c ? c->rayset_builds : 0; }
