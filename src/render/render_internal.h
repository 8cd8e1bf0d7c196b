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

#endif /* BB_RENDER_INTERNAL_H */
