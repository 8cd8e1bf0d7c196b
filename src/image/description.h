/* description.h: how an ImageDescription (provenance) is fitted to a file
 * format and read back from it (description.c). */
#ifndef BB_IMAGE_DESCRIPTION_H
#define BB_IMAGE_DESCRIPTION_H

#include "bumpbake.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The ImageDescription to hand OpenImageIO for description in a file whose
 * extension is path's: the text itself, except that a TGA's provenance
 * longer than a comment row is fitted to the rows with whole key=value
 * lines. malloc'd; NULL when out of memory. */
char *bb__description_to_store(const char *path, const char *description);

/* What of description a TGA at path cannot keep in its comment rows, for
 * its image ID field: the lines bb__description_to_store left out, whole,
 * as many as 255 bytes hold ("" for any other file, or when all fit).
 * malloc'd; NULL when out of memory. */
char *bb__description_overflow(const char *path, const char *description);

/* A TGA's description (malloc'd; taken) with the provenance lines of its
 * image ID (what bb__description_overflow stored) after it; any other
 * image ID, or file, leaves it as it is. Returns the text (reallocated). */
char *bb__description_join(const char *format_name, char *description,
                           const char *image_id);

/* The description as read from a file of OpenImageIO's format_name, fixed
 * in place: a TGA's provenance loses the blank lines its row padding left. */
void bb__description_as_read(const char *format_name, char *description);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_DESCRIPTION_H */
