/* bake_internal.h: the bake's stages with the bake's thread count,
 * and the checks the bake family shares (not public). */
#ifndef BB_BAKE_INTERNAL_H
#define BB_BAKE_INTERNAL_H

#include "bumpbake.h"
#include "core/internal.h"

/* Once in bumpbake.h, now internal (issue 41): a bake's options, which
 * change with every feature; clients set them through a command
 * (bb_command_set) and read them by name (bb_command_value) */
typedef struct bb_smooth_options {
  int radius_texels;     /* R, window |ix|,|iy| <= R; 0 = off (copy). Default 10 */
  float threshold;       /* T in normalised height units, > 0. Default 2/255 */
  bb_addressing addressing;
} bb_smooth_options;

/* A bake's options; a client has them, its defaults filled in, from a
 * bake command (bb__command_job_options). */
typedef struct bb_bake_options {
  float height_scale;         /* S, texels per unit of h, > 0 */
  int rays;                   /* ray budget, 1..BB_MAX_RAYS, default 256:
                                 round(sqrt(rays)) slices (bb__bake_slices) */
  int slices;                 /* azimuth slices, 1..BB_MAX_SLICES; 0 (default):
                                 from rays */
  bb_smooth_options smooth;   /* filter radius 0..BB_MAX_FILTER_RADIUS,
                                 threshold > 0, addressing */
  bb_trace_options trace;     /* bias 0..BB_MAX_BIAS_TEXELS; threads
                                 0..BB_MAX_THREADS, used by EVERY stage of the
                                 bake (smooth, normals, pyramid, trace,
                                 derive); progress, which may cancel */
  double power;               /* P in 1..BB_MAX_POWER, default 1 */
  bb_basis basis;             /* default "hl2"; weights and
                                 ssbump get one channel per direction */
  bb_normal_filter normal_filter; /* default BB_NORMAL_VERTEX */
  int normal_y_up;            /* 1 flips green of normal and bent */
  unsigned outputs;           /* the maps to make: BB_MAP_BIT(kind)s,
                                 default BB_MAPS_BAKED, not 0. Nothing else
                                 is computed: no trace without a traced kind
                                 (then rays and slices are not checked); a map
                                 another needs is made and freed (bent needs
                                 ssbump, both need the normal) */
  double bounce_albedo;       /* rho in [0, 1]: inter-reflection. ao, ssbump
                                 and bent then include the light the
                                 surrounding height field reflects,
                                 Lambertian with albedo rho (times
                                 bounce_albedo_map), normalised as without it
                                 (docs/conventions.md "Inter-reflection"; the
                                 weights hold no visibility and do not change).
                                 Default 0: none, and the bake is bit for bit
                                 the one without these fields. Costs about 3
                                 traces per bounce, and 72 (1 + basis count)
                                 bytes per texel */
  const bb_image *bounce_albedo_map; /* NULL (default), or an image of the
                                 height's size whose grey (1 channel: it; 2:
                                 the first; 3 or more: Rec. 709 luma of R, G,
                                 B), clamped to [0, 1], multiplies rho at each
                                 vertex, linear over each triangle. Not owned;
                                 ignored while bounce_albedo is 0 (a job given
                                 only bounce_albedo_file bounces with rho 1) */
  int bounces;                /* 1..BB_MAX_BOUNCES: light reflected that many
                                 times; 0 (default): converged (each
                                 triangle's light estimated from what it
                                 blocks, one bounce gathered from that
                                 estimate, the rest of the series then
                                 added as geometric) */
  const bb_image *brightness; /* NULL (default), or a brightness map of the
                                 height's size: ssbump and weights are
                                 multiplied by its grey, the paper's
                                 "brightness modulation factor in the normal
                                 map", as combine --brightness does (a
                                 texel that would exceed 1 is scaled down,
                                 its channels' ratios kept); ao and bent do
                                 not change. Not owned */
} bb_bake_options;


/* The stages of a bake with the bake's thread count (0 = all cores); the
 * public functions of the same name without "bb__" call them with 0.
 * Every stage splits its work into items whose results do not depend on
 * the split, so any thread count gives the same bits. */
bb_status bb__smooth_bilateral(const bb_image *in, const bb_image *guide,
                               const bb_smooth_options *o, int threads,
                               const bb__checkpoint *checkpoint, bb_image *out, bb_error *err);
/* bb__smooth_bilateral's texels of a rectangle only, x0 .. x0+width-1 by
 * y0 .. y0+height-1 (taken through the addressing: periodic ones may pass
 * the sides and wrap), written into out, which already holds the whole
 * image's smoothing: the same bits as smoothing all of it. The guide's
 * heights must be finite. */
bb_status bb__smooth_region(const bb_image *in, const bb_image *guide,
                            const bb_smooth_options *o, int x0, int y0, int width,
                            int height, int threads, bb_image *out, bb_error *err);
/* How far (texels, along each axis) a smoothed texel reads its input. */
int bb__smooth_reach(int radius_texels);
bb_status bb__normals_compute(const bb_image *height, float height_scale,
                              bb_normal_filter filter, bb_addressing addressing, int threads,
                              const bb__checkpoint *checkpoint, bb_image *out, bb_error *err);
/* Rows y0 .. y1-1 of bb__normals_compute's normals of height (finite
 * heights; the same bits), into rows: (y1 - y0) x width x 3 floats. For a
 * stage that needs the normals a band at a time, without the whole image. */
void bb__normals_rows(const bb_image *height, float height_scale, bb_normal_filter filter,
                      bb_addressing addressing, int y0, int y1, float *rows);
/* bb__derive_ssbump with the normals of the smoothed height computed band
 * by band (bb__normals_rows with the bake's scale, filter and addressing)
 * instead of read from a normal image: the same bits, 12 bytes a texel
 * fewer when the bake writes no normal map. */
bb_status bb__derive_ssbump_from_height(const bb_image *filtered, float height_scale,
                                        bb_normal_filter filter, bb_addressing addressing,
                                        const bb_image *vis, const bb_basis *basis, int threads,
                                        bb_image *out, bb_error *err);
bb_status bb__derive_weights(const bb_image *normals, const bb_basis *basis, int threads,
                             bb_image *out, bb_error *err);
bb_status bb__derive_ssbump(const bb_image *normals, const bb_image *vis,
                            const bb_basis *basis, int threads, bb_image *out, bb_error *err);
bb_status bb__derive_ao(const bb_image *vis, int threads, bb_image *out, bb_error *err);
bb_status bb__derive_bent(const bb_image *ssbump, const bb_basis *basis, int threads,
                          bb_image *out, bb_error *err);
/* One texel of the derived maps, as the stages above make it (the same
 * bits), for a bake that derives a few texels again: weights and ssbump of
 * a normal n, ssbump from the texel's visibility (ao, then a channel per
 * direction), bent from its ssbump before brightness; brightness as
 * bb__derive_brightness scales every channel of a texel by the grey of its
 * brightness map. */
void bb__derive_texel_weights(const bb_basis *basis, const float n[3], float *weights);
void bb__derive_texel_ssbump(const bb_basis *basis, const float n[3], const float *vis,
                             float *ssbump);
void bb__derive_texel_bent(const bb_basis *basis, const float *ssbump, float bent[3]);
void bb__derive_texel_brightness(const float *map, int channels, float grey, float *out);


/* The ranges of bb_bake_options' fields, the one home of each (options.c);
 * the options that set them (cmd/) check against these. */
extern const bb__range bb__range_height_scale, bb__range_rays, bb__range_slices,
    bb__range_filter_radius, bb__range_filter_threshold, bb__range_bias, bb__range_power,
    bb__range_bounce_albedo, bb__range_bounces;

/* The one check of a bake's options (bb__bake_options_check) and the one
 * place its ray budget becomes azimuth slices: out is in with slices set
 * (bb__bake_slices) when a traced map is asked. Every entry point taking
 * bb_bake_options prepares them once; what runs after (bb__bake, the
 * memory estimate, the ray set) reads out->slices and checks nothing. */
bb_status bb__bake_prepare(const bb_bake_options *in, bb_bake_options *out, bb_error *err);
/* bb__bake_prepare without the check, for options already checked (a
 * command's, cmd/): the one place rays become slices. */
void bb__bake_resolve(bb_bake_options *o);

/* bb__bake_checked for a caller that only writes the maps (the job), which lets go
 * of what it will not use as soon as the bake is done with it:
 * BB__BAKE_DROP_VIS: r->vis goes once ssbump and ao are made (4 bytes a
 * texel per lobe and one); BB__BAKE_TAKE_HEIGHT: the bake frees height's
 * pixels once it is smoothed (4 bytes a texel), on success or failure. */
enum { BB__BAKE_DROP_VIS = 1, BB__BAKE_TAKE_HEIGHT = 2 };
bb_status bb__bake(bb_image *height, const bb_bake_options *o, unsigned flags,
                   bb_bake_context *context, bb_bake_result *r, bb_error *err);
/* (o prepared by bb__bake_prepare: it is not checked again. context may
 * be NULL: a cold bake.) */

/* What a bake whose context keeps it (rebake.c) takes from the stages:
 * every texel's horizon in each slice, written to the caller's
 * horizons[s] (width x height floats each), and the max-mip pyramid,
 * handed over instead of freed (the caller frees it, on failure too). */
typedef struct bb__bake_keep {
  float *const *horizons;
  bb_pyramid *pyramid;
} bb__bake_keep;
/* bake_stages for such a bake: nothing dropped (vis and the smoothed
 * height stay in r whatever o asks), the same maps and bits. */
bb_status bb__bake_keeping(const bb_image *height, const bb_bake_options *o,
                           bb_bake_context *context, bb__bake_keep *keep,
                           bb_bake_result *r, bb_error *err);

/* rebake.c: a bake through a context that keeps what it made
 * (bb_bake_context_keep): again only where the height changed since the
 * context's last bake of the same size and options, else whole; r as
 * bb__bake fills it (flags as there, but height is not freed). changed
 * (may be NULL) receives bb__bake_context_bake's rectangle. */
bb_status bb__context_bake(bb_bake_context *context, const bb_image *height,
                           const bb_bake_options *o, unsigned flags, bb_bake_result *r,
                           bb_region *changed, bb_error *err);
/* bb__bake through context: bb__context_bake when it keeps (height freed
 * as BB__BAKE_TAKE_HEIGHT says), bb__bake otherwise. For the job. */
bb_status bb__bake_through(bb_bake_context *context, bb_image *height,
                           const bb_bake_options *o, unsigned flags, bb_bake_result *r,
                           bb_error *err);
/* The kept bake (rebake.c), held by the context (context.c): 1 when bakes
 * through context keep (NULL: 0); what it holds (NULL: nothing); and
 * kept in its place, freed by kept_free when it goes (the one before it
 * goes now; NULL, NULL: nothing kept). */
typedef struct bb__kept bb__kept;
int bb__context_keeps(const bb_bake_context *context);
bb__kept *bb__context_kept(const bb_bake_context *context);
void bb__context_hold(bb_bake_context *context, bb__kept *kept,
                      void (*kept_free)(bb__kept *));
/* What bb_bake_context_changed says from now on. */
void bb__context_set_changed(bb_bake_context *context, bb_region changed);
/* For tests: 1 when the context's last bake was edit-local. */
int bb__context_last_local(const bb_bake_context *context);

/* context.c: the ray set of these parameters into *rays: context's own,
 * lent (*owned 0), built anew when the last one's parameters differ; or,
 * without a context, built for the caller to release (*owned 1). */
bb_status bb__context_rayset(bb_bake_context *context, int slices, double power,
                             const bb_basis *basis, int threads, bb_rayset *rays,
                             int *owned, bb_error *err);
/* 1 when two bases are the same directions of the same name. */
int bb__same_basis(const bb_basis *a, const bb_basis *b);
/* Ray sets the context has built (tests: 1 after two bakes alike). */
long bb__context_rayset_builds(const bb_bake_context *context);

/* The most bytes bb__bake with flags allocates at one time for a width x
 * height bake with options o (memory.c follows its stages), counting
 * `held` bytes the caller holds as the bake starts (its height, freed
 * after smoothing with BB__BAKE_TAKE_HEIGHT); *kept (may be NULL) receives
 * what is left allocated once it returns (the maps it made). An upper
 * bound, from the sizes alone. */
double bb__bake_memory(int width, int height, const bb_bake_options *o, unsigned flags,
                       double held, double *kept);

/* The grey of img (1 channel: it; 2: the first; 3 or more: Rec. 709 luma
 * of R, G, B) into out (allocated, 1 channel), which must be width x
 * height: BB_ERR_SIZE otherwise, BB_ERR_VALUE at a NaN or infinite grey,
 * messages starting with `what`. Not clamped. */
bb_status bb__image_grey(const bb_image *img, int width, int height, const char *what,
                         bb_image *out, bb_error *err);

/* The first `scaled` channels of map times the grey of brightness
 * (bb__image_grey; negative taken as 0), the others copied; where the
 * largest scaled channel would exceed 1, the texel's scaled channels are
 * divided by it (their ratios kept). out is allocated; messages start
 * with "who: ". */
bb_status bb__derive_brightness(const bb_image *map, int scaled, const bb_image *brightness,
                                const char *who, int threads, bb_image *out, bb_error *err);

/* Checks that height_scale * h is a finite float with room to spare for
 * differences (|S h| <= BB_MAX_HEIGHT_TEXELS) at every texel of a 1-channel
 * height; BB_ERR_VALUE names the first texel over it (scaled_height.c). */
bb_status bb__check_scaled_height(const bb_image *height, float height_scale, bb_error *err);

/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

void bb__smooth_options_init(bb_smooth_options *o);

/* Valve's tileable bilateral filter (docs/conventions.md "Smoothing") of every
 * channel of in, guided by channel 0 of guide (guide may be in). Allocates out
 * with in's size and channels. */
bb_status bb__smooth_bilateral_all_cores(const bb_image *in, const bb_image *guide,
                              const bb_smooth_options *o, bb_image *out,
                              bb_error *err);

/* Unit tangent-space normals (+Y down) of the surface z = height_scale * h.
 * height: 1 channel; out: allocated, 3 channels. */
bb_status bb__normals_compute_all_cores(const bb_image *height, float height_scale,
                             bb_normal_filter filter, bb_addressing addressing,
                             bb_image *out, bb_error *err);

/* ssbump s_c = max(0, N.B_c) * vis_c, for the channels of vis after ao
 * (vis as bb__trace_occlusion makes it: 1 + basis->count channels; with
 * basis NULL, 4 or 5). out (allocated): count channels. */
bb_status bb__derive_ssbump_all_cores(const bb_image *normals, const bb_image *vis,
                           const bb_basis *basis, bb_image *out, bb_error *err);

/* ao as a 1-channel image (channel 0 of vis). */
bb_status bb__derive_ao_all_cores(const bb_image *vis, bb_image *out, bb_error *err);

/* Bent normal normalize(sum_c s_c B_c) over the basis' channels of ssbump
 * (basis->count of them; with basis NULL, 3 or 4); (0, 0, 1) where every
 * s_c is 0. out (allocated): 3 channels, +Y down. */
bb_status bb__derive_bent_all_cores(const bb_image *ssbump, const bb_basis *basis, bb_image *out,
                         bb_error *err);

/* Checks every field of o as bb__bake_checked does before it starts (ranges in the
 * field comments): BB_OK, or BB_ERR_ARGUMENT with a message such as "bake:
 * filter radius must be in 0..4096 (got 5000)". So a caller can refuse bad
 * options before loading anything. */
bb_status bb__bake_options_check(const bb_bake_options *o, bb_error *err);

/* The defaults of a bake's options (height_scale 0: it must be set); a
 * command's bake starts from them (bb__job_options_init). */
void bb__bake_options_init(bb_bake_options *o);

/* The maps of docs/conventions.md "Derived maps", for any basis: channel c belongs
 * to basis->vector[c]. basis NULL means Half-Life 2's B0, B1, B2, and for
 * ssbump and bent also hl2+z when the input has a fourth basis channel. */

/* weights w_c = sat(N.B_c)^2 / sum_k sat(N.B_k)^2 over the basis' count
 * directions (Valve's normal2ssbump for "hl2"); a normal facing away from
 * every direction gets 1 / count in each. normals: 3 channels; out
 * (allocated): count channels. */
bb_status bb__derive_weights_all_cores(const bb_image *normals, const bb_basis *basis,
                                      bb_image *out, bb_error *err);

/* Once in bumpbake.h beside the functions that stay public there. */
/* "periodic" or "clamp"; "unknown" for other values. */
const char *bb__addressing_name(bb_addressing addressing);
/* Parses "vertex", "valve", "central", "sobel". */
bb_status bb__normal_filter_parse(const char *name, bb_normal_filter *out, bb_error *err);
const char *bb__normal_y_name(int normal_y_up);

/* The words of --normal-filter and --normal-y (once public: a client
 * reads them through the option rows, bb_option_word and bb_option_parse). */
const char *bb__normal_filter_name(bb_normal_filter f);
/* "down" or "up", the words of --normal-y (normal_y_up 0 or 1). */
bb_status bb__normal_y_parse(const char *name, int *normal_y_up, bb_error *err);

/* Runs smooth -> normals -> pyramid -> trace -> derive on a 1-channel height
 * field (normalised h), making the maps o->outputs asks for and nothing
 * else (vis is made whenever a traced kind is asked), o checked and
 * prepared first (bb__bake_prepare). Results are bit-identical for any
 * o->trace.threads. Fills result; free it with bb_bake_result_free.
 * Errors: BB_ERR_ARGUMENT (a value outside the range of bake's option for
 * it, bb_option_bounds; no outputs or unknown ones, an unknown addressing
 * or normal filter, a bounce albedo or brightness map without pixels, a
 * basis of other than 3..BB_MAX_BASIS unit directions with z >= 0),
 * BB_ERR_VALUE (NaN heights, scale x height overflowing), BB_ERR_MEMORY,
 * and BB_ERR_CANCELLED when o->trace.progress returned nonzero: then
 * nothing is returned (result is zeroed). */
bb_status bb__bake_checked(const bb_image *height, const bb_bake_options *o,
                           bb_bake_result *result, bb_error *err);

/* The image of kind in r (NULL for an unknown kind); its pixels are NULL
 * when the bake did not make it. Owned by r. */
const bb_image *bb__bake_result_image(const bb_bake_result *r, bb_map_kind kind);

/* bb__bake_checked of height with o through context: the same checks, maps and
 * bits; result as bb__bake_checked fills it (free it with bb_bake_result_free),
 * its seconds and horizons_found those of the work done. changed (may be
 * NULL) receives the texels whose maps may differ from those of the
 * context's bake before (bb_bake_context_changed's rectangle). */
bb_status bb__bake_context_bake(bb_bake_context *context, const bb_image *height,
                                const bb_bake_options *o, bb_bake_result *result,
                                bb_region *changed, bb_error *err);

/* What a bake traces, built alone for a trace split over processes
 * (bb_command_trace_input builds it of a command's input): the
 * max-mip pyramid of the smoothed height scaled to texels, and the ray set
 * of o's slices, power and basis, built by the bake's own stages (the same
 * bits), so the horizons found from them (bb_trace_horizons) are those of
 * a bake's trace of height with o. Checks o and the height as the bake does;
 * o->outputs must ask for a traced kind. On success *pyramid and *rays
 * receive them (free with bb_pyramid_free and bb_rayset_free). Memory:
 * about 13 bytes per texel while building, 5.4 once built. */
bb_status bb__bake_trace_input(const bb_image *height, const bb_bake_options *o,
                               bb_pyramid **pyramid, bb_rayset **rays, bb_error *err);

/* Once in bumpbake.h, now internal (issue 41): no client of the library
 * calls it; the library, tests and tools do. */
/* The azimuth slices o traces with: o->slices when set, else
 * the slices o->rays asks for (round(sqrt(rays)), at least 1). The one rule; provenance, JSON and the
 * up-to-date check all report it. */
int bb__bake_slices(const bb_bake_options *o);

#endif /* BB_BAKE_INTERNAL_H */
