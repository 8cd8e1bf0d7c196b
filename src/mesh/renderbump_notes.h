/* renderbump_notes.h: the notes a flat render bump owes its caller
 * (renderbump_notes.c). */
#ifndef BB_MESH_RENDERBUMP_NOTES_H
#define BB_MESH_RENDERBUMP_NOTES_H

#include "bumpbake.h"
#include "mesh/mesh_internal.h" /* bb_renderbump_options */

/* Tells o->note (when set) that r's texels are not square, with the size
 * and the rectangle that would make them so. */
void bb__renderbump_notes(const bb_renderbump_options *o, const bb_renderbump_result *r);

#endif /* BB_MESH_RENDERBUMP_NOTES_H */
