/* header_walk_psd.c: a PSD's (and PSB's) sections walked as OpenImageIO
 * 2.4.7's reader walks them in open() (psdinput.cpp), each length checked
 * against the file before the walk follows it. The reader allocates what
 * these lengths declare, zeroed, before reading a byte of it (a 30-byte
 * file declaring 4 GiB of colour data took 4.3 GB), and fseek succeeds
 * past the end of the file, so only a read there would have stopped it:
 *
 * - the colour mode data (its length at 26);
 * - each image resource block ("8BIM", an id, a name, a length): EXIF,
 *   XMP and ICC blocks are allocated whole; a thumbnail (1033, 1036)
 *   allocates its length less its 28-byte header (shorter: about 4 GiB);
 *   the alpha names (1006) are read string by string until the block's
 *   length is used up, and a string past the end of the file reads as
 *   nothing, forever (OpenImageIO aborts once 16 MB of errors pile up);
 * - each layer's channels: every channel with data gets a table of 8
 *   bytes a row (12 for RLE), its rows the layer's (or, for the layer
 *   mask, channel -2, the mask's) bottom - top, before its data is read.
 *   A PSB is at most 300000 texels a side, and a row costs a channel at
 *   least one byte of its declared data, which lies in the file: so the
 *   tables are at most 12 bytes for each byte of the file.
 *
 * The walk stops quietly where a read of a fixed field fails: the reader's
 * read fails there too, before it allocates. */
#include "image/header_walk.h"

#include <stdlib.h>
#include <string.h>

/* The PSB additional layer information whose length is 8 bytes. */
static int psb_long_key(const unsigned char key[4]) {
  static const char keys[][5] = {"LMsk", "Lr16", "Lr32", "Layr", "Mt16", "Mt32", "Mtrn",
                                 "Alph", "FMsk", "Ink2", "FEid", "FXid", "PxSD", "cinf"};
  for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
    if (memcmp(key, keys[i], 4) == 0) return 1;
  return 0;
}

/* A Pascal string padded to a multiple of `pad` (its length byte
 * included), as the reader skips it. */
static void skip_name(bb__walk *w, unsigned pad) {
  const uint64_t length = bb__walk_number(w, 1, 0);
  if (!w->ok) return;
  w->pos += (double)(((1 + length + pad - 1) / pad) * pad - 1);
}

/* The image resource blocks from w->pos to end. 0 when the probe is
 * corrupt. */
static int walk_resources(bb__walk *w, double end, bb__probe *p) {
  while (w->ok && w->pos < end) {
    unsigned char tag[4];
    if (!bb__walk_tag(w, tag) || memcmp(tag, "8BIM", 4) != 0) return 1;
    const unsigned id = (unsigned)bb__walk_number(w, 2, 0);
    skip_name(w, 2);
    const double length = (double)bb__walk_number(w, 4, 0);
    if (!w->ok) return 1;
    if (w->pos + length > p->file_bytes) {
      bb__probe_corrupt(p,
                        "PSD image resource %u declares %.0f bytes at byte %.0f, past the "
                        "end of the file of %.0f bytes",
                        id, length, w->pos, p->file_bytes);
      return 0;
    }
    if ((id == 1033 || id == 1036) && length < 28) {
      bb__probe_corrupt(p, "PSD thumbnail resource %u of %.0f bytes is shorter than its header",
                        id, length);
      return 0;
    }
    if (id == 1006) { /* the alpha names, as the reader reads them */
      bb__walk names = *w;
      int32_t left = (int32_t)(uint32_t)length;
      while (left >= 2) {
        const uint64_t n = bb__walk_number(&names, 1, 0);
        if (!names.ok || names.pos + (double)n > p->file_bytes) {
          bb__probe_corrupt(p, "PSD alpha channel names (resource 1006) run past the end of "
                               "the file");
          return 0;
        }
        names.pos += (double)n;
        left -= (int32_t)(1 + n);
      }
    }
    w->pos += length + ((uint64_t)length & 1);
  }
  return 1;
}

/* |a - b| of two 32-bit coordinates, read as ints as the reader does. */
static double span(uint64_t a, uint64_t b) {
  const double d = (double)(int32_t)(uint32_t)a - (double)(int32_t)(uint32_t)b;
  return d < 0 ? -d : d;
}

/* A PSB's largest side. */
#define PSD_MAX_SIDE 300000.0

/* The channels of one layer: their records (an id and a data length,
 * `records` bytes at `at`), checked once the layer's mask is known. The
 * declared data is added to *data. 0 when the probe is corrupt. */
static int check_channels(const unsigned char *records, unsigned count, int psb, int layer,
                          double rows, double cols, double mask_rows, double mask_cols,
                          double *data, bb__probe *p) {
  const unsigned size = psb ? 10 : 6;
  for (unsigned c = 0; c < count; c++) {
    const unsigned char *r = records + (size_t)c * size;
    const int id = (int16_t)(uint16_t)(r[0] << 8 | r[1]);
    double length = 0;
    for (unsigned i = 2; i < size; i++) length = length * 256 + r[i];
    if (length <= 2) continue; /* no data: the reader allocates nothing for it */
    const double h = id == -2 ? mask_rows : rows, w = id == -2 ? mask_cols : cols;
    if (h > PSD_MAX_SIDE || w > PSD_MAX_SIDE) {
      bb__probe_corrupt(p,
                        "PSD layer %d's channel %d is %.0fx%.0f, past the largest a PSB may "
                        "be (300000 a side)",
                        layer, id, w, h);
      return 0;
    }
    if (h > length - 2) {
      bb__probe_corrupt(p, "PSD layer %d's channel %d declares %.0f rows in %.0f bytes", layer,
                        id, h, length);
      return 0;
    }
    *data += length;
  }
  return 1;
}

/* One layer record (as psdinput.cpp's load_layer reads it); w->ok cleared
 * where the reader would fail. 0 when the probe is corrupt. */
static int walk_layer(bb__walk *w, int psb, int layer, double *data, bb__probe *p) {
  const uint64_t top = bb__walk_number(w, 4, 0), left = bb__walk_number(w, 4, 0);
  const uint64_t bottom = bb__walk_number(w, 4, 0), right = bb__walk_number(w, 4, 0);
  const unsigned count = (unsigned)bb__walk_number(w, 2, 0);
  if (!w->ok) return 1;
  const size_t records = (size_t)count * (psb ? 10 : 6);
  unsigned char *r = malloc(records ? records : 1);
  if (!r || bb__probe_read(w->fd, r, records, w->pos) != records) {
    free(r);
    w->ok = 0;
    return 1;
  }
  w->pos += (double)records;
  unsigned char tag[4];
  if (!bb__walk_tag(w, tag) || memcmp(tag, "8BIM", 4) != 0) {
    free(r);
    w->ok = 0;
    return 1;
  }
  w->pos += 8; /* blend mode, opacity, clipping, flags, filler */
  uint32_t extra = (uint32_t)bb__walk_number(w, 4, 0);
  const uint32_t mask = (uint32_t)bb__walk_number(w, 4, 0);
  double mask_rows = 0, mask_cols = 0;
  if (w->ok && mask > 0) {
    const double start = w->pos;
    if (mask >= 18) {
      const uint64_t mt = bb__walk_number(w, 4, 0), ml = bb__walk_number(w, 4, 0);
      const uint64_t mb = bb__walk_number(w, 4, 0), mr = bb__walk_number(w, 4, 0);
      mask_rows = span(mb, mt), mask_cols = span(mr, ml);
    }
    w->pos = start + mask;
  }
  extra -= mask + 4;
  const uint32_t ranges = (uint32_t)bb__walk_number(w, 4, 0);
  w->pos += ranges;
  extra -= ranges + 4;
  const double name_at = w->pos;
  skip_name(w, 4);
  extra -= (uint32_t)(w->pos - name_at);
  while (w->ok && extra >= 12) { /* additional layer information */
    unsigned char key[4];
    if (!bb__walk_tag(w, tag) || !bb__walk_tag(w, key) ||
        (memcmp(tag, "8BIM", 4) != 0 && memcmp(tag, "8B64", 4) != 0)) {
      w->ok = 0;
      break;
    }
    const int wide = psb && psb_long_key(key);
    const uint64_t length = bb__walk_number(w, wide ? 8 : 4, 0);
    extra -= wide ? 16u : 12u;
    w->pos += (double)length;
    extra -= (uint32_t)length;
  }
  int fine = 1;
  if (w->ok)
    fine = check_channels(r, count, psb, layer, span(bottom, top), span(right, left), mask_rows,
                          mask_cols, data, p);
  free(r);
  return fine;
}

void bb__probe_psd(int fd, const unsigned char *head, bb__probe *p) {
  (void)head;
  p->format = "PSD";
  const double file = p->file_bytes;
  bb__walk w = {fd, file, 4, 1};
  const uint64_t version = bb__walk_number(&w, 2, 0);
  if (!w.ok || (version != 1 && version != 2)) return;
  const int psb = version == 2;
  w.pos = 26;
  const double colour = (double)bb__walk_number(&w, 4, 0);
  if (w.ok && w.pos + colour > file) {
    bb__probe_corrupt(p, "its PSD colour mode data of %.0f bytes runs past the end of the file "
                         "of %.0f bytes", colour, file);
    return;
  }
  w.pos += colour;
  const double resources = (double)bb__walk_number(&w, 4, 0);
  const double resources_end = w.pos + resources;
  if (w.ok && resources_end > file) {
    bb__probe_corrupt(p, "its PSD image resources of %.0f bytes run past the end of the file "
                         "of %.0f bytes", resources, file);
    return;
  }
  if (!w.ok || !walk_resources(&w, resources_end, p)) return;
  w.ok = 1, w.pos = resources_end;
  const double masks = (double)bb__walk_number(&w, psb ? 8 : 4, 0);
  if (!w.ok || masks == 0) return;
  if (w.pos + masks > file) {
    bb__probe_corrupt(p, "its PSD layer and mask information of %.0f bytes runs past the end "
                         "of the file of %.0f bytes", masks, file);
    return;
  }
  const double layers = (double)bb__walk_number(&w, psb ? 8 : 4, 0);
  if (!w.ok || layers == 0) return;
  int count = (int16_t)(uint16_t)bb__walk_number(&w, 2, 0);
  if (count < 0) count = -count;
  double data = 0; /* the layers' channels' declared data, which follows the records */
  for (int layer = 0; layer < count && w.ok; layer++)
    if (!walk_layer(&w, psb, layer, &data, p)) return;
  if (w.ok && w.pos + data > file)
    bb__probe_corrupt(p, "its PSD layers' channel data of %.0f bytes runs past the end of the "
                         "file of %.0f bytes", data, file);
}
