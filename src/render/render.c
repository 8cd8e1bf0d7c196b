/* render.c: the baked maps lit as the paper's "Rendering" section and
 * Source's shaders light them (static lightmaps, a dynamic light with
 * self-shadowing, Blinn-Phong specular from the bent normal).
 *
 * Each mode turns one texel's maps into three terms: the weights w_c that
 * multiply the lightmap colours L_c, the factor that multiplies the dynamic
 * light's colour, and the normal the specular highlight uses. Everything
 * else (albedo, colours, specular, tiling) is shared, so a new mode is one
 * function and one row of `modes` below.
 */

#include "trace/basis.h"
#include "core/internal.h"
#include "render/render_internal.h"
#include "maps/maps_internal.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ----------------------------------------------------------------- modes */

enum {
  NEEDS_NORMAL = BB_RENDER_NEEDS_NORMAL,
  NEEDS_SSBUMP = BB_RENDER_NEEDS_SSBUMP,
  NEEDS_AO = BB_RENDER_NEEDS_AO,
  NEEDS_SLOPE = BB_RENDER_NEEDS_SLOPE
};

/* One texel's inputs; pointers are NULL for maps the mode does not read. */
typedef struct texel_maps {
  const float *normal, *ssbump, *ao, *bent, *slope;
} texel_maps;

/* What a mode makes of one texel. */
typedef struct shade_terms {
  double lightmap_weight[3]; /* w_c: static light = sum_c w_c L_c */
  double dynamic;            /* the dynamic light's colour is multiplied by this */
  double specular_normal[3]; /* unit normal for the highlight */
} shade_terms;

/* Light and basis, computed once per render. */
typedef struct shade_setup {
  double basis[3][3];
  double light[3];       /* l, towards the dynamic light */
  double light_basis[3]; /* l.B_c */
  float slope_table[256]; /* flipcode's table for l (bb__slope_table) */
} shade_setup;

typedef void (*shade_fn)(const shade_setup *s, const texel_maps *t, shade_terms *out);

static double dot3d(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double dot3f(const float n[3], const double b[3]) {
  return (double)n[0] * b[0] + (double)n[1] * b[1] + (double)n[2] * b[2];
}

static double saturate(double v) {
  return v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0;
}

static void copy3f(const float *v, double out[3]) {
  for (int k = 0; k < 3; k++)
    out[k] = (double)v[k];
}

/* Source's static weights for a normal map (lightmappedgeneric_ps2_3_x.h):
 * dp_c = sat(N.B_c)^2, divided by their sum, which is the weights map. A
 * normal facing away from all three gets 1/3 each, as derive.c's weights. */
static void source_weights(const shade_setup *s, const float *n, double w[3]) {
  double sum = 0.0;
  for (int c = 0; c < 3; c++) {
    double d = saturate(dot3f(n, s->basis[c]));
    w[c] = d * d;
    sum += w[c];
  }
  for (int c = 0; c < 3; c++)
    w[c] = sum > 0.0 ? w[c] / sum : 1.0 / 3.0;
}

/* Plain normal mapping: Lambert for the dynamic light, no self-shadowing. */
static void shade_normal(const shade_setup *s, const texel_maps *t, shade_terms *out) {
  source_weights(s, t->normal, out->lightmap_weight);
  double n_dot_l = dot3f(t->normal, s->light);
  out->dynamic = n_dot_l > 0.0 ? n_dot_l : 0.0;
  copy3f(t->normal, out->specular_normal);
}

/* Normal mapping darkened by ambient occlusion, for every light. */
static void shade_normal_ao(const shade_setup *s, const texel_maps *t, shade_terms *out) {
  shade_normal(s, t, out);
  const double ao = (double)t->ao[0];
  for (int c = 0; c < 3; c++)
    out->lightmap_weight[c] *= ao;
  out->dynamic *= ao;
}

/* The ssbump. Static: Source's sum_c s_c L_c. Dynamic: the light projected
 * on the basis, modulated by the stored weights, sat(sum_c s_c (l.B_c)), as
 * Source's ssbump flashlight computes its N.L. Where nothing is occluded
 * (s_c = max(0, N.B_c)) and N lies inside the basis' cone, this is exactly
 * N.l, since the basis is orthonormal; occlusion removes light lobe by lobe. */
static void shade_ssbump(const shade_setup *s, const texel_maps *t, shade_terms *out) {
  double sum = 0.0;
  for (int c = 0; c < 3; c++) {
    out->lightmap_weight[c] = (double)t->ssbump[c];
    sum += (double)t->ssbump[c] * s->light_basis[c];
  }
  out->dynamic = saturate(sum);
  if (t->bent) {
    copy3f(t->bent, out->specular_normal);
    return;
  }
  /* The paper's bent normal, as derive.c's bb__derive_bent_all_cores computes it. */
  double b[3] = {0.0, 0.0, 0.0};
  for (int c = 0; c < 3; c++)
    for (int k = 0; k < 3; k++)
      b[k] += (double)t->ssbump[c] * s->basis[c][k];
  double len = sqrt(dot3d(b, b));
  for (int k = 0; k < 3; k++)
    out->specular_normal[k] = len > 0.0 ? b[k] / len : (k == 2 ? 1.0 : 0.0);
}

/* flipcode's slope map: the byte indexes the 16 x 16 table made for the
 * light (the article's "translation for each of the 256 possible normal
 * vectors"), which is N.l clamped at 0 for the normal the byte's slopes
 * give; that normal also takes Source's static weights and the highlight. */
static void shade_slope(const shade_setup *s, const texel_maps *t, shade_terms *out) {
  double code = 255.0 * (double)t->slope[0] + 0.5;
  int byte = code < 0.0 ? 0 : (code > 255.0 ? 255 : (int)code);
  int dx, dy;
  bb__slope_decode((uint8_t)byte, &dx, &dy);
  double n[3] = {-(double)dx, -(double)dy, 1.0};
  bb__normalize3(n);
  const float nf[3] = {(float)n[0], (float)n[1], (float)n[2]};
  source_weights(s, nf, out->lightmap_weight);
  out->dynamic = (double)s->slope_table[byte];
  copy3f(nf, out->specular_normal);
}

typedef struct mode_info {
  bb_render_mode mode;
  const char *name;
  unsigned needs; /* NEEDS_* */
  shade_fn shade;
} mode_info;

static const mode_info modes[] = {
    {BB_RENDER_SSBUMP, "ssbump", NEEDS_SSBUMP, shade_ssbump},
    {BB_RENDER_NORMAL, "normal", NEEDS_NORMAL, shade_normal},
    {BB_RENDER_NORMAL_AO, "ao", NEEDS_NORMAL | NEEDS_AO, shade_normal_ao},
    {BB_RENDER_SLOPE, "slope", NEEDS_SLOPE, shade_slope},
};

enum { MODE_COUNT = sizeof modes / sizeof modes[0] };

/* The row of mode, or NULL for a value that is not a mode (read as an int:
 * C callers may store anything in an enum field). */
static const mode_info *find_mode(bb_render_mode mode) {
  for (int i = 0; i < MODE_COUNT; i++)
    if ((int)modes[i].mode == (int)mode)
      return &modes[i];
  return NULL;
}

bb_status bb__render_mode_parse(const char *name, bb_render_mode *out, bb_error *err) {
  const char *names[MODE_COUNT];
  for (int i = 0; i < MODE_COUNT; i++)
    names[i] = modes[i].name;
  int i;
  bb_status st = bb__parse_name("render mode", name, names, MODE_COUNT, 0, &i, err);
  if (st == BB_OK)
    *out = modes[i].mode;
  return st;
}

unsigned bb__render_mode_needs(bb_render_mode mode) {
  const mode_info *m = find_mode(mode);
  return m ? m->needs : 0u;
}

const char *bb__render_mode_name(bb_render_mode mode) {
  const mode_info *m = find_mode(mode);
  return m ? m->name : "unknown";
}

/* --------------------------------------------------------------- albedo */

static const char *const albedo_mode_names[] = {"multiply", "mod2x", "ssbump"};

bb_status bb__albedo_mode_parse(const char *name, bb_albedo_mode *out, bb_error *err) {
  int i;
  bb_status st = bb__parse_name("albedo mode", name, albedo_mode_names, 3, 0, &i, err);
  if (st == BB_OK)
    *out = (bb_albedo_mode)i;
  return st;
}

const char *bb__albedo_mode_name(bb_albedo_mode mode) {
  int i = (int)mode;
  return i >= 0 && i < 3 ? albedo_mode_names[i] : "unknown";
}

/* ----------------------------------------------------------------- light */

/* cos and sin of an angle in degrees, exact (0, 1, -1) at multiples of 90
 * degrees, so an overhead light is exactly (0, 0, 1). */
static void cos_sin_degrees(double degrees, double *c, double *s) {
  double turns = fmod(degrees, 360.0);
  if (turns < 0.0)
    turns += 360.0;
  if (turns == 0.0 || turns == 90.0 || turns == 180.0 || turns == 270.0) {
    int quarter = (int)(turns / 90.0);
    static const double cosines[4] = {1.0, 0.0, -1.0, 0.0};
    static const double sines[4] = {0.0, 1.0, 0.0, -1.0};
    *c = cosines[quarter];
    *s = sines[quarter];
    return;
  }
  double radians = turns * (BB__PI / 180.0);
  *c = cos(radians);
  *s = sin(radians);
}

void bb__light_direction(double azimuth_degrees, double elevation_degrees, double dir[3]) {
  double ca, sa, ce, se;
  cos_sin_degrees(azimuth_degrees, &ca, &sa);
  cos_sin_degrees(elevation_degrees, &ce, &se);
  dir[0] = ce * ca;
  dir[1] = -ce * sa; /* azimuth turns counter-clockwise on screen; +y is down */
  dir[2] = se;
}

/* -------------------------------------------------------------- options */

void bb__render_options_init(bb_render_options *o) {
  memset(o, 0, sizeof *o);
  o->mode = BB_RENDER_SSBUMP;
  o->dynamic_light = 1;
  o->light_azimuth = 135.0; /* from the top-left, as GIMP's Bump Map */
  o->light_elevation = 45.0;
  for (int k = 0; k < 3; k++) {
    o->light_color[k] = 1.0f;
    o->lightmap[k][k] = 1.0f; /* L_0 red, L_1 green, L_2 blue */
  }
  o->specular_strength = 1.0;
  o->tile_x = o->tile_y = 1;
  o->view_azimuth = 270.0; /* from the bottom: the surface recedes up the picture */
  o->view_elevation = 30.0;
}

const bb__range bb__range_light_elevation = {"light elevation", 0.0, 90.0, 0, 0};
const bb__range bb__range_view_elevation = {"view elevation", 1.0, 90.0, 0, 0};
const bb__range bb__range_colour = {"colour", 0.0, FLT_MAX, 0, 0};
const bb__range bb__range_specular_exponent = {"specular exponent", 0.0,
                                               BB_MAX_SPECULAR_EXPONENT, 0, 0};
const bb__range bb__range_specular_strength = {"specular strength", 0.0, 1000.0, 0, 0};
const bb__range bb__range_tile = {"tile", 1, 64, 0, 1};

static bb_status in_range(const bb__range *r, double v, bb_error *err) {
  char who[64] = "render: ";
  strncat(who, r->what, sizeof who - strlen(who) - 1);
  return bb__range_check(r, v, who, err);
}

static bb_status check_colour(const char *what, const float *c, bb_error *err) {
  bb_status st = BB_OK;
  for (int k = 0; k < 3 && st == BB_OK; k++)
    st = bb__range_check(&bb__range_colour, (double)c[k], what, err);
  return st;
}

static bb_status check_lights(const bb_render_options *o, bb_error *err) {
  bb_status st = BB_OK;
  if (o->dynamic_light) {
    if (!isfinite(o->light_azimuth))
      return bb__fail(err, BB_ERR_ARGUMENT, "render: light azimuth must be finite");
    st = in_range(&bb__range_light_elevation, o->light_elevation, err);
    if (st == BB_OK)
      st = check_colour("render: light colour", o->light_color, err);
  }
  for (int c = 0; c < 3 && o->static_light && st == BB_OK; c++)
    st = check_colour("render: lightmap colour", o->lightmap[c], err);
  if (st == BB_OK)
    st = in_range(&bb__range_specular_exponent, o->specular_exponent, err);
  if (st == BB_OK)
    st = in_range(&bb__range_specular_strength, o->specular_strength, err);
  return st;
}

static bb_status check_options(const bb_render_options *o, bb_error *err) {
  if (!o)
    return bb__fail(err, BB_ERR_ARGUMENT, "render: options are NULL");
  if (!find_mode(o->mode))
    return bb__fail(err, BB_ERR_ARGUMENT, "render: unknown mode %d", (int)o->mode);
  if ((int)o->albedo_mode < 0 || (int)o->albedo_mode > (int)BB_ALBEDO_SSBUMP)
    return bb__fail(err, BB_ERR_ARGUMENT, "render: unknown albedo mode %d",
                    (int)o->albedo_mode);
  bb_status st = in_range(&bb__range_tile, o->tile_x, err);
  if (st == BB_OK)
    st = in_range(&bb__range_tile, o->tile_y, err);
  if (st != BB_OK)
    return st;
  if (o->crop_width < 0 || (o->crop_width > 0 && o->crop_height <= 0))
    return bb__fail(err, BB_ERR_ARGUMENT, "render: crop size must be > 0 (got %dx%d)",
                    o->crop_width, o->crop_height);
  if ((st = bb__range_check(&bb__range_threads, o->threads, "render: threads", err)) != BB_OK)
    return st;
  if (o->view && !isfinite(o->view_azimuth))
    return bb__fail(err, BB_ERR_ARGUMENT, "render: view azimuth must be finite");
  if (o->view && (st = in_range(&bb__range_view_elevation, o->view_elevation, err)) != BB_OK)
    return st;
  if (o->relief && !o->view)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "render: relief needs a view (seen from straight above it shows nothing)");
  if (o->relief && !(o->relief_depth > 0.0 && o->relief_depth <= BB_MAX_HEIGHT_TEXELS))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "render: relief depth must be > 0 texels: the bake's scale (got %g)",
                    o->relief_depth);
  return check_lights(o, err);
}

/* ----------------------------------------------------------------- maps */

static bb_status check_map(const bb_image *img, const char *what, int min_channels,
                           const bb_image *first, bb_error *err) {
  if (!img || !img->pixels)
    return bb__fail(err, BB_ERR_ARGUMENT, "render: the %s map is missing", what);
  if (img->channels < min_channels)
    return bb__fail(err, BB_ERR_ARGUMENT, "render: the %s map has %d channel%s, needs %d",
                    what, img->channels, img->channels == 1 ? "" : "s", min_channels);
  if (first && (img->width != first->width || img->height != first->height))
    return bb__fail(err, BB_ERR_ARGUMENT, "render: the %s map is %dx%d, the others %dx%d",
                    what, img->width, img->height, first->width, first->height);
  /* NaN or infinite values would light as black or white, silently */
  char name[64];
  snprintf(name, sizeof name, "render: the %s map", what);
  return bb__check_finite(img, min_channels, name, err);
}

/* The maps a mode reads, checked; *size receives the first one. */
static bb_status check_maps(const bb_render_maps *m, unsigned needs,
                            const bb_image **size, bb_error *err) {
  const struct {
    const bb_image *img;
    const char *what;
    int channels, needed;
  } list[] = {
      {m->ssbump, "ssbump", 3, (needs & NEEDS_SSBUMP) != 0},
      {m->normal, "normal", 3, (needs & NEEDS_NORMAL) != 0},
      {m->ao, "ao", 1, (needs & NEEDS_AO) != 0},
      {m->bent, "bent", 3, m->bent != NULL && (needs & NEEDS_SSBUMP)},
      {m->slope, "slope", 1, (needs & NEEDS_SLOPE) != 0},
      {m->albedo, "albedo", 1, m->albedo != NULL},
  };
  const bb_image *first = NULL;
  for (size_t i = 0; i < sizeof list / sizeof list[0]; i++) {
    if (!list[i].needed)
      continue;
    bb_status st = check_map(list[i].img, list[i].what, list[i].channels, first, err);
    if (st == BB_OK && list[i].img == m->ssbump)
      st = bb__check_hl2_map(m->ssbump, NULL, "render: the ssbump map", err);
    if (st != BB_OK)
      return st;
    if (!first)
      first = list[i].img;
  }
  *size = first;
  return BB_OK;
}

/* --------------------------------------------------------------- render */

typedef struct render_job {
  const bb_render_maps *maps;
  const bb_render_options *o;
  const mode_info *mode;
  shade_setup setup;
  /* Lights the specular sums over: the dynamic light, then the basis. */
  int light_count;
  double light_dir[4][3];
  double light_half[4][3]; /* normalize(d + view) */
  float light_color[4][3];
  bb_image *out;
  /* o->view: V towards the viewer, the screen's right R and the way to the
   * viewer D on the plane (2D), 1 / sin(elevation), the picture's size */
  double view[3], right[2], toward[2], stretch;
  int width, height;
} render_job;

static void add_specular_light(render_job *job, const double dir[3],
                               const float color[3]) {
  int i = job->light_count++;
  for (int k = 0; k < 3; k++) {
    job->light_dir[i][k] = dir[k];
    job->light_half[i][k] = dir[k] + job->view[k];
    job->light_color[i][k] = color[k];
  }
  bb__normalize3(job->light_half[i]);
}

static void job_init(render_job *job, const bb_render_maps *maps,
                     const bb_render_options *o, bb_image *out) {
  memset(job, 0, sizeof *job);
  job->maps = maps;
  job->o = o;
  job->mode = find_mode(o->mode);
  job->out = out;
  job->view[2] = 1.0; /* overhead */
  if (o->view) {
    bb__light_direction(o->view_azimuth, o->view_elevation, job->view);
    double horizontal = hypot(job->view[0], job->view[1]);
    if (horizontal > 0.0) {
      job->toward[0] = job->view[0] / horizontal, job->toward[1] = job->view[1] / horizontal;
    } else { /* straight down: the azimuth still turns the picture */
      double d[3];
      bb__light_direction(o->view_azimuth, 0.0, d);
      job->toward[0] = d[0], job->toward[1] = d[1];
    }
    job->right[0] = job->toward[1], job->right[1] = -job->toward[0];
    job->stretch = 1.0 / job->view[2];
  }
  for (int c = 0; c < 3; c++)
    bb__basis_vector(c, job->setup.basis[c]);
  if (o->dynamic_light) {
    bb__light_direction(o->light_azimuth, o->light_elevation, job->setup.light);
    add_specular_light(job, job->setup.light, o->light_color);
  }
  for (int c = 0; c < 3; c++)
    job->setup.light_basis[c] = dot3d(job->setup.light, job->setup.basis[c]);
  bb__slope_table(job->setup.light, job->setup.slope_table);
  if (o->static_light)
    for (int c = 0; c < 3; c++)
      add_specular_light(job, job->setup.basis[c], o->lightmap[c]);
}

static const float *texel_of(const bb_image *img, size_t i) {
  return img ? img->pixels + i * (size_t)img->channels : NULL;
}

/* Blinn-Phong over the job's lights, for the unit normal n. */
static void add_specular(const render_job *job, const double n[3], double rgb[3]) {
  const double k = job->o->specular_exponent, strength = job->o->specular_strength;
  for (int i = 0; i < job->light_count; i++) {
    if (!(dot3d(n, job->light_dir[i]) > 0.0))
      continue; /* the light is behind the surface the highlight is on */
    double n_dot_h = dot3d(n, job->light_half[i]);
    if (!(n_dot_h > 0.0))
      continue;
    double spec = strength * pow(n_dot_h, k);
    for (int c = 0; c < 3; c++)
      rgb[c] += (double)job->light_color[i][c] * spec;
  }
}

/* The albedo factor of texel i by the albedo mode (Source's TextureCombine:
 * mod2x is 2 A per channel; an ssbump detail used as an albedo is the grey
 * dot(A, 2/3)). */
static void albedo_from(const render_job *job, const float *v, double a[3]) {
  const bb_image *albedo = job->maps->albedo;
  if (!albedo) {
    a[0] = a[1] = a[2] = 1.0;
    return;
  }
  for (int c = 0; c < 3; c++)
    a[c] = (double)(albedo->channels >= 3 ? v[c] : v[0]);
  switch (job->o->albedo_mode) {
  case BB_ALBEDO_MOD2X:
    for (int c = 0; c < 3; c++)
      a[c] *= 2.0;
    break;
  case BB_ALBEDO_SSBUMP:
    a[0] = a[1] = a[2] = (2.0 / 3.0) * (a[0] + a[1] + a[2]);
    break;
  case BB_ALBEDO_MULTIPLY:
    break;
  }
}

/* One point's maps (t) and albedo (its values, or NULL) lit into out. */
static void shade_point(const render_job *job, const texel_maps *t, const float *albedo_texel,
                        float *out) {
  shade_terms terms;
  job->mode->shade(&job->setup, t, &terms);

  const bb_render_options *o = job->o;
  double diffuse[3] = {0.0, 0.0, 0.0}, albedo[3], rgb[3] = {0.0, 0.0, 0.0};
  for (int k = 0; k < 3; k++) {
    if (o->static_light)
      for (int c = 0; c < 3; c++)
        diffuse[k] += terms.lightmap_weight[c] * (double)o->lightmap[c][k];
    if (o->dynamic_light)
      diffuse[k] += terms.dynamic * (double)o->light_color[k];
  }
  albedo_from(job, albedo_texel, albedo);
  for (int k = 0; k < 3; k++)
    rgb[k] = albedo[k] * diffuse[k];
  if (o->specular_exponent > 0.0)
    add_specular(job, terms.specular_normal, rgb);
  for (int k = 0; k < 3; k++)
    out[k] = (float)rgb[k];
}

static void shade_texel(const render_job *job, size_t i, float *out) {
  const bb_render_maps *m = job->maps;
  const unsigned needs = job->mode->needs;
  texel_maps t = {
      (needs & NEEDS_NORMAL) ? texel_of(m->normal, i) : NULL,
      (needs & NEEDS_SSBUMP) ? texel_of(m->ssbump, i) : NULL,
      (needs & NEEDS_AO) ? texel_of(m->ao, i) : NULL,
      (needs & NEEDS_SSBUMP) ? texel_of(m->bent, i) : NULL,
      (needs & NEEDS_SLOPE) ? texel_of(m->slope, i) : NULL,
  };
  shade_point(job, &t, texel_of(m->albedo, i), out);
}

/* ------------------------------------------------------ view and relief */

/* Bilinear read of the first `channels` channels of img at point (x, y):
 * texel (i, j) sits at (i, j) and the map tiles (GL_LINEAR, GL_REPEAT). */
static void sample(const bb_image *img, double x, double y, int channels, float *out) {
  const double fx0 = floor(x), fy0 = floor(y), fx = x - fx0, fy = y - fy0;
  const int x0 = bb__wrap((int)fmod(fx0, (double)img->width), img->width);
  const int y0 = bb__wrap((int)fmod(fy0, (double)img->height), img->height);
  const int x1 = x0 + 1 < img->width ? x0 + 1 : 0, y1 = y0 + 1 < img->height ? y0 + 1 : 0;
  const float *a = bb_image_texel(img, x0, y0), *b = bb_image_texel(img, x1, y0);
  const float *c = bb_image_texel(img, x0, y1), *d = bb_image_texel(img, x1, y1);
  for (int k = 0; k < channels; k++)
    out[k] = (float)((1.0 - fy) * ((1.0 - fx) * a[k] + fx * b[k]) +
                     fy * ((1.0 - fx) * c[k] + fx * d[k]));
}

/* The relief's height, in texels, at point (x, y). */
static double relief_z(const bb_image *height, double depth, double x, double y) {
  float h;
  sample(height, x, y, 1, &h);
  return depth * (double)h;
}

/* Parallax occlusion mapping, shaders/ssbump_relief.glsl's relief_hit: the
 * view ray enters the relief's top plane (z = depth) at p and runs down
 * along -V; layers a horizontal half texel apart at most (at least 1, at
 * most BB__RELIEF_LAYERS) are tested until the ray is under the surface,
 * and the crossing is taken on the line between the last two (the
 * secant). Returns the point met. */
#define BB__RELIEF_LAYERS 1024
static void relief_hit(const bb_image *height, double depth, const double v[3], double px,
                       double py, double hit[2]) {
  const double reach = depth * hypot(v[0], v[1]) / v[2];
  double layers = ceil(2.0 * reach);
  layers = layers < 1.0 ? 1.0 : (layers > BB__RELIEF_LAYERS ? BB__RELIEF_LAYERS : layers);
  const double dz = depth / layers, dx = -v[0] / v[2] * dz, dy = -v[1] / v[2] * dz;
  double z = depth, above = z - relief_z(height, depth, px, py);
  hit[0] = px, hit[1] = py;
  if (!(above > 0.0)) return;
  for (int i = 0; i < (int)layers; i++) {
    const double nx = hit[0] + dx, ny = hit[1] + dy, nz = z - dz;
    const double below = nz - relief_z(height, depth, nx, ny);
    if (!(below > 0.0)) {
      const double t = above / (above - below);
      hit[0] += t * dx, hit[1] += t * dy;
      return;
    }
    hit[0] = nx, hit[1] = ny, z = nz, above = below;
  }
}

static void normalize3f(float *v) {
  const double len = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
  if (len > 0.0)
    for (int k = 0; k < 3; k++) v[k] = (float)(v[k] / len);
}

static void view_pixel(const render_job *job, int i, int j, float *out) {
  const bb_render_maps *m = job->maps;
  const bb_render_options *o = job->o;
  const double si = (double)i - 0.5 * job->width, sj = ((double)j - 0.5 * job->height) * job->stretch;
  double p[2] = {0.5 * job->width + si * job->right[0] + sj * job->toward[0],
                 0.5 * job->height + si * job->right[1] + sj * job->toward[1]};
  if (o->relief) {
    double hit[2];
    relief_hit(o->relief_height, o->relief_depth, job->view, p[0], p[1], hit);
    p[0] = hit[0], p[1] = hit[1];
  }
  const unsigned needs = job->mode->needs;
  float normal[3], ssbump[3], ao[1], bent[3], slope[1], albedo[3];
  texel_maps t = {NULL, NULL, NULL, NULL, NULL};
  if (needs & NEEDS_NORMAL) {
    sample(m->normal, p[0], p[1], 3, normal);
    normalize3f(normal);
    t.normal = normal;
  }
  if (needs & NEEDS_SSBUMP) {
    sample(m->ssbump, p[0], p[1], 3, ssbump);
    t.ssbump = ssbump;
    if (m->bent) {
      sample(m->bent, p[0], p[1], 3, bent);
      normalize3f(bent);
      t.bent = bent;
    }
  }
  if (needs & NEEDS_AO) {
    sample(m->ao, p[0], p[1], 1, ao);
    t.ao = ao;
  }
  if (needs & NEEDS_SLOPE) { /* a byte code, not a quantity: the nearest texel */
    const int x = bb__wrap((int)fmod(floor(p[0] + 0.5), (double)m->slope->width), m->slope->width);
    const int y = bb__wrap((int)fmod(floor(p[1] + 0.5), (double)m->slope->height), m->slope->height);
    slope[0] = bb_image_texel(m->slope, x, y)[0];
    t.slope = slope;
  }
  if (m->albedo) sample(m->albedo, p[0], p[1], m->albedo->channels >= 3 ? 3 : 1, albedo);
  shade_point(job, &t, m->albedo ? albedo : NULL, out);
}

static void view_row(void *user, int y) {
  const render_job *job = user;
  for (int x = 0; x < job->width; x++)
    view_pixel(job, x, y, job->out->pixels + 3 * ((size_t)y * (size_t)job->width + (size_t)x));
}

static void render_row(void *user, int y) {
  const render_job *job = user;
  const size_t width = (size_t)job->out->width, first = (size_t)y * width;
  for (size_t i = first; i < first + width; i++)
    shade_texel(job, i, job->out->pixels + 3 * i);
}

/* Tiling and cropping of the plain render; frees *img on failure. */
static bb_status apply_view(const bb_render_options *o, bb_image *img, bb_error *err) {
  bb_status st = BB_OK;
  if (o->tile_x > 1 || o->tile_y > 1) {
    bb_image tiled;
    st = bb__image_tile(img, o->tile_x, o->tile_y, &tiled, err);
    bb_image_free(img);
    if (st != BB_OK)
      return st;
    *img = tiled;
  }
  if (o->crop_width > 0) {
    bb_image cropped;
    st = bb__image_crop(img, o->crop_x, o->crop_y, o->crop_width, o->crop_height, &cropped,
                       err);
    bb_image_free(img);
    if (st != BB_OK)
      return st;
    *img = cropped;
  }
  return BB_OK;
}

/* Each colour is a float, but their sum and product can pass a float's
 * largest (light 3e38 with a specular highlight): a texel gone infinite is
 * refused with what to lower, never written as inf or as clipped white. */
static bb_status check_finite(const bb_image *img, bb_error *err) {
  const size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
  for (size_t i = 0; i < n; i++)
    if (isinf(img->pixels[i])) {
      char largest[32];
      bb__number_text(FLT_MAX, largest, sizeof largest);
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "render: too bright: a texel passes a float's largest value (%s); "
                      "lower the light colour, lightmap or specular strength",
                      largest);
    }
  return BB_OK;
}

bb_status bb__render(const bb_render_maps *maps, const bb_render_options *o, bb_image *out,
                    bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "render: out is NULL");
  memset(out, 0, sizeof *out);
  if (!maps)
    return bb__fail(err, BB_ERR_ARGUMENT, "render: maps are NULL");
  bb_status st = check_options(o, err);
  if (st != BB_OK)
    return st;
  const bb_image *size = NULL;
  st = check_maps(maps, find_mode(o->mode)->needs, &size, err);
  if (st == BB_OK && o->relief)
    st = check_map(o->relief_height, "relief height", 1, size, err);
  /* The picture's size and memory, before it is allocated. */
  double picture = 0.0;
  int picture_width = 0, picture_height = 0;
  if (st == BB_OK)
    st = bb__render_estimate(size->width, size->height, o, 0, NULL, BB_DEPTH_DEFAULT,
                            &picture_width, &picture_height, &picture, err);
  if (st == BB_OK) {
    char what[64];
    snprintf(what, sizeof what, "render: a %d x %d picture", picture_width, picture_height);
    st = bb__memory_check(picture, what, err);
  }
  if (st != BB_OK)
    return st;
  render_job job;
  if (!o->view) {
    st = bb_image_alloc(out, size->width, size->height, 3, err);
    if (st != BB_OK)
      return st;
    job_init(&job, maps, o, out);
    st = bb__parallel_for(out->height, o->threads, render_row, &job, NULL, NULL, err);
    if (st == BB_OK)
      st = apply_view(o, out, err);
  } else {
    /* the picture of the tiled maps' size, seen by the camera, then cropped */
    const long w = (long)size->width * o->tile_x, h = (long)size->height * o->tile_y;
    st = bb_image_alloc(out, (int)w, (int)h, 3, err);
    if (st != BB_OK)
      return st;
    job_init(&job, maps, o, out);
    job.width = (int)w, job.height = (int)h;
    st = bb__parallel_for(out->height, o->threads, view_row, &job, NULL, NULL, err);
    if (st == BB_OK && o->crop_width > 0) {
      bb_image cropped;
      st = bb__image_crop(out, o->crop_x, o->crop_y, o->crop_width, o->crop_height, &cropped, err);
      bb_image_free(out);
      if (st == BB_OK)
        *out = cropped;
    }
  }
  if (st == BB_OK)
    st = check_finite(out, err);
  if (st != BB_OK)
    bb_image_free(out);
  return st;
}

/* ----------------------------------------------------------- provenance */

/* Appends printf output to a malloc'd text, growing it; frees it and
 * returns NULL when out of memory. */
static char *append(char *text, size_t *length, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static char *append(char *text, size_t *length, const char *fmt, ...) {
  if (!text)
    return NULL;
  char line[256];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(line, sizeof line, fmt, ap);
  va_end(ap);
  if (n < 0 || (size_t)n >= sizeof line) {
    free(text);
    return NULL;
  }
  char *grown = realloc(text, *length + (size_t)n + 1);
  if (!grown) {
    free(text);
    return NULL;
  }
  memcpy(grown + *length, line, (size_t)n + 1);
  *length += (size_t)n;
  return grown;
}

char *bb__render_options_describe(const bb_render_options *o) {
  if (!o)
    return NULL;
  size_t n = 0;
  char *t = calloc(1, 1);
  t = append(t, &n, "render_mode=%s\n", bb__render_mode_name(o->mode));
  if (o->dynamic_light)
    t = append(t, &n, "light=%.9g,%.9g\nlight_color=%.9g,%.9g,%.9g\n", o->light_azimuth,
               o->light_elevation, (double)o->light_color[0], (double)o->light_color[1],
               (double)o->light_color[2]);
  else
    t = append(t, &n, "light=none\n");
  if (o->static_light) {
    const float(*L)[3] = o->lightmap;
    t = append(t, &n, "lightmap=%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
               (double)L[0][0], (double)L[0][1], (double)L[0][2], (double)L[1][0],
               (double)L[1][1], (double)L[1][2], (double)L[2][0], (double)L[2][1],
               (double)L[2][2]);
  } else {
    t = append(t, &n, "lightmap=none\n");
  }
  t = append(t, &n, "specular=%.9g\nspecular_strength=%.9g\nalbedo_mode=%s\ntile=%dx%d\n",
             o->specular_exponent, o->specular_strength, bb__albedo_mode_name(o->albedo_mode),
             o->tile_x, o->tile_y);
  if (o->crop_width > 0)
    t = append(t, &n, "crop=%d,%d,%d,%d\n", o->crop_x, o->crop_y, o->crop_width,
               o->crop_height);
  else
    t = append(t, &n, "crop=none\n");
  if (o->view)
    t = append(t, &n, "view=%.9g,%.9g\n", o->view_azimuth, o->view_elevation);
  if (o->relief)
    t = append(t, &n, "relief=%.9g\n", o->relief_depth);
  return t;
}

