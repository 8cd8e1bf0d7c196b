/* signatures.h: which OpenImageIO reader a file is for, told by its first
 * bytes, so that no reader is handed a file that cannot be its own
 * (signatures.c). */
#ifndef BB_IMAGE_SIGNATURES_H
#define BB_IMAGE_SIGNATURES_H

#ifdef __cplusplus
extern "C" {
#endif

/* The bytes bb__format_by_content looks at: a file's first ones. */
#define BB_SIGNATURE_BYTES 132

/* The OpenImageIO format ("png", "tiff", "openexr"...) whose signature the
 * first n bytes of a file (head) carry, or NULL when they carry none of
 * the signatures known here. */
const char *bb__format_by_content(const unsigned char *head, unsigned long n);

/* 1 when format (an OpenImageIO format name) is known by a signature, so a
 * file without it is not of that format and its reader need not look. */
int bb__format_has_signature(const char *format);

/* What messages call format: "PNG", "TGA", "OpenEXR"; format itself when
 * the table does not name it. */
const char *bb__format_display_name(const char *format);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_SIGNATURES_H */
