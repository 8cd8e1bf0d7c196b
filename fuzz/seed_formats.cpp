// seed_formats.cpp: make_seeds' writer of the formats bumpbake itself does
// not write (JPEG, BMP, PNM, GIF, HDR, DPX, JPEG 2000, WebP, SGI, ICO...),
// through OpenImageIO, so the load fuzzer starts from a valid file of every
// format OpenImageIO reads here. A fuzzing tool, not part of the library.
#include <OpenImageIO/imageio.h>

#include <string>

extern "C" int seed_write(const char *path, const float *pixels, int width, int height,
                          int channels, const char *flag);

// Writes pixels (width x height x channels floats in [0, 1]) to path in the
// format its extension names, as 8-bit samples (float for HDR), with the
// integer attribute flag set to 1 when not NULL ("jpeg:progressive"); 0 on
// success, -1 when the format refuses this image (GIF wants RGB, say).
extern "C" int seed_write(const char *path, const float *pixels, int width, int height,
                          int channels, const char *flag) {
  try {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) {
      (void)OIIO::geterror();
      return -1;
    }
    const bool is_float = std::string(out->format_name()) == "hdr";
    OIIO::ImageSpec spec(width, height, channels,
                         is_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    if (flag) spec.attribute(flag, 1);
    bool ok = out->open(path, spec) && out->write_image(OIIO::TypeDesc::FLOAT, pixels);
    ok = out->close() && ok;
    (void)out->geterror();
    return ok ? 0 : -1;
  } catch (...) {
    return -1;
  }
}
