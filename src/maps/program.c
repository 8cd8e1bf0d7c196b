/* program.c: evaluating a DOOM 3 image program (program_internal.h's tree)
 * the way id Tech 4's Image_program.cpp does, in float instead of bytes.
 *
 * Every intermediate image is RGBA in [0, 1], v standing for id's byte / 255;
 * normal-map operations decode N = (255 v - 128) / 127 and encode
 * v = (127 N + 128) / 255, id's own pair (R_AddNormalMaps decodes with 127,
 * R_HeightmapToNormalMap encodes with 127 + 128). Where id relies on power of
 * two sizes (x & (width - 1)), this code wraps with a modulo, which is the
 * same for those sizes and tiles any other size too. */

#define _XOPEN_SOURCE 700 /* realpath */

#include "core/internal.h"
#include "maps/maps_internal.h"
#include "maps/program_internal.h"
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void bb__program_options_init(bb__program_options *o) {
  memset(o, 0, sizeof *o);
}

/* One value of the program: an RGBA image and whether id would mark it a
 * normal map (TD_BUMP). */
typedef struct value {
  bb_image img;
  int is_normal;
} value;

typedef struct evaluator {
  const bb__program_options *o;
  bb_error *err;
} evaluator;

static double decode_n(float v) {
  return (255.0 * (double)v - 128.0) / 127.0;
}

static float encode_n(double n) {
  return (float)((127.0 * n + 128.0) / 255.0);
}

static float clamp01(double v) {
  return (float)(v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v));
}

static size_t texel_count(const bb_image *img) {
  return (size_t)img->width * (size_t)img->height;
}

/* ------------------------------------------------------------------ leaves */

/* RGBA from a file's channels: grey -> R = G = B, no alpha -> A = 1; values
 * clamped to [0, 1], the range of id's bytes. */
static bb_status to_rgba(const bb_image *in, int alpha_channel, bb_image *out,
                         bb_error *err) {
  bb_status st = bb_image_alloc(out, in->width, in->height, 4, err);
  if (st != BB_OK)
    return st;
  const int ch = in->channels;
  const int grey = ch < 3;
  int alpha = alpha_channel; /* the file's own, else grey + alpha or RGBA's last */
  if (alpha < 0)
    alpha = ch == 2 ? 1 : (ch >= 4 ? 3 : -1);
  const size_t n = texel_count(in);
  for (size_t i = 0; i < n; i++) {
    const float *t = in->pixels + i * (size_t)ch;
    float *o = out->pixels + 4 * i;
    for (int c = 0; c < 3; c++)
      o[c] = clamp01(t[grey ? 0 : c]);
    o[3] = alpha >= 0 ? clamp01(t[alpha]) : 1.0f;
  }
  return BB_OK;
}

int bb__program_image_path(const char *base_dir, const char *name, char *out, size_t cap) {
  if (!name)
    name = "";
  if (base_dir && *base_dir && name[0] != '/')
    return snprintf(out, cap, "%s/%s", base_dir, name);
  return snprintf(out, cap, "%s", name);
}

/* A program's images are untrusted text (a material from a mod): unless
 * allowed, an image must resolve to a file inside the base directory. A
 * name that resolves to nothing is left to the read, which says so. */
static bb_status check_inside_base(const bb__program_options *o, const char *name,
                                   const char *path, bb_error *err) {
  if (o->allow_outside_base)
    return BB_OK;
  if (name[0] == '/')
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%.200s: an absolute path; image names are relative to the base directory",
                    name);
  char base[PATH_MAX], file[PATH_MAX];
  if (!realpath(o->base_dir && *o->base_dir ? o->base_dir : ".", base) || !realpath(path, file))
    return BB_OK;
  const size_t n = strlen(base);
  const int inside =
      strncmp(file, base, n) == 0 && (file[n] == '/' || (n == 1 && base[0] == '/'));
  if (!inside)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%.200s: resolves to %.200s, outside the base directory %.200s", name, file,
                    base);
  return BB_OK;
}

static bb_status load_image(evaluator *ev, const prog_node *n, value *out) {
  const bb__program_options *o = ev->o;
  char path[4096];
  int len = bb__program_image_path(o->base_dir, n->name, path, sizeof path);
  /* A cut path would name another file (even an existing one). */
  if (len < 0 || (size_t)len >= sizeof path)
    return bb__fail(ev->err, BB_ERR_ARGUMENT,
                    "%.64s: path too long (%d bytes, at most %zu)", n->name, len,
                    sizeof path - 1);
  bb_status inside = check_inside_base(o, n->name, path, ev->err);
  if (inside != BB_OK)
    return inside;
  bb_image raw = {0};
  bb_image_info info;
  memset(&info, 0, sizeof info);
  info.alpha_channel = -1;
  bb_status st = o->loader ? o->loader(o->loader_user, path, &raw, &info, ev->err)
                           : bb_image_read(path, &raw, &info, ev->err);
  if (st != BB_OK)
    return st;
  bb_error local;
  st = bb__check_finite(&raw, raw.channels, path, ev->err);
  if (st == BB_OK) {
    st = to_rgba(&raw, info.alpha_channel < raw.channels ? info.alpha_channel : -1,
                 &out->img, &local);
    if (st != BB_OK)
      bb__fail(ev->err, st, "%s: %s", path, local.message);
  }
  bb_image_free(&raw);
  bb_image_info_free(&info);
  out->is_normal = 0;
  return st;
}

/* id's R_FlatNormalImage: 2 x 2 texels of (128, 128, 255, 255). */
static bb_status make_flat(evaluator *ev, value *out) {
  bb_status st = bb_image_alloc(&out->img, 2, 2, 4, ev->err);
  if (st != BB_OK)
    return st;
  for (size_t i = 0; i < 4; i++) {
    float *o = out->img.pixels + 4 * i;
    o[0] = o[1] = encode_n(0.0);
    o[2] = o[3] = 1.0f;
  }
  out->is_normal = 1;
  return BB_OK;
}

/* ---------------------------------------------------------- resampling */

/* id's R_Dropsample: nearest texels, row (i + 0.25) h_in / h_out, column
 * j w_in / w_out, so a second operand takes the first one's size. */
static bb_status dropsample(const bb_image *in, int width, int height, bb_image *out,
                            bb_error *err) {
  bb_status st = bb_image_alloc(out, width, height, 4, err);
  if (st != BB_OK)
    return st;
  for (int i = 0; i < height; i++) {
    int row = (int)(((double)i + 0.25) * in->height / height);
    for (int j = 0; j < width; j++) {
      int col = (int)((long long)j * in->width / width);
      memcpy(bb_image_texel(out, j, i), bb_image_texel(in, col, row), 4 * sizeof(float));
    }
  }
  return BB_OK;
}

/* Makes b the size of a (in place), as id does before combining two images. */
static bb_status match_size(const value *a, value *b, bb_error *err) {
  if (a->img.width == b->img.width && a->img.height == b->img.height)
    return BB_OK;
  bb_image resized;
  bb_status st = dropsample(&b->img, a->img.width, a->img.height, &resized, err);
  if (st != BB_OK)
    return st;
  bb_image_free(&b->img);
  b->img = resized;
  return BB_OK;
}

/* ------------------------------------------------------ normal-map ops */

/* id's R_HeightmapToNormalMap. depth d = (R + G + B) / 3 in byte units; per
 * texel, with s = scale / 256 and d1 = d(x, y), d2 = d(x+1, y),
 * d3 = d(x, y+1), d4 = d(x+1, y+1):
 *   n1 = normalize(-(d2 - d1) s, -(d3 - d1) s, 1)
 *   n2 = normalize(-(d4 - d3) s, (d1 - d3) s, 1)
 *   N  = normalize(n1 + n2), alpha = 1. */
static bb_status heightmap(evaluator *ev, value *v, double scale) {
  bb_image *img = &v->img;
  const int w = img->width, h = img->height;
  double *depth = malloc(texel_count(img) * sizeof *depth);
  if (!depth)
    return bb__fail(ev->err, BB_ERR_MEMORY, "heightmap: out of memory");
  for (size_t i = 0; i < texel_count(img); i++) {
    const float *t = img->pixels + 4 * i;
    depth[i] = 255.0 * ((double)t[0] + (double)t[1] + (double)t[2]) / 3.0;
  }
  const double s = scale / 256.0;
  for (int y = 0; y < h; y++) {
    const int y1 = (y + 1) % h;
    for (int x = 0; x < w; x++) {
      const int x1 = (x + 1) % w;
      double d1 = depth[(size_t)y * (size_t)w + (size_t)x];
      double d2 = depth[(size_t)y * (size_t)w + (size_t)x1];
      double d3 = depth[(size_t)y1 * (size_t)w + (size_t)x];
      double d4 = depth[(size_t)y1 * (size_t)w + (size_t)x1];
      double n1[3] = {-(d2 - d1) * s, -(d3 - d1) * s, 1.0};
      double n2[3] = {-(d4 - d3) * s, (d1 - d3) * s, 1.0};
      bb__normalize3(n1);
      bb__normalize3(n2);
      double n[3] = {n1[0] + n2[0], n1[1] + n2[1], n1[2] + n2[2]};
      bb__normalize3(n);
      float *o = bb_image_texel(img, x, y);
      for (int k = 0; k < 3; k++)
        o[k] = encode_n(n[k]);
      o[3] = 1.0f;
    }
  }
  free(depth);
  v->is_normal = 1;
  return BB_OK;
}

/* id's R_AddNormalMaps: a's normal (z rebuilt when short) plus b's x and y,
 * renormalised; alpha = 1. */
static void addnormals(value *a, const value *b) {
  const size_t n = texel_count(&a->img);
  for (size_t i = 0; i < n; i++) {
    float *o = a->img.pixels + 4 * i;
    const float *t = b->img.pixels + 4 * i;
    double base[3] = {decode_n(o[0]), decode_n(o[1]), decode_n(o[2])}, sum[3];
    bb__add_normals(base, decode_n(t[0]), decode_n(t[1]), sum);
    for (int k = 0; k < 3; k++)
      o[k] = encode_n(sum[k]);
    o[3] = 1.0f;
  }
  a->is_normal = 1;
}

/* A texel id's R_SmoothNormalMap leaves out: bytes (0, 0, 0) or
 * (128, 128, 128). */
static int smooth_skips(const float *t) {
  int zero = 1, mid = 1;
  for (int k = 0; k < 3; k++) {
    double code = 255.0 * (double)t[k];
    zero = zero && fabs(code) < 0.5;
    mid = mid && fabs(code - 128.0) < 0.5;
  }
  return zero || mid;
}

/* id's R_SmoothNormalMap: the sum of (byte - 128) over the 3 x 3 texels
 * around (wrapping), skipped texels left out, normalised; alpha is kept. A
 * texel whose nine neighbours are all skipped becomes flat (id normalises a
 * zero vector there). */
static bb_status smoothnormals(evaluator *ev, value *v) {
  bb_image orig;
  bb_status st = bb_image_alloc(&orig, v->img.width, v->img.height, 4, ev->err);
  if (st != BB_OK)
    return st;
  memcpy(orig.pixels, v->img.pixels, texel_count(&orig) * 4 * sizeof(float));
  const int w = orig.width, h = orig.height;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      double n[3] = {0.0, 0.0, 0.0};
      for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
          const float *t =
              bb_image_texel(&orig, bb__wrap(x + dx, w), bb__wrap(y + dy, h));
          if (smooth_skips(t))
            continue;
          for (int k = 0; k < 3; k++)
            n[k] += 255.0 * (double)t[k] - 128.0;
        }
      bb__normalize3(n);
      float *o = bb_image_texel(&v->img, x, y);
      for (int k = 0; k < 3; k++)
        o[k] = encode_n(n[k]);
    }
  bb_image_free(&orig);
  v->is_normal = 1;
  return BB_OK;
}

/* ------------------------------------------------------- colour ops */

/* id's R_ImageAdd: per channel, clamped at 255. */
static void add(value *a, const value *b) {
  const size_t n = 4 * texel_count(&a->img);
  for (size_t i = 0; i < n; i++)
    a->img.pixels[i] = clamp01((double)a->img.pixels[i] + (double)b->img.pixels[i]);
  a->is_normal = a->is_normal || b->is_normal;
}

/* id's R_ImageScale: channel c times factor c, clamped to 0..255. (id casts
 * to a byte before its clamp, so a product over 255 wraps around in the
 * engine; this clamps, as the code's clamp intends.) */
static void scale(value *v, const double factors[4]) {
  const size_t n = texel_count(&v->img);
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < 4; c++) {
      float *p = v->img.pixels + 4 * i + (size_t)c;
      *p = clamp01((double)*p * factors[c]);
    }
}

static void per_texel(value *v, prog_op op) {
  const size_t n = texel_count(&v->img);
  for (size_t i = 0; i < n; i++) {
    float *t = v->img.pixels + 4 * i;
    switch (op) {
    case PROG_INVERT_ALPHA: /* id's R_InvertAlpha */
      t[3] = 1.0f - t[3];
      break;
    case PROG_INVERT_COLOR: /* id's R_InvertColor */
      for (int c = 0; c < 3; c++)
        t[c] = 1.0f - t[c];
      break;
    case PROG_MAKE_INTENSITY: /* red copied to green, blue and alpha */
      t[1] = t[2] = t[3] = t[0];
      break;
    case PROG_MAKE_ALPHA: /* mean of R, G, B into alpha, then RGB white */
      t[3] = (float)(((double)t[0] + (double)t[1] + (double)t[2]) / 3.0);
      t[0] = t[1] = t[2] = 1.0f;
      break;
    default:
      break;
    }
  }
}

/* ------------------------------------------------------------- evaluation */

static bb_status eval(evaluator *ev, const prog_node *n, value *out);

/* Evaluates both operands of n, the second resized to the first. */
static bb_status eval_pair(evaluator *ev, const prog_node *n, value *a, value *b) {
  bb_status st = eval(ev, n->args[0], a);
  if (st == BB_OK)
    st = eval(ev, n->args[1], b);
  if (st == BB_OK)
    st = match_size(a, b, ev->err);
  if (st != BB_OK) {
    bb_image_free(&a->img);
    bb_image_free(&b->img);
  }
  return st;
}

static bb_status eval_binary(evaluator *ev, const prog_node *n, value *out) {
  value b = {{0}, 0};
  bb_status st = eval_pair(ev, n, out, &b);
  if (st != BB_OK)
    return st;
  if (n->op == PROG_ADDNORMALS)
    addnormals(out, &b);
  else
    add(out, &b);
  bb_image_free(&b.img);
  return BB_OK;
}

static bb_status eval(evaluator *ev, const prog_node *n, value *out) {
  memset(out, 0, sizeof *out);
  switch (n->op) {
  case PROG_IMAGE:
    return load_image(ev, n, out);
  case PROG_FLAT:
    return make_flat(ev, out);
  case PROG_ADDNORMALS:
  case PROG_ADD:
    return eval_binary(ev, n, out);
  default:
    break;
  }
  bb_status st = eval(ev, n->args[0], out);
  if (st != BB_OK)
    return st;
  if (n->op == PROG_HEIGHTMAP)
    st = heightmap(ev, out, n->numbers[0]);
  else if (n->op == PROG_SMOOTHNORMALS)
    st = smoothnormals(ev, out);
  else if (n->op == PROG_SCALE)
    scale(out, n->numbers);
  else
    per_texel(out, n->op);
  if (st != BB_OK)
    bb_image_free(&out->img);
  return st;
}

/* The normals a normal-map result holds, decoded with id's mapping. */
static bb_status decode_result(const bb_image *rgba, bb_image *out, bb_error *err) {
  bb_status st = bb_image_alloc(out, rgba->width, rgba->height, 3, err);
  if (st != BB_OK)
    return st;
  const size_t n = texel_count(rgba);
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++)
      out->pixels[3 * i + (size_t)k] = (float)decode_n(rgba->pixels[4 * i + (size_t)k]);
  return BB_OK;
}

bb_status bb__program_run(const bb__program *program, const bb__program_options *o,
                         bb_image *out, int *is_normal_map, bb_error *err) {
  if (!out || !is_normal_map)
    return bb__fail(err, BB_ERR_ARGUMENT, "program: out and is_normal_map are required");
  memset(out, 0, sizeof *out);
  *is_normal_map = 0;
  if (!program || !program->root)
    return bb__fail(err, BB_ERR_ARGUMENT, "program: no program");
  bb__program_options defaults;
  bb__program_options_init(&defaults);
  evaluator ev = {o ? o : &defaults, err};
  value v;
  bb_status st = eval(&ev, program->root, &v);
  if (st != BB_OK)
    return st;
  if (v.is_normal) {
    st = decode_result(&v.img, out, err);
    bb_image_free(&v.img);
    *is_normal_map = st == BB_OK;
    return st;
  }
  *out = v.img;
  return BB_OK;
}
