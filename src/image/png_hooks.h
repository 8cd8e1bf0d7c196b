/* png_hooks.h: what the library sets on OpenImageIO's libpng structs:
 * quiet errors, bounded allocations (png_hooks.c). */
#ifndef BB_IMAGE_PNG_HOOKS_H
#define BB_IMAGE_PNG_HOOKS_H

#ifdef __cplusplus
extern "C" {
#endif

/* 1 once a libpng error handler of OpenImageIO's has been wrapped. Every
 * image read calls it, which is what links png_hooks.c into a static
 * program. */
int bb__png_hooks_set(void);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_PNG_HOOKS_H */
