/* bake_internal.h: the bake's stages with the bake's thread count,
 * and the checks the bake family shares (not public). */
#ifndef BB_BAKE_INTERNAL_H
#define BB_BAKE_INTERNAL_H

#include "bumpbake.h"

/* The stages of a bake with the bake's thread count (0 = all cores); the
 * public functions of the same name without "bb__" call them with 0.
 * Every stage splits its work into items whose results do not depend on
 * the split, so any thread count gives the same bits. */
bb_status bb__smooth_bilateral(const bb_image *in, const bb_image *guide,
                               const bb_smooth_options *o, int threads, bb_image *out,
                               bb_error *err);
bb_status bb__normals_compute(const bb_image *height, float height_scale,
                              bb_normal_filter filter, bb_addressing addressing, int threads,
                              bb_image *out, bb_error *err);
bb_status bb__derive_weights(const bb_image *normals, const bb_basis *basis, int threads,
                             bb_image *out, bb_error *err);
bb_status bb__derive_ssbump(const bb_image *normals, const bb_image *vis,
                            const bb_basis *basis, int threads, bb_image *out, bb_error *err);
bb_status bb__derive_ao(const bb_image *vis, int threads, bb_image *out, bb_error *err);
bb_status bb__derive_bent(const bb_image *ssbump, const bb_basis *basis, int threads,
                          bb_image *out, bb_error *err);


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

/* BB_OK when b has 3..BB_MAX_BASIS unit vectors with z >= 0 (a basis
 * filled by hand is checked before it is used), else BB_ERR_ARGUMENT with a
 * message starting "who: ". */
bb_status bb__basis_check(const bb_basis *b, const char *who, bb_error *err);

/* Consumers of basis maps (render, ssbump2normal, combine's detail,
 * Valve's files) read channels 0..2 as Half-Life 2's B0, B1, B2 and leave a
 * fourth alone (Valve's alpha, hl2+z's B3). BB_OK when img (named what)
 * has at most 4 channels, else BB_ERR_ARGUMENT saying so; with a basis
 * (may be NULL: not known) also when it is not Half-Life 2's. */
bb_status bb__check_hl2_map(const bb_image *img, const bb_basis *basis, const char *what,
                            bb_error *err);


/* Checks that height_scale * h is a finite float with room to spare for
 * differences (|S h| <= BB_MAX_HEIGHT_TEXELS) at every texel of a 1-channel
 * height; BB_ERR_VALUE names the first texel over it. */
bb_status bb__check_scaled_height(const bb_image *height, float height_scale, bb_error *err);

#endif /* BB_BAKE_INTERNAL_H */
