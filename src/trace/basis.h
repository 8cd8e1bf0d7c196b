/* basis.h: the checks of a basis and of a basis map every family that
 * reads one makes (basis.c); not public. */
#ifndef BB_TRACE_BASIS_H
#define BB_TRACE_BASIS_H

#include "bumpbake.h"

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

#endif /* BB_TRACE_BASIS_H */
