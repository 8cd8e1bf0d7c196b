/* signatures.c: the signatures that open the image formats OpenImageIO
 * reads, from each format's specification, and what messages call each
 * format.
 *
 * OpenImageIO picks a reader by the file's extension and, when that reader
 * refuses the file, tries every other reader in turn; some of those (the
 * DICOM, PNM and IFF readers of OpenImageIO 2.4) read a file that is not
 * theirs to its end, so a large file that no reader recognises took
 * minutes. bumpbake asks this table instead: a reader whose format has a
 * signature here is handed only files carrying it, and when the
 * extension's reader refuses a file, the one other reader tried is the one
 * its first bytes name. Formats without a signature (TGA, camera raw, RLA,
 * video) are left to their extension's reader alone. */
#include "image/signatures.h"

#include <string.h>

typedef struct signature {
  unsigned offset; /* where in the file the bytes start */
  const char *bytes;
  unsigned length;
} signature;

typedef struct known_format {
  const char *format; /* OpenImageIO's name for it */
  const char *display;
  signature signatures[8]; /* any one of them; { 0, NULL, 0 } ends the list */
} known_format;

#define SIG(off, text)                                                                   \
  { (off), (text), (unsigned)(sizeof(text) - 1) }

static const known_format FORMATS[] = {
    {"png", "PNG", {SIG(0, "\x89PNG\r\n\x1a\n")}},
    {"jpeg", "JPEG", {SIG(0, "\xff\xd8\xff")}},
    {"tiff",
     "TIFF",
     {SIG(0, "II*\0"), SIG(0, "MM\0*"), SIG(0, "II+\0"), SIG(0, "MM\0+")}},
    {"openexr", "OpenEXR", {SIG(0, "\x76\x2f\x31\x01")}},
    {"gif", "GIF", {SIG(0, "GIF87a"), SIG(0, "GIF89a")}},
    {"hdr", "Radiance HDR", {SIG(0, "#?")}},
    {"dds", "DDS", {SIG(0, "DDS ")}},
    {"bmp", "BMP", {SIG(0, "BM")}},
    {"psd", "PSD", {SIG(0, "8BPS")}},
    {"pnm",
     "PNM",
     {SIG(0, "P1"), SIG(0, "P2"), SIG(0, "P3"), SIG(0, "P4"), SIG(0, "P5"), SIG(0, "P6"),
      SIG(0, "PF"), SIG(0, "Pf")}},
    {"iff", "IFF", {SIG(0, "FOR4")}},
    {"dicom", "DICOM", {SIG(128, "DICM")}},
    {"sgi", "SGI", {SIG(0, "\x01\xda")}},
    {"softimage", "Softimage PIC", {SIG(0, "\x53\x80\xf6\x34")}},
    {"cineon", "Cineon", {SIG(0, "\x80\x2a\x5f\xd7"), SIG(0, "\xd7\x5f\x2a\x80")}},
    {"dpx", "DPX", {SIG(0, "SDPX"), SIG(0, "XPDS")}},
    {"fits", "FITS", {SIG(0, "SIMPLE  =")}},
    {"webp", "WebP", {SIG(8, "WEBP")}},
    {"heif", "HEIF", {SIG(4, "ftyp")}},
    {"jpeg2000",
     "JPEG 2000",
     {SIG(0, "\0\0\0\x0cjP  \r\n\x87\n"), SIG(0, "\xff\x4f\xff\x51")}},
    {"ico", "ICO", {SIG(0, "\0\0\1\0")}},
    {"zfile", "Zfile", {SIG(0, "\xab\x67\x08\x2f"), SIG(0, "\x2f\x08\x67\xab")}},
    /* No signature: the extension's reader alone decides. */
    {"targa", "TGA", {{0, NULL, 0}}},
    {"raw", "camera raw", {{0, NULL, 0}}},
    {"rla", "RLA", {{0, NULL, 0}}},
};

#define FORMAT_COUNT (sizeof FORMATS / sizeof FORMATS[0])

static const known_format *find(const char *format) {
  if (!format)
    return NULL;
  for (size_t i = 0; i < FORMAT_COUNT; i++)
    if (strcmp(FORMATS[i].format, format) == 0)
      return &FORMATS[i];
  return NULL;
}

static int carries(const known_format *f, const unsigned char *head, unsigned long n) {
  for (size_t s = 0; s < sizeof f->signatures / sizeof f->signatures[0]; s++) {
    const signature *sig = &f->signatures[s];
    if (!sig->bytes)
      break;
    if (sig->offset + sig->length <= n &&
        memcmp(head + sig->offset, sig->bytes, sig->length) == 0)
      return 1;
  }
  return 0;
}

const char *bb__format_by_content(const unsigned char *head, unsigned long n) {
  for (size_t i = 0; i < FORMAT_COUNT; i++)
    if (carries(&FORMATS[i], head, n))
      return FORMATS[i].format;
  return NULL;
}

int bb__format_has_signature(const char *format) {
  const known_format *f = find(format);
  return f && f->signatures[0].bytes != NULL;
}

const char *bb__format_display_name(const char *format) {
  const known_format *f = find(format);
  return f ? f->display : format;
}
