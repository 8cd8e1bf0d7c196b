/* maps_internal.h: helpers shared by the map conversions (convert.c,
 * combine.c, program.c); not public. The image checks they share with
 * other families are core's (core/internal.h). */
#ifndef BB_MAPS_INTERNAL_H
#define BB_MAPS_INTERNAL_H

#include "bumpbake.h"
#include "bake/bake_internal.h"
#include "core/internal.h"


#ifdef __cplusplus
extern "C" {
#endif

/* The ranges of bb_compare_limits' fields (compare.c): thresholds >= 0
 * (infinity allowed), percentages 0..100, counts >= 0. */
extern const bb__range bb__range_compare_threshold, bb__range_compare_percent,
    bb__range_compare_count;
/* A blend's factor, 0..1 (combine.c). */
extern const bb__range bb__range_mix;

/* DOOM 3's addnormals on one texel: n = base, z rebuilt from x and y when
 * |n| < 1 (maps that fade to (0, 0, 0) at their edges), n.xy += (dx, dy),
 * out = normalize(n). */
void bb__add_normals(const double base[3], double dx, double dy, double out[3]);



/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* Packs slopes dx, dy (each clamped to -7..7) into flipcode's byte: dx in
 * the low nibble, dy in the high nibble, each as a 4-bit two's complement
 * number (-1 is 0xF, -7 is 0x9). */
uint8_t bb__slope_encode(int dx, int dy);

/* Unpacks a slope byte; nibble 0x8 reads as -8 (bb__slope_encode never
 * writes it). */
void bb__slope_decode(uint8_t byte, int *dx, int *dy);

/* flipcode's slope map of a 1-channel height field h: for texel (x, y),
 * dx = S (h(x+1, y) - h(x, y)) and dy = S (h(x, y+1) - h(x, y)) in texels
 * (S = height_scale; forward differences, neighbours by addressing),
 * rounded to the nearest integer (halves away from 0) and clamped to -7..7.
 * Allocates out: 1 channel holding byte / 255, so an 8-bit file stores the
 * byte itself. */
bb_status bb__slope_map(const bb_image *height, float height_scale,
                       bb_addressing addressing, bb_image *out, bb_error *err);

/* The 16 x 16 lighting table: table[byte] = max(0, N.L) with N =
 * normalize(-dx, -dy, 1) for the slopes (dx, dy) the byte decodes to and L
 * a unit light direction (bb__light_direction makes one from azimuth and
 * elevation). Row = high nibble (dy), column = low nibble (dx). */
void bb__slope_table(const double light[3], float table[256]);

/* Lights a slope map through a table: out = table[byte] per texel, byte =
 * round(255 * slope value). Allocates out: 1 channel. */
bb_status bb__slope_light(const bb_image *slope, const float table[256], bb_image *out,
                         bb_error *err);

/* Channel-by-channel comparison of two images of equal size and channels
 * (BB_ERR_SIZE otherwise). A pixel counts as over a threshold when any of
 * its channels differs by more than it. diff (may be NULL) receives |a - b|. */
bb_status bb__compare_images(const bb_image *a, const bb_image *b,
                            double fail_threshold, double warn_threshold,
                            bb_compare_stats *stats, bb_image *diff,
                            bb_error *err);

/* Sets idiff's defaults (in the field comments above). */
void bb__compare_limits_init(bb_compare_limits *limits);

/* BB_OK when every limit is in its range: fail, hard_fail, warn and
 * hard_warn >= 0 (infinity allowed), the percentages in 0..100,
 * allow_failures >= 0; else BB_ERR_ARGUMENT naming the limit by idiff's
 * option ("compare: failpercent must be in 0..100 (got 150)"). NaN is
 * refused. */
bb_status bb__compare_limits_check(const bb_compare_limits *limits, bb_error *err);

/* idiff's rule (OpenImageIO 2.4), for stats made by bb__compare_images with
 * thresholds limits->fail and limits->warn: PASS when at most
 * allow_failures pixels fail; else FAIL when more than fail_percent % of
 * the pixels fail or max_abs > hard_fail; else WARN when more than
 * warn_percent % warn or max_abs > hard_warn; else PASS. As in idiff,
 * warnings are only reported once some pixel fails: with no failing pixel
 * the verdict is PASS. */
bb_compare_verdict bb__compare_judge(const bb_compare_stats *stats,
                                    const bb_compare_limits *limits);

/* Valve's RGBA file (height2ssbump), as the job writes it (once public;
 * a client asks for it through the bake's options). */
void bb__valve_options_init(bb_valve_options *o);

/* Packs a bake into Valve's RGBA layout: RGB = result->ssbump (its first
 * three channels) or result->normal encoded as 0.5 + 0.5 N, A =
 * result->filtered or result->ao. Every channel of out is then a unit value
 * (write it with BB_RANGE_UNIT). Allocates out: 4 channels, the bake's size.
 * BB_ERR_ARGUMENT when an image it needs was not baked (ssbump and ao need
 * the traced outputs) or has too few channels, or when the ssbump is of a basis
 * other than Half-Life 2's (result->basis, when set, or more than 4
 * channels); BB_ERR_SIZE when sizes differ. */
bb_status bb__valve_pack(const bb_bake_result *result, const bb_valve_options *o,
                        bb_image *out, bb_error *err);

/* Valve's detail variant (-d): multiplies R, G, B of rgba (4 channels, as
 * bb__valve_pack makes it; alpha untouched) by (R + G + B) / sqrt(3) of the
 * input colour smoothed like the height: colour is the decoded input (grey
 * and grey + alpha: grey is replicated; 3+ channels: R, G, B; alpha is
 * ignored), smoothed by bb__smooth_bilateral_all_cores with smooth and guided by
 * height (the 1-channel height the bake started from), so the factor
 * follows the same edges. A flat, unoccluded texel (0.57735) of mid-grey
 * input gives 0.5, the neutral value of a mod2x detail texture. All three
 * images must have the same size (BB_ERR_SIZE). */
bb_status bb__valve_detail(bb_image *rgba, const bb_image *colour, const bb_image *height,
                          const bb_smooth_options *smooth, bb_error *err);

/* Once in bumpbake.h, now internal (issue 41): the operators of
 * normal2ssbump, ssbump2normal and combine, which a client runs through
 * their commands (bb_command_map, bb_command_run). */

/* The kind of a map a conversion or combine works on; it fixes the
 * operators and the flat, unoccluded texel (ssbump 1/sqrt(3), weights 1/3,
 * ao 1, normal (0, 0, 1)). What a three-channel basis map holds is
 * BB_MAP_SSBUMP (s_c = max(0, N.B_c) vis_c: height2ssbump, bake --ssbump)
 * or BB_MAP_WEIGHTS (w_c = sat(N.B_c)^2 / sum: normal2ssbump, bake
 * --weights). */
/* The normal of a basis map, the paper's "sum of the basis vectors weighted
 * by the bumpmap texture, normalized": N = normalize(sum_c f(s_c) B_c) over
 * channels 0..2 (further channels, such as Valve's alpha, are ignored), with
 * f(s) = s for BB_MAP_SSBUMP and sqrt(max(0, s)) for BB_MAP_WEIGHTS (the
 * square root undoes normal2ssbump's square, so both kinds give back N
 * wherever every N.B_c >= 0). A texel with no weight gives (0, 0, 1).
 * A map of more than 4 channels (another basis) is BB_ERR_ARGUMENT.
 * Allocates normals: 3 channels, +Y down. Non-finite values: BB_ERR_VALUE. */
bb_status bb__ssbump_to_normal(const bb_image *ssbump, bb_map_kind kind,
                              bb_image *normals, bb_error *err);

/* combine works on BB_MAP_SSBUMP, BB_MAP_WEIGHTS, BB_MAP_AO and
 * BB_MAP_NORMAL; other kinds are BB_ERR_ARGUMENT. Its operators act on the
 * kind's bb_map_kind_info.file_channels: 3, or 1 for ao. */

/* The flat, unoccluded texel of kind (channels 0..file_channels-1 of
 * texel) as it reads back from a file of that sample depth: an integer file
 * of bits_per_sample bits stores it rounded to a code (an 8-bit ssbump holds
 * 147/255, an 8-bit normal map 128/255, which decodes to x = y = 1/255), a
 * half-float file (is_float, 16 bits) to 11 significant bits, a float file
 * exactly (as float). Normals are returned decoded. */
void bb__map_flat_texel(bb_map_kind kind, int bits_per_sample, int is_float,
                       float texel[3]);

/* Blends two maps of the same size: t = (1 - m) a + m b, m = mask channel 0
 * at the texel (clamped to [0, 1]) or the constant mix when mask is NULL.
 * ssbump, weights, ao: every channel, linearly (a and b need the same channel
 * count). normal: normalize(t) on channels 0..2. m = 0 gives a and m = 1
 * gives b bit for bit. Allocates out with a's channels (3 for normals). */
bb_status bb__combine_blend(const bb_image *a, const bb_image *b, const bb_image *mask,
                           float mix, bb_map_kind kind, bb_image *out, bb_error *err);

/* Overlays a detail map on a base of the same size. flat is the detail's own
 * flat texel (bb__map_flat_texel of the detail file's depth), or NULL for the
 * exact flat of the kind; a detail texel equal to it (within 1e-6, far
 * under one 16-bit code) leaves the base texel unchanged bit for bit.
 * ssbump, weights, ao: out_c = base_c * detail_c / flat_c on the kind's
 * channels (visibilities multiply; a flat detail is the identity, on either
 * side); further base channels (Valve's alpha) are copied, so an ssbump or
 * weights map of more than 4 channels (another basis) is BB_ERR_ARGUMENT.
 * normal: DOOM 3's addnormals: n = base (z rebuilt as sqrt(1 - x^2 - y^2)
 * when |n| < 1), n.xy += detail.xy - flat.xy, out = normalize(n).
 * Allocates out with base's channels. */
bb_status bb__combine_detail(const bb_image *base, const bb_image *detail,
                            bb_map_kind kind, const float *flat, bb_image *out,
                            bb_error *err);

/* Multiplies a map by a grey brightness map of the same size: the paper's
 * "brightness modulation factor in the normal map, for free", which lets a
 * low-resolution colour map and a high-resolution ssbump share the work.
 * The engine multiplies the stored weights by its lightmaps, so scaling the
 * weights scales the light. b is the brightness map's grey at the texel (1
 * channel: it; 2: the first; 3 or more: Rec. 709 luma of R, G, B; a
 * negative grey counts as 0).
 *   ssbump, weights: channels 0..2 times b. A channel holds at most 1: where
 *     the largest of the three would exceed it, the texel is scaled so that
 *     the largest is 1 instead, which keeps the channels' ratios (the
 *     direction the engine derives from them, the paper's bent normal): what
 *     clips is the brightness, never the direction. A flat, unoccluded
 *     ssbump texel (1/sqrt(3)) takes brightness up to sqrt(3) unclipped.
 *     Further channels (Valve's alpha) are copied; a map of more than 4
 *     channels (another basis) is BB_ERR_ARGUMENT.
 *   ao: times b, at most 1.
 *   normal: BB_ERR_ARGUMENT: a unit normal has no room for a brightness.
 * A brightness of 1 gives the map back bit for bit. Allocates out with the
 * map's channels. Errors: BB_ERR_ARGUMENT, BB_ERR_SIZE (another size),
 * BB_ERR_VALUE (a NaN or infinite value in either map). */
bb_status bb__combine_brightness(const bb_image *map, const bb_image *brightness,
                                bb_map_kind kind, bb_image *out, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_MAPS_INTERNAL_H */
