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

/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* The default basis, "hl2": Half-Life 2's B0, B1, B2 (header top). */
void bb__basis_init(bb_basis *b);

/* Unit vector of Half-Life 2's direction index 0..3 into v (3 is the
 * optional B3 = (0, 0, 1) of "hl2+z"); an index outside gives zeros. */
void bb__basis_vector(int index, double v[3]);

/* "dirs:N": N directions (3..BB_MAX_BASIS) evenly spread in azimuth at
 * Half-Life 2's elevation asin(1/sqrt(3)) (35.26 degrees):
 *   B_c = (sqrt(2/3) cos(phi_c), sqrt(2/3) sin(phi_c), 1/sqrt(3)),
 *   phi_c = 360 c / N degrees,
 * in the +Y-down frame: B_0 lights from the right (+x) and phi grows from
 * +x towards +y (the bottom of the image), clockwise on screen, the way
 * Half-Life 2's B1 and B2 lie at 120 and 240 degrees. So "dirs:3" is "hl2"
 * bit for bit (a direction of N's that is one of Half-Life 2's takes its
 * constants: "dirs:6" holds B0, B1, B2 in channels 0, 2, 4), and a quarter
 * turn is exact ((0, +-sqrt(2/3)) for N a multiple of 4). BB_ERR_ARGUMENT
 * for N outside 3..BB_MAX_BASIS; out is untouched then. */
bb_status bb__basis_dirs(int count, bb_basis *out, bb_error *err);

/* A named basis: "hl2", "hl2+z" or "dirs:N" (bb__basis_dirs), exactly as
 * written. BB_ERR_ARGUMENT with a message saying what is accepted for any
 * other text; out is untouched then. */
bb_status bb__basis_parse(const char *name, bb_basis *out, bb_error *err);

/* Parses a basis file's text: one direction "x y z" per line (numbers as
 * strtod reads them, separated by blanks or commas), '#' starts a comment
 * that runs to the end of the line, blank lines are skipped; then as
 * bb_basis_from_vectors. source names the text in messages, which read
 * "SOURCE:LINE: reason" (BB_ERR_FORMAT for a line that is not three
 * numbers, BB_ERR_ARGUMENT for a vector or a count the basis refuses). */
bb_status bb__basis_read_text(const char *text, const char *source, bb_basis *out,
                             bb_error *err);

/* Reads a basis file (format: bb__basis_read_text) of at most 64 KiB.
 * Errors: BB_ERR_IO (missing, unreadable, a directory), BB_ERR_SIZE (over
 * 64 KiB), and those of bb__basis_read_text, each naming path. */
bb_status bb__basis_load(const char *path, bb_basis *out, bb_error *err);

/* Readers of basis maps (render, ssbump2normal, combine --detail) take
 * channels 0..2 as Half-Life 2's B0, B1, B2. BB_OK when a map file (its
 * decoded img and its description, the provenance text, may be NULL) can
 * be one: at most 4 channels, and a provenance basis, if any, that is
 * Half-Life 2's (hl2, hl2+z, dirs:3: bb__basis_is_hl2); else
 * BB_ERR_ARGUMENT saying which ("baked with --basis dirs:6; this reads
 * Half-Life 2's basis (bake with --basis hl2)"). */
bb_status bb__basis_map_check(const bb_image *img, const char *description, bb_error *err);

/* 1 when b holds Half-Life 2's B0, B1, B2 in channels 0..2 bit for bit
 * ("hl2", "dirs:3", and "hl2+z", whose B3 is a fourth channel), which the
 * consumers of 3-channel basis maps (render, ssbump2normal, Valve's
 * files) assume; else 0. */
int bb__basis_is_hl2(const bb_basis *b);

#endif /* BB_TRACE_BASIS_H */
