/* description.c: provenance in a TGA's comment field.
 *
 * TGA keeps ImageDescription in its extension area's comment field: 4 rows
 * of 80 characters, each NUL-terminated (324 bytes). OpenImageIO 2.4 writes
 * the text flat into those bytes and reads each 81-byte row back as one
 * line, so a provenance text longer than a row came back cut inside values
 * ("input=roc" / "k.tga"). Provenance is therefore fitted to the rows with
 * whole key=value lines (bb__provenance_pack), each row padded to its 81
 * bytes with newlines, and the blank lines the padding leaves are dropped
 * when it is read. The lines the rows cannot hold (the command line, which
 * ranks last) go to the header's image ID field (255 bytes, before the
 * pixels), whole lines as many as fit, and join the text again when it is
 * read. Other text is left to OpenImageIO. */
#include "image/description.h"
#include "image/formats.h"
#include "files/provenance.h"

#include <stdlib.h>
#include <string.h>

enum { TGA_COMMENT_ROWS = 4, TGA_COMMENT_CHARS = 80, TGA_IMAGE_ID_CHARS = 255 };

static char *copy_of(const char *s) {
  size_t n = strlen(s) + 1;
  char *c = malloc(n);
  if (c) memcpy(c, s, n);
  return c;
}

/* 1 when description is a TGA's provenance that must be fitted to its rows
 * (a text that fits the first row is stored as it is). */
static int is_fitted(const char *path, const char *description) {
  return bb__path_has_extension(path, "tga") && strlen(description) > TGA_COMMENT_CHARS &&
         bb__provenance_classify(description) != BB_PROVENANCE_NONE;
}

char *bb__description_to_store(const char *path, const char *description) {
  if (!is_fitted(path, description))
    return copy_of(description);
  char rows[TGA_COMMENT_ROWS][TGA_COMMENT_CHARS + 1];
  bb__provenance_pack(description, TGA_COMMENT_ROWS, TGA_COMMENT_CHARS, &rows[0][0]);
  char *flat = malloc(sizeof rows);
  if (!flat) return NULL;
  size_t n = 0;
  for (int r = 0; r < TGA_COMMENT_ROWS && rows[r][0]; r++) {
    /* pad the previous row to its 81 bytes */
    size_t row_start = (size_t)r * (TGA_COMMENT_CHARS + 1);
    while (n < row_start) flat[n++] = '\n';
    size_t len = strlen(rows[r]);
    memcpy(flat + n, rows[r], len);
    n += len;
  }
  flat[n] = '\0';
  return flat;
}

char *bb__description_overflow(const char *path, const char *description) {
  if (!is_fitted(path, description))
    return copy_of("");
  char rows[TGA_COMMENT_ROWS][TGA_COMMENT_CHARS + 1];
  char overflow[TGA_IMAGE_ID_CHARS + 1];
  bb__provenance_pack_overflow(description, TGA_COMMENT_ROWS, TGA_COMMENT_CHARS,
                               &rows[0][0], overflow, sizeof overflow);
  return copy_of(overflow);
}

/* 1 when every line of text is "key=value" (key: a-z, 0-9, '_'). */
static int all_entries(const char *text) {
  for (const char *line = text; *line;) {
    size_t k = 0;
    while ((line[k] >= 'a' && line[k] <= 'z') || (line[k] >= '0' && line[k] <= '9') ||
           line[k] == '_')
      k++;
    if (k == 0 || line[k] != '=')
      return 0;
    const char *end = strchr(line, '\n');
    line = end ? end + 1 : line + strlen(line);
  }
  return 1;
}

char *bb__description_join(const char *format_name, char *desc, const char *image_id) {
  if (strcmp(format_name, "targa") != 0 || !image_id || !image_id[0] ||
      bb__provenance_classify(desc) == BB_PROVENANCE_NONE)
    return desc;
  /* only key=value lines join: any other image ID is another tool's */
  if (!all_entries(image_id))
    return desc;
  size_t n = strlen(desc);
  char *joined = realloc(desc, n + 1 + strlen(image_id) + 1);
  if (!joined)
    return desc;
  joined[n] = '\n';
  strcpy(joined + n + 1, image_id);
  return joined;
}

void bb__description_as_read(const char *format_name, char *desc) {
  /* Padded rows always leave an empty line; a text stored as it was has none. */
  if (strcmp(format_name, "targa") != 0 || !strstr(desc, "\n\n") ||
      bb__provenance_classify(desc) == BB_PROVENANCE_NONE)
    return;
  size_t n = 0;
  for (const char *c = desc; *c; c++)
    if (*c != '\n' || (n > 0 && desc[n - 1] != '\n')) desc[n++] = *c;
  while (n > 0 && desc[n - 1] == '\n') n--;
  desc[n] = '\0';
}
