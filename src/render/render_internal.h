/* render_internal.h: what the render family shares with the families above
 * it (not public): the ranges of bb_render_options' fields, each written
 * once in render.c and referred to by the options that set them (cmd/) and
 * by the job's lit slope preview. */
#ifndef BB_RENDER_INTERNAL_H
#define BB_RENDER_INTERNAL_H

#include "core/internal.h"

extern const bb__range bb__range_light_elevation, bb__range_view_elevation,
    bb__range_colour, bb__range_specular_exponent, bb__range_specular_strength,
    bb__range_tile;

/* bb_render_files_check's estimate without its memory check: *need, the
 * bytes of memory the render of files will take at its peak (0 when a
 * read will refuse a file first, as too large), the file messages name
 * (*named: the output, else the first file read) and what it is ("a 16384
 * x 16384 render", what_cap bytes). */
bb_status bb__render_files_need(const bb_render_sources *files,
                                const bb_bake_options *bake, const bb_render_options *o,
                                int compare, const char *output, bb_depth depth,
                                int *width, int *height, double *need, const char **named,
                                char *what, size_t what_cap, bb_error *err);

#endif /* BB_RENDER_INTERNAL_H */
