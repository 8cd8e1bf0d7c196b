/* text.h: labels drawn through OpenImageIO's FreeType text
 * (oiio_text.cpp), for the panels of pictures. */
#ifndef BB_RENDER_TEXT_H
#define BB_RENDER_TEXT_H

#include "bumpbake.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Text through OpenImageIO (oiio_text.cpp). font is a font file or a name
 * OpenImageIO searches for (its font path and /usr/share/fonts). */
/* 1 when OpenImageIO can draw text with font. */
int bb__font_usable(const char *font);
/* Width in pixels of text at size_px, or -1 when it cannot be measured. */
int bb__text_width(const char *text, int size_px, const char *font);
/* Draws text into a 3-channel img, centred on center_x, its baseline at
 * baseline_y (so labels with and without descenders line up). */
bb_status bb__text_draw(bb_image *img, int center_x, int baseline_y, const char *text,
                        int size_px, const float color[3], const char *font, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_RENDER_TEXT_H */
