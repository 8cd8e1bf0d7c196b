/* mesh_internal.h: what the mesh family shares with the families above it
 * (not public): the range of a render bump's samples, written once
 * (renderbump.c) and referred to by the option that sets it (cmd/). */
#ifndef BB_MESH_INTERNAL_H
#define BB_MESH_INTERNAL_H

#include "core/internal.h"

extern const bb__range bb__range_renderbump_samples;

#endif /* BB_MESH_INTERNAL_H */
