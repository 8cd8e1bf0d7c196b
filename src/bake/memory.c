/* memory.c: what a bake will allocate, worked out from its size and
 * options alone before anything is allocated (bake.c's stages, in their
 * order, each map counted while it is alive), so that one too large for
 * the machine is refused with the figures instead of being killed. */
#include "bake/bake_internal.h"
#include "core/internal.h"

/* Bytes alive as the stages go, and the most at any one time. */
typedef struct ledger {
  double alive, peak;
} ledger;

static void take(ledger *l, double bytes) {
  l->alive += bytes;
  if (l->alive > l->peak)
    l->peak = l->alive;
}

static void give(ledger *l, double bytes) {
  l->alive -= bytes;
}

/* A line sweep's buffers on one thread: the profile and two hulls of 24-byte
 * points for the longest line of a bundle, whose points a periodic line
 * caps near 2^20 (longer ones go in chunks) and a clamped line keeps near
 * a few per texel of its length; the profiles of the 3 periodic lines
 * filled beside it (sweep.c's LANES, lines of up to 2^17 points); and 56
 * bytes per texel of the line, 16 more for each line beside it. */
static double sweep_scratch(int width, int height) {
  const double side = width > height ? width : height;
  double points = 64.0 * side; /* up to 4 steps past each end, 16 points a step */
  if (points > 1.2 * (1 << 20))
    points = 1.2 * (1 << 20);
  const double beside = points < 131072.0 ? points : 131072.0;
  return 3.0 * 24.0 * points + 3.0 * 24.0 * beside + (56.0 + 3.0 * 16.0) * 4.0 * side +
         256.0 * 1024.0;
}

/* The pyramid's level maxima (level 0: one node per texel). */
static double pyramid_levels(int width, int height) {
  double bytes = 0.0;
  for (long w = width, h = height;; w = (w + 1) / 2, h = (h + 1) / 2) {
    bytes += 4.0 * (double)w * (double)h;
    if (w == 1 && h == 1)
      break;
  }
  return bytes;
}

static int wants(const bb_bake_options *o, unsigned bits) {
  return (o->outputs & bits) != 0;
}

double bb__bake_memory(int width, int height, const bb_bake_options *o, unsigned flags,
                       double held, double *kept) {
  const double t = (double)width * (double)height, texel = 4.0 * t;
  const int lobes = o->basis.count > 0 ? o->basis.count : 3;
  const int threads = bb__thread_count(o->trace.threads);
  const int traced = wants(o, BB_MAPS_TRACED);
  const unsigned normal = BB_MAP_BIT(BB_MAP_NORMAL), weights = BB_MAP_BIT(BB_MAP_WEIGHTS),
                 ssbump = BB_MAP_BIT(BB_MAP_SSBUMP), ao = BB_MAP_BIT(BB_MAP_AO),
                 bent = BB_MAP_BIT(BB_MAP_BENT), filtered = BB_MAP_BIT(BB_MAP_FILTERED);
  ledger l = {held, held};
  take(&l, texel); /* smoothed height */
  if (flags & BB__BAKE_TAKE_HEIGHT)
    give(&l, held);
  const int normal_now = wants(o, weights) || (wants(o, normal) && !traced);
  double normals = normal_now ? 3 * texel : 0.0, filtered_alive = texel;
  take(&l, normals);
  if (wants(o, weights))
    take(&l, lobes * texel);
  if (traced) {
    const double levels = pyramid_levels(width, height);
    const int slices = o->slices; /* prepared: bb__bake_prepare */
    take(&l, texel);                   /* heights in texels */
    take(&l, texel + levels + texel);  /* the pyramid's copy, its levels, a row pass */
    give(&l, texel);                   /* the row pass */
    give(&l, texel);                   /* heights in texels */
    take(&l, (double)slices * lobes * 8192.0 + 65536.0); /* the ray set's tables */
    const double vis = (1 + lobes) * texel;
    take(&l, vis);
    take(&l, threads * sweep_scratch(width, height));
    give(&l, threads * sweep_scratch(width, height));
    if (o->bounce_albedo > 0.0) { /* bounce.c: three sums per triangle corner, the albedo's grey */
      const double bounce = 3.0 * 6.0 * (1 + lobes) * texel + texel +
                            threads * sweep_scratch(width, height) * 2.0;
      take(&l, bounce);
      give(&l, bounce);
    }
    give(&l, texel + levels + (double)slices * lobes * 8192.0 + 65536.0);
    const int normal_later = wants(o, normal) && !normal_now;
    double ssbump_alive = 0.0;
    if (wants(o, ssbump | bent)) {
      ssbump_alive = lobes * texel;
      take(&l, ssbump_alive);
      if (!normals) { /* normals a band at a time */
        take(&l, threads * 16.0 * width * 12.0);
        give(&l, threads * 16.0 * width * 12.0);
      }
    }
    if (!normal_later && !wants(o, filtered))
      give(&l, filtered_alive), filtered_alive = 0.0;
    if (wants(o, ao))
      take(&l, texel);
    if (flags & BB__BAKE_DROP_VIS)
      give(&l, vis);
    if (normal_later)
      take(&l, 3 * texel), normals = 3 * texel;
    if (!wants(o, filtered))
      give(&l, filtered_alive), filtered_alive = 0.0;
    if (wants(o, bent))
      take(&l, 3 * texel);
    if (!wants(o, ssbump))
      give(&l, ssbump_alive);
  }
  if (!wants(o, filtered))
    give(&l, filtered_alive);
  if (!wants(o, normal))
    give(&l, normals);
  if (o->brightness) /* ssbump and weights each scaled into a copy */
    take(&l, lobes * texel), give(&l, lobes * texel);
  if (kept)
    *kept = l.alive;
  return l.peak;
}
