/* rebake.c: bakes through a context that keeps what they made
 * (bb_bake_context_keep): the whole bake once, then, for a height of the
 * same size and options, only what the change can reach.
 *
 * The reach, stage by stage, each found exactly (by comparing bits) where
 * it is cheap and bounded from above where it is not:
 *   height     the texels that differ from the kept height (a rectangle:
 *              the smallest holding them, wrapping on a periodic map);
 *   smoothing  those widened by the filter's reach, smoothed again; the
 *              texels whose smoothing changed make the changed heights;
 *   pyramid    the nodes above those (bb__pyramid_update);
 *   trace      per slice, the horizons the change can move along the lines
 *              crossing it (bb__retrace_run), written where they changed;
 *   normals    the changed heights widened by 2 (the estimators' reach);
 *   derive     every texel whose normal, visibility or brightness changed.
 * Each stage's texels are computed by the very arithmetic of the whole
 * bake, so the maps kept are the whole bake's bits; tests compare them
 * with memcmp after random edits. */
#include "bake/bake_internal.h"
#include "core/internal.h"
#include "trace/pyramid.h"
#include "trace/rayset.h"
#include "trace/retrace.h"
#include "bumpbake_cluster.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A change over more than this share of the texels bakes whole. */
#define WHOLE_SHARE 0.25

/* The normal estimators read at most this far from a texel. */
#define NORMAL_REACH 2

/* Marks of a texel in kept->mark, zero between bakes. */
enum {
  MARK_VIS = 1,        /* a horizon changed: its visibility again */
  MARK_NORMAL = 2,     /* its normal changed */
  MARK_BRIGHTNESS = 4, /* its brightness changed */
  MARK_FILTERED = 8    /* its smoothed height changed */
};

struct bb__kept {
  bb_bake_options o; /* as baked; the maps it points to are not kept */
  int has_brightness;
  int width, height;
  bb_image height_in;  /* the height baked */
  bb_image filtered;   /* its smoothing */
  bb_image normals;    /* their normals, +Y down (when a map needs them) */
  bb_bake_result maps; /* the maps asked but filtered, and vis when traced */
  bb_image grey;       /* the brightness map's grey */
  bb_pyramid *pyramid; /* when traced */
  float **horizons;    /* when traced: a width x height image per slice */
  int slices;
  int order[BB_MAX_SLICES];
  unsigned char *mark; /* width x height */
  bb_region changed;   /* the last bake's */
  int last_local;      /* was it edit-local? */
};

static int wants(const bb_bake_options *o, unsigned bits) {
  return (o->outputs & bits) != 0;
}

static int traced(const bb_bake_options *o) {
  return wants(o, BB_MAPS_TRACED);
}

/* Does a map (other than the visibility) need the normals? */
static int needs_normals(const bb_bake_options *o) {
  return wants(o, BB_MAPS_TRACED & ~BB_MAP_BIT(BB_MAP_AO)) ||
         wants(o, BB_MAP_BIT(BB_MAP_NORMAL) | BB_MAP_BIT(BB_MAP_WEIGHTS));
}

static void kept_free(bb__kept *k) {
  if (!k)
    return;
  bb_image_free(&k->height_in);
  bb_image_free(&k->filtered);
  bb_image_free(&k->normals);
  bb_bake_result_free(&k->maps);
  bb_image_free(&k->grey);
  bb_pyramid_free(k->pyramid);
  if (k->horizons)
    for (int s = 0; s < k->slices; s++)
      free(k->horizons[s]);
  free(k->horizons);
  free(k->mark);
  free(k);
}

/* Would o bake what the kept bake baked (its maps from the same height)? */
static int same_options(const bb__kept *k, const bb_bake_options *o) {
  const bb_bake_options *a = &k->o;
  return a->height_scale == o->height_scale && a->slices == o->slices &&
         a->smooth.radius_texels == o->smooth.radius_texels &&
         a->smooth.threshold == o->smooth.threshold &&
         a->smooth.addressing == o->smooth.addressing &&
         a->trace.bias_texels == o->trace.bias_texels && a->power == o->power &&
         bb__same_basis(&a->basis, &o->basis) && a->normal_filter == o->normal_filter &&
         a->normal_y_up == o->normal_y_up && a->outputs == o->outputs &&
         k->has_brightness == (o->brightness != NULL);
}

/* ------------------------------------------------------------ rectangles */

/* The smallest run of an axis of n holding every position set in used:
 * first and count, the run wrapping past n on a periodic axis (count 0
 * when none is set). */
static void span_of(const unsigned char *used, int n, int periodic, int *first,
                    int *count) {
  int lo = -1, hi = -1;
  for (int i = 0; i < n; i++)
    if (used[i]) {
      if (lo < 0)
        lo = i;
      hi = i;
    }
  *first = lo < 0 ? 0 : lo;
  *count = lo < 0 ? 0 : hi - lo + 1;
  if (lo < 0 || !periodic)
    return;
  /* the longest gap, going round, is left out */
  int gap = n - 1 - hi + lo, start = lo, last = lo;
  for (int i = lo + 1; i <= hi; i++)
    if (used[i]) {
      if (i - last - 1 > gap)
        gap = i - last - 1, start = i;
      last = i;
    }
  *first = start;
  *count = n - gap;
}

/* A rectangle on the image's axes, x0 and y0 inside it; width and height
 * at most the sides (periodic: it may pass the right and bottom sides). */
typedef struct rect {
  int x0, y0, width, height;
} rect;

static int rect_empty(const rect *r) {
  return r->width <= 0 || r->height <= 0;
}

/* r widened by d on every side, within the image (periodic: wrapping). */
static rect widen(const rect *r, int d, int w, int h, int periodic) {
  if (rect_empty(r))
    return *r;
  rect o = {r->x0 - d, r->y0 - d, r->width + 2 * d, r->height + 2 * d};
  if (periodic) {
    o.x0 = bb__wrap(o.x0, w), o.y0 = bb__wrap(o.y0, h);
    if (o.width >= w)
      o.x0 = 0, o.width = w;
    if (o.height >= h)
      o.y0 = 0, o.height = h;
    return o;
  }
  const int x1 = o.x0 + o.width < w ? o.x0 + o.width : w;
  const int y1 = o.y0 + o.height < h ? o.y0 + o.height : h;
  o.x0 = o.x0 > 0 ? o.x0 : 0, o.y0 = o.y0 > 0 ? o.y0 : 0;
  o.width = x1 - o.x0, o.height = y1 - o.y0;
  return o;
}

/* The image index of the rectangle's texel (i, j). */
static size_t rect_texel(const rect *r, int i, int j, int w, int h) {
  const int x = r->x0 + i < w ? r->x0 + i : r->x0 + i - w;
  const int y = r->y0 + j < h ? r->y0 + j : r->y0 + j - h;
  return (size_t)y * (size_t)w + (size_t)x;
}

/* The smallest rectangle holding the texels of `within` at which image a
 * (1 channel) and b (within's texels, row-major) differ in any bit. */
static bb_status changed_rect(const bb_image *a, const float *b, const rect *within,
                              int periodic, rect *out, bb_error *err) {
  const int w = a->width, h = a->height;
  unsigned char *cols = calloc((size_t)w + (size_t)h, 1);
  if (!cols)
    return bb__fail(err, BB_ERR_MEMORY, "bake: out of memory");
  unsigned char *rows = cols + w;
  const size_t row_bytes = (size_t)within->width * sizeof(float);
  for (int j = 0; j < within->height; j++) {
    /* most rows are the same throughout: one memcmp, when not wrapping */
    const float *row_b = b + (size_t)j * (size_t)within->width;
    if (within->x0 + within->width <= w &&
        memcmp(a->pixels + rect_texel(within, 0, j, w, h), row_b, row_bytes) == 0)
      continue;
    for (int i = 0; i < within->width; i++) {
      const size_t t = rect_texel(within, i, j, w, h);
      if (memcmp(&a->pixels[t], &b[(size_t)j * (size_t)within->width + (size_t)i],
                 sizeof(float)) != 0)
        cols[t % (size_t)w] = 1, rows[t / (size_t)w] = 1;
    }
  }
  rect o;
  span_of(cols, w, periodic, &o.x0, &o.width);
  span_of(rows, h, periodic, &o.y0, &o.height);
  *out = o;
  free(cols);
  return BB_OK;
}

/* a's texels of r, row-major, into a new buffer (NULL: out of memory). */
static float *save_rect(const bb_image *a, const rect *r) {
  float *out = malloc(((size_t)r->width * (size_t)r->height + 1) * sizeof(float));
  if (!out)
    return NULL;
  for (int j = 0; j < r->height; j++)
    for (int i = 0; i < r->width; i++)
      out[(size_t)j * (size_t)r->width + (size_t)i] =
          a->pixels[rect_texel(r, i, j, a->width, a->height)];
  return out;
}

/* ------------------------------------------------------------ whole bake */

/* A copy of an image (none of none). Not bb_image_alloc, whose zeroing
 * would cost as much again as the copy. */
static bb_status copy_image(const bb_image *in, bb_image *out, bb_error *err) {
  memset(out, 0, sizeof *out);
  if (!in->pixels)
    return BB_OK;
  const size_t bytes =
      (size_t)in->width * (size_t)in->height * (size_t)in->channels * sizeof(float);
  if (!(out->pixels = malloc(bytes)))
    return bb__fail(err, BB_ERR_MEMORY, "cannot allocate a %dx%dx%d image", in->width,
                    in->height, in->channels);
  memcpy(out->pixels, in->pixels, bytes);
  out->width = in->width, out->height = in->height, out->channels = in->channels;
  return BB_OK;
}

/* The caller's maps from the kept ones: what bb__bake with flags returns. */
static bb_status copy_out(const bb__kept *k, unsigned flags, bb_bake_result *r,
                          bb_error *err) {
  const bb_bake_result *m = &k->maps;
  bb_status st = BB_OK;
  if (wants(&k->o, BB_MAP_BIT(BB_MAP_FILTERED)))
    st = copy_image(&k->filtered, &r->filtered, err);
  if (st == BB_OK)
    st = copy_image(&m->normal, &r->normal, err);
  if (st == BB_OK)
    st = copy_image(&m->weights, &r->weights, err);
  if (st == BB_OK)
    st = copy_image(&m->ssbump, &r->ssbump, err);
  if (st == BB_OK)
    st = copy_image(&m->ao, &r->ao, err);
  if (st == BB_OK)
    st = copy_image(&m->bent, &r->bent, err);
  if (st == BB_OK && !(flags & BB__BAKE_DROP_VIS))
    st = copy_image(&m->vis, &r->vis, err);
  r->basis = m->basis;
  snprintf(r->rayset_id, sizeof r->rayset_id, "%s", m->rayset_id);
  return st;
}

/* The bytes a kept bake holds besides the maps the bake returns: the
 * height, the smoothing, the normals, the horizons, the visibility and the
 * pyramid, the brightness's grey and the marks. */
static double kept_bytes(int width, int height, const bb_bake_options *o) {
  const double texel = 4.0 * (double)width * (double)height;
  double bytes = 2.0 * texel + texel / 4.0; /* height, smoothing, marks */
  if (needs_normals(o))
    bytes += 3.0 * texel;
  if (o->brightness)
    bytes += texel;
  if (traced(o))
    bytes += (double)o->slices * texel + (1.0 + o->basis.count) * texel + 1.4 * texel;
  return bytes;
}

/* Bakes height whole with o and keeps it all in a new *out. */
static bb_status bake_whole(bb_bake_context *context, const bb_image *height,
                            const bb_bake_options *o, bb__kept **out, bb_bake_result *r,
                            bb_error *err) {
  *out = NULL;
  bb__kept *k = calloc(1, sizeof *k);
  if (!k)
    return bb__fail(err, BB_ERR_MEMORY, "bake: out of memory");
  const int w = height->width, h = height->height;
  const size_t n = (size_t)w * (size_t)h;
  k->o = *o;
  k->o.brightness = NULL, k->o.bounce_albedo_map = NULL;
  k->o.trace.progress = NULL, k->o.trace.progress_user = NULL;
  k->has_brightness = o->brightness != NULL;
  k->width = w, k->height = h;
  bb_status st = BB_OK;
  bb__bake_keep keep = {NULL, NULL};
  if (traced(o)) {
    k->slices = o->slices;
    k->horizons = calloc((size_t)k->slices, sizeof *k->horizons);
    if (!k->horizons)
      st = bb__fail(err, BB_ERR_MEMORY, "bake: out of memory");
    for (int s = 0; st == BB_OK && s < k->slices; s++)
      if (!(k->horizons[s] = malloc(n * sizeof(float))))
        st = bb__fail(err, BB_ERR_MEMORY, "bake: out of memory for the kept horizons");
    keep.horizons = k->horizons;
  }
  if (st == BB_OK)
    st = bb__bake_keeping(height, o, context, &keep, &k->maps, err);
  k->pyramid = keep.pyramid;
  if (st == BB_OK) {
    k->filtered = k->maps.filtered;
    memset(&k->maps.filtered, 0, sizeof k->maps.filtered);
    st = copy_image(height, &k->height_in, err);
  }
  if (st == BB_OK && needs_normals(o))
    st = bb__normals_compute(&k->filtered, o->height_scale, o->normal_filter,
                             o->smooth.addressing, k->maps.threads, NULL, &k->normals,
                             err);
  if (st == BB_OK && o->brightness)
    st = bb__image_grey(o->brightness, w, h, "bake: the brightness map", &k->grey, err);
  if (st == BB_OK && traced(o)) {
    bb_rayset rays;
    int owned = 0;
    st = bb__context_rayset(context, o->slices, o->power, &o->basis, k->maps.threads,
                            &rays, &owned, err);
    if (st == BB_OK)
      st = bb_trace_slice_order(&rays, k->order, err);
    if (st == BB_OK && owned)
      bb__rayset_release(&rays);
  }
  if (st == BB_OK && !(k->mark = calloc(n, 1)))
    st = bb__fail(err, BB_ERR_MEMORY, "bake: out of memory");
  if (st == BB_OK) {
    r->seconds_smooth = k->maps.seconds_smooth;
    r->seconds_pyramid = k->maps.seconds_pyramid;
    r->seconds_trace = k->maps.seconds_trace;
    r->seconds_derive = k->maps.seconds_derive;
    r->horizons_found = k->maps.horizons_found;
    r->threads = k->maps.threads;
    k->changed = (bb_region){0, 0, w, h};
    *out = k;
    return BB_OK;
  }
  kept_free(k);
  return st;
}

/* ------------------------------------------------------------ edit bake */

/* The derive pass: every marked texel's maps again, a row per work item;
 * the marks are cleared. */
typedef struct derive_job {
  bb__kept *k;
  const bb_rayset *rs;
} derive_job;

static void derive_texel(const derive_job *job, size_t t, unsigned m) {
  bb__kept *k = job->k;
  const bb_bake_options *o = &k->o;
  bb_bake_result *maps = &k->maps;
  const bb_basis *basis = &maps->basis;
  const int count = basis->count;
  float *vis = maps->vis.pixels ? maps->vis.pixels + t * (size_t)(1 + count) : NULL;
  if ((m & MARK_VIS) && vis)
    bb__trace_texel(job->rs, k->order, (const float *const *)k->horizons, t, vis);
  const float *n = k->normals.pixels ? k->normals.pixels + 3 * t : NULL;
  const float grey = k->grey.pixels ? k->grey.pixels[t] : 0.0f;
  if (maps->normal.pixels && (m & MARK_NORMAL)) {
    float *out = maps->normal.pixels + 3 * t;
    memcpy(out, n, 3 * sizeof(float));
    if (o->normal_y_up)
      out[1] *= -1.0f; /* bb__image_flip_green */
  }
  if (maps->weights.pixels && (m & (MARK_NORMAL | MARK_BRIGHTNESS))) {
    float *out = maps->weights.pixels + (size_t)count * t, w[BB_MAX_BASIS];
    bb__derive_texel_weights(basis, n, w);
    if (k->grey.pixels)
      bb__derive_texel_brightness(w, count, grey, out);
    else
      memcpy(out, w, (size_t)count * sizeof(float));
  }
  if ((maps->ssbump.pixels || maps->bent.pixels) && vis &&
      (m & (MARK_VIS | MARK_NORMAL | MARK_BRIGHTNESS))) {
    float raw[BB_MAX_BASIS];
    bb__derive_texel_ssbump(basis, n, vis, raw);
    if (maps->bent.pixels && (m & (MARK_VIS | MARK_NORMAL))) {
      float *out = maps->bent.pixels + 3 * t;
      bb__derive_texel_bent(basis, raw, out);
      if (o->normal_y_up)
        out[1] *= -1.0f;
    }
    if (maps->ssbump.pixels) {
      float *out = maps->ssbump.pixels + (size_t)count * t;
      if (k->grey.pixels)
        bb__derive_texel_brightness(raw, count, grey, out);
      else
        memcpy(out, raw, (size_t)count * sizeof(float));
    }
  }
  if (maps->ao.pixels && vis && (m & MARK_VIS))
    maps->ao.pixels[t] = vis[0];
}

static void derive_row(void *user, int y) {
  const derive_job *job = user;
  const size_t first = (size_t)y * (size_t)job->k->width;
  unsigned char *mark = job->k->mark + first;
  for (int x = 0; x < job->k->width; x++)
    if (mark[x]) {
      derive_texel(job, first + (size_t)x, mark[x]);
      mark[x] = 0;
    }
}

/* Marks every texel of r with m. */
static void mark_rect(bb__kept *k, const rect *r, unsigned char m) {
  for (int j = 0; j < r->height; j++)
    for (int i = 0; i < r->width; i++)
      k->mark[rect_texel(r, i, j, k->width, k->height)] |= m;
}

/* The normals of the texels of r again (rows of them at a time, through
 * bb__normals_rows), marked. */
static bb_status normals_again(bb__kept *k, const rect *r, bb_error *err) {
  const int w = k->width, h = k->height;
  float *rows = malloc((size_t)r->height * (size_t)w * 3 * sizeof(float) + 1);
  if (!rows)
    return bb__fail(err, BB_ERR_MEMORY, "bake: out of memory");
  /* the rows of r, as at most two runs inside the image */
  const int y1 = r->y0 + r->height;
  const int runs = y1 > h ? 2 : 1;
  const int from[2] = {r->y0, 0}, to[2] = {y1 > h ? h : y1, y1 - h};
  for (int q = 0; q < runs; q++) {
    const int first_row = from[q] == r->y0 ? 0 : h - r->y0;
    bb__normals_rows(&k->filtered, k->o.height_scale, k->o.normal_filter,
                     k->o.smooth.addressing, from[q], to[q],
                     rows + (size_t)first_row * (size_t)w * 3);
  }
  for (int j = 0; j < r->height; j++)
    for (int i = 0; i < r->width; i++) {
      const size_t t = rect_texel(r, i, j, w, h);
      memcpy(k->normals.pixels + 3 * t,
             rows + 3 * ((size_t)j * (size_t)w + t % (size_t)w), 3 * sizeof(float));
      k->mark[t] |= MARK_NORMAL;
    }
  free(rows);
  return BB_OK;
}

/* The changed heights' z into the pyramid, and the trace again. */
static bb_status trace_again(bb__kept *k, const rect *rf, const bb_rayset *rs,
                             int threads, const bb_bake_options *o, double *found,
                             bb_error *err) {
  const int w = k->width, h = k->height;
  bb_pyramid *p = k->pyramid;
  float old_min = FLT_MAX;
  float *old_z = malloc((size_t)rf->width * (size_t)rf->height * sizeof(float));
  if (!old_z)
    return bb__fail(err, BB_ERR_MEMORY, "bake: out of memory");
  for (int j = 0; j < rf->height; j++)
    for (int i = 0; i < rf->width; i++) {
      const size_t t = rect_texel(rf, i, j, w, h);
      old_z[(size_t)j * (size_t)rf->width + (size_t)i] = p->z[t];
      if (p->z[t] < old_min)
        old_min = p->z[t];
      p->z[t] =
          o->height_scale * k->filtered.pixels[t]; /* as the whole bake scales them */
    }
  bb_status st = bb__pyramid_update(p, rf->x0, rf->y0, rf->width, rf->height, old_min);
  if (st != BB_OK) {
    free(old_z);
    return st;
  }
  bb__retrace rt = {.p = p,
                    .rs = rs,
                    .horizons = k->horizons,
                    .order = k->order,
                    .bias = o->trace.bias_texels,
                    .threads = threads,
                    .x0 = rf->x0,
                    .y0 = rf->y0,
                    .width = rf->width,
                    .height = rf->height,
                    .old_z = old_z,
                    .dirty = k->mark,
                    .progress = o->trace.progress,
                    .progress_user = o->trace.progress_user};
  st = bb__retrace_run(&rt, err);
  *found = rt.horizons_found;
  free(old_z);
  return st;
}

/* Bakes o again where height differs (within rh) from the kept height:
 * k's maps become those of a whole bake of height. On failure k is left
 * half made: the caller lets it go. */
static bb_status bake_edit(bb_bake_context *context, bb__kept *k, const bb_image *height,
                           const bb_bake_options *o, const rect *rh, int threads,
                           bb_bake_result *r, bb_error *err) {
  const int w = k->width, h = k->height,
            periodic = o->smooth.addressing == BB_ADDRESS_PERIODIC;
  double t0 = bb__now_seconds();
  for (int j = 0; j < rh->height; j++)
    for (int i = 0; i < rh->width; i++) {
      const size_t t = rect_texel(rh, i, j, w, h);
      k->height_in.pixels[t] = height->pixels[t];
    }
  /* the smoothing around the change, and where it changed */
  const rect rs = widen(rh, bb__smooth_reach(o->smooth.radius_texels), w, h, periodic);
  float *old = save_rect(&k->filtered, &rs);
  if (!old)
    return bb__fail(err, BB_ERR_MEMORY, "bake: out of memory");
  bb_status st = bb__smooth_region(&k->height_in, &k->height_in, &o->smooth, rs.x0, rs.y0,
                                   rs.width, rs.height, threads, &k->filtered, err);
  rect rf = {0, 0, 0, 0};
  if (st == BB_OK)
    st = changed_rect(&k->filtered, old, &rs, periodic, &rf, err);
  free(old);
  if (st != BB_OK)
    return st;
  if (!rect_empty(&rf)) {
    /* rf's runs are of the image's columns and rows, within rs */
    mark_rect(k, &rf, MARK_FILTERED);
  }
  double t1 = bb__now_seconds();
  r->seconds_smooth = t1 - t0;
  bb_rayset rays = {0};
  int owned = 0;
  if (traced(o)) {
    st = bb__context_rayset(context, o->slices, o->power, &o->basis, threads, &rays,
                            &owned, err);
    if (st == BB_OK && !rect_empty(&rf))
      st = trace_again(k, &rf, &rays, threads, o, &r->horizons_found, err);
  }
  double t2 = bb__now_seconds();
  r->seconds_trace = t2 - t1;
  const rect rn = widen(&rf, NORMAL_REACH, w, h, periodic);
  if (st == BB_OK && k->normals.pixels && !rect_empty(&rn))
    st = normals_again(k, &rn, err);
  /* the changed rectangle: every texel marked */
  unsigned char *cols = st == BB_OK ? calloc((size_t)w + (size_t)h, 1) : NULL;
  if (st == BB_OK && !cols)
    st = bb__fail(err, BB_ERR_MEMORY, "bake: out of memory");
  if (st == BB_OK) {
    unsigned char *rows = cols + w;
    for (int y = 0; y < h; y++) {
      const unsigned char *m = k->mark + (size_t)y * (size_t)w;
      for (int x = 0; x < w; x++)
        if (m[x])
          cols[x] = 1, rows[y] = 1;
    }
    rect c;
    span_of(cols, w, periodic, &c.x0, &c.width);
    span_of(rows, h, periodic, &c.y0, &c.height);
    if (c.x0 + c.width > w)
      c.x0 = 0, c.width = w;
    if (c.y0 + c.height > h)
      c.y0 = 0, c.height = h;
    k->changed = rect_empty(&c) ? (bb_region){0, 0, 0, 0}
                                : (bb_region){c.x0, c.y0, c.width, c.height};
    derive_job job = {k, traced(o) ? &rays : NULL};
    st = bb__parallel_for(h, threads, derive_row, &job, NULL, NULL, err);
  }
  free(cols);
  if (owned)
    bb__rayset_release(&rays);
  r->seconds_derive = bb__now_seconds() - t2;
  r->threads = threads;
  return st;
}

/* The height's and brightness's texels that differ from the kept ones:
 * the height's as a rectangle, the brightness's marked. */
static bb_status what_changed(bb__kept *k, const bb_image *height,
                              const bb_bake_options *o, rect *rh, int *brightness_changed,
                              bb_error *err) {
  const rect all = {0, 0, k->width, k->height};
  const int periodic = o->smooth.addressing == BB_ADDRESS_PERIODIC;
  bb_status st = changed_rect(&k->height_in, height->pixels, &all, periodic, rh, err);
  *brightness_changed = 0;
  if (st != BB_OK || !o->brightness)
    return st;
  bb_image grey;
  st = bb__image_grey(o->brightness, k->width, k->height, "bake: the brightness map",
                      &grey, err);
  if (st != BB_OK)
    return st;
  const size_t n = (size_t)k->width * (size_t)k->height;
  for (size_t i = 0; i < n; i++)
    if (memcmp(&grey.pixels[i], &k->grey.pixels[i], sizeof(float)) != 0) {
      k->mark[i] |= MARK_BRIGHTNESS;
      *brightness_changed = 1;
    }
  bb_image_free(&k->grey);
  k->grey = grey;
  return BB_OK;
}

/* Is every texel of r one bb__check_scaled_height passes? */
static int scaled_ok(const bb_image *height, const rect *r, float height_scale) {
  for (int j = 0; j < r->height; j++)
    for (int i = 0; i < r->width; i++) {
      const double z =
          (double)height_scale *
          (double)height->pixels[rect_texel(r, i, j, height->width, height->height)];
      if (!(fabs(z) <= BB_MAX_HEIGHT_TEXELS))
        return 0;
    }
  return 1;
}

/* Can the kept bake be baked again for height with o, edit by edit? */
static int can_edit(const bb__kept *k, const bb_image *height, const bb_bake_options *o) {
  return k && height->width == k->width && height->height == k->height &&
         same_options(k, o) &&
         (!o->brightness ||
          (o->brightness->width == k->width && o->brightness->height == k->height));
}

/* A whole bake that keeps nothing (the context's ray set still serves). */
static bb_status bake_plain(bb_bake_context *context, const bb_image *height,
                            const bb_bake_options *o, unsigned flags, bb_bake_result *r,
                            bb_region *changed, bb_error *err) {
  bb_status st = bb__bake_keeping(height, o, context, NULL, r, err);
  if (st == BB_OK) { /* bb__bake_keeping drops nothing: drop what bb__bake would */
    if (!wants(o, BB_MAP_BIT(BB_MAP_FILTERED)))
      bb_image_free(&r->filtered);
    if (flags & BB__BAKE_DROP_VIS)
      bb_image_free(&r->vis);
    *changed = (bb_region){0, 0, height->width, height->height};
  }
  return st;
}

/* bb__context_bake; changed is not NULL. */
static bb_status context_bake(bb_bake_context *context, const bb_image *height,
                              const bb_bake_options *o, unsigned flags, bb_bake_result *r,
                              bb_region *changed, bb_error *err) {
  memset(r, 0, sizeof *r);
  bb__kept *k = bb__context_kept(context);
  const int keepable = o->bounce_albedo <= 0.0 && !o->trace.trace;
  bb_status st = BB_OK;
  if (!height || !height->pixels || height->channels != 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: need a 1-channel height field");
  if (k && keepable && can_edit(k, height, o)) {
    /* a checkpoint before anything kept is touched */
    if (o->trace.progress && o->trace.progress(o->trace.progress_user, 0, 0))
      return bb__fail(err, BB_ERR_CANCELLED, "bake: cancelled by the progress callback");
    rect rh;
    int brightness_changed = 0;
    st = what_changed(k, height, o, &rh, &brightness_changed, err);
    if (st != BB_OK) { /* (a brightness the whole bake refuses as well) */
      bb__context_hold(context, NULL, NULL);
      return st;
    }
    /* a height the whole bake refuses can only be so at a changed texel
     * (the rest is the kept one's): the whole bake says so, in its words */
    const double share =
        (double)rh.width * (double)rh.height / ((double)k->width * (double)k->height);
    if (scaled_ok(height, &rh, o->height_scale) && share <= WHOLE_SHARE) {
      const int threads = bb__thread_count(o->trace.threads);
      st = bake_edit(context, k, height, o, &rh, threads, r, err);
      if (st == BB_OK)
        st = copy_out(k, flags, r, err);
      if (st == BB_OK) {
        k->last_local = 1;
        *changed = k->changed;
        return BB_OK;
      }
      /* half made: let it go */
      bb_bake_result_free(r);
      bb__context_hold(context, NULL, NULL);
      if (st == BB_ERR_CANCELLED)
        bb__fail(err, st, "bake: cancelled by the progress callback");
      return st;
    }
  }
  /* whole: the kept bake (if any) goes first, its memory with it */
  bb__context_hold(context, NULL, NULL);
  if (!keepable)
    return bake_plain(context, height, o, flags, r, changed, err);
  /* what is kept, and the maps the caller gets as copies of the kept ones:
   * when the machine cannot hold them, a plain bake keeps nothing */
  double maps = 0.0;
  const double bake = bb__bake_memory(height->width, height->height, o, 0, 0.0, &maps);
  if (bb__memory_check(bake + kept_bytes(height->width, height->height, o) + maps, "bake",
                       NULL) != BB_OK)
    return bake_plain(context, height, o, flags, r, changed, err);
  st = bake_whole(context, height, o, &k, r, err);
  if (st == BB_ERR_MEMORY) { /* the estimate fell short: as above */
    bb_bake_result_free(r);
    return bake_plain(context, height, o, flags, r, changed, err);
  }
  if (st == BB_OK)
    st = copy_out(k, flags, r, err);
  if (st != BB_OK) {
    bb_bake_result_free(r);
    kept_free(k);
    return st;
  }
  k->last_local = 0;
  bb__context_hold(context, k, kept_free);
  *changed = (bb_region){0, 0, height->width, height->height};
  return BB_OK;
}

bb_status bb__context_bake(bb_bake_context *context, const bb_image *height,
                           const bb_bake_options *o, unsigned flags, bb_bake_result *r,
                           bb_region *changed, bb_error *err) {
  bb_region got = {0, 0, 0, 0};
  const bb_status st = context_bake(context, height, o, flags, r, &got, err);
  if (st == BB_OK) {
    bb__context_set_changed(context, got);
    if (changed)
      *changed = got;
  }
  return st;
}

int bb__context_last_local(const bb_bake_context *context) {
  const bb__kept *k = bb__context_kept(context);
  return k && k->last_local;
}

bb_status bb__bake_through(bb_bake_context *context, bb_image *height,
                           const bb_bake_options *o, unsigned flags, bb_bake_result *r,
                           bb_error *err) {
  if (!bb__context_keeps(context))
    return bb__bake(height, o, flags, context, r, err);
  const bb_status st = bb__context_bake(context, height, o, flags, r, NULL, err);
  if (flags & BB__BAKE_TAKE_HEIGHT)
    bb_image_free(height);
  return st;
}

bb_status bb__bake_context_bake(bb_bake_context *context, const bb_image *height,
                               const bb_bake_options *o, bb_bake_result *result,
                               bb_region *changed, bb_error *err) {
  if (result)
    memset(result, 0, sizeof *result);
  if (changed)
    *changed = (bb_region){0, 0, 0, 0};
  if (!context || !result)
    return bb__fail(err, BB_ERR_ARGUMENT, "bake: missing context or result");
  bb_bake_options prepared;
  bb_status st = bb__bake_prepare(o, &prepared, err);
  if (st != BB_OK)
    return st;
  if (!bb__context_keeps(context)) {
    st = bb__bake((bb_image *)height, &prepared, 0, context, result, err);
    if (st == BB_OK && changed && height)
      *changed = (bb_region){0, 0, height->width, height->height};
    return st;
  }
  return bb__context_bake(context, height, &prepared, 0, result, changed, err);
}
