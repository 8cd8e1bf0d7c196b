// oiio_text.cpp: the OpenImageIO calls of text: labels drawn with
// OpenImageIO's FreeType text for the panels of pictures (text.h).
#include "core/internal.h"
#include "image/oiio_guard.h"
#include "render/text.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <string>

using OIIO::ImageSpec;
using OIIO::TypeDesc;

namespace {

// OIIO records a failed font lookup in its global error queue; read it so a
// later, unrelated OIIO error message does not carry it along.
void drop_global_error() { (void)OIIO::geterror(); }

bool text_size_of(const char *text, int size_px, const char *font, OIIO::ROI *roi) {
  *roi = OIIO::ImageBufAlgo::text_size(text, size_px, font);
  if (roi->defined()) return true;
  drop_global_error();
  return false;
}

} // namespace

extern "C" {

int bb__font_usable(const char *font) {
  if (!font || !font[0]) return 0;
  return bb::guard_value(0, [&] {
    OIIO::ROI roi;
    return text_size_of("Ag", 16, font, &roi) ? 1 : 0;
  });
}

int bb__text_width(const char *text, int size_px, const char *font) {
  if (!text || !font) return -1;
  return bb::guard_value(-1, [&] {
    OIIO::ROI roi;
    return text_size_of(text, size_px, font, &roi) ? roi.width() : -1;
  });
}

bb_status bb__text_draw(bb_image *img, int center_x, int baseline_y, const char *text,
                        int size_px, const float color[3], const char *font, bb_error *err) {
  if (!img || !img->pixels || img->channels != 3 || !text || !font || !color)
    return bb__fail(err, BB_ERR_ARGUMENT, "text: bad arguments");
  return bb::guard(err, "text", bb::DRAWING, [&] {
    // The ImageBuf wraps img's own pixels: OIIO draws straight into them.
    ImageSpec spec(img->width, img->height, 3, TypeDesc::FLOAT);
    OIIO::ImageBuf buf(spec, img->pixels);
    bool ok = OIIO::ImageBufAlgo::render_text(
        buf, center_x, baseline_y, text, size_px, font, OIIO::cspan<float>(color, 3),
        OIIO::ImageBufAlgo::TextAlignX::Center, OIIO::ImageBufAlgo::TextAlignY::Baseline, 0,
        OIIO::ROI(), 1);
    if (!ok) {
      std::string why = buf.geterror();
      drop_global_error();
      return bb__fail(err, BB_ERR_FORMAT, "text: cannot draw '%s' with font %s: %s", text,
                      font, bb::one_line(why).c_str());
    }
    return BB_OK;
  });
}

} // extern "C"
