// oiio_read.cpp: the OpenImageIO calls of every image read: opening a file,
// its header, its pixels band by band, its mip levels and its frames. The
// limits a read applies are C (read_limits.c), decided from the header this
// file hands them; the public reads are image_read.c.
//
// Alpha is never premultiplied or divided out: bumpbake's channels are data
// (heights, ssbump, ao), so reads ask for unassociated alpha.
#include "core/input_file.h"
#include "core/internal.h"
#include "core/sanitizer_options.h"
#include "image/description.h"
#include "image/formats.h"
#include "image/header_probe.h"
#include "image/oiio_calls.h"
#include "image/oiio_guard.h"
#include "image/oiio_setup.h"
#include "image/read_limits.h"
#include "image/signatures.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <unistd.h>

#ifdef BB_ASAN_BUILD
#include <sanitizer/lsan_interface.h>
#endif

using OIIO::ImageInput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

namespace {

constexpr long MiB = 1L << 20;

// OpenImageIO's own guard on an image's samples: the most any read may
// take, BB_MAX_READ_BYTES_PER_TEXEL bytes for each of BB_MAX_PIXELS texels.
constexpr double oiio_imagesize_limit() {
  return (double)BB_MAX_PIXELS * BB_MAX_READ_BYTES_PER_TEXEL;
}

// OIIO's refusal under its limits spans two lines and tells the reader to
// raise an OIIO attribute, which a bumpbake user cannot: keep the first line.
bool is_limit_refusal(const std::string &why) {
  return why.find("limits:imagesize_MB") != std::string::npos ||
         why.find("limits:channels") != std::string::npos;
}

// In sanitizer builds, allocations made while OpenImageIO's PNG reader
// opens or decodes a file (in this thread) are not leaks to LeakSanitizer:
// its one known leak is not ours (see sanitizer_options.h). Whether the
// file is a PNG is asked of OpenImageIO's PNG reader (its signature check),
// since OpenImageIO picks readers by content too. Release builds skip all
// of this.
class OiioPngLeakScope {
public:
  explicit OiioPngLeakScope(bool png) : active_(png) {
#ifdef BB_ASAN_BUILD
    if (active_) __lsan_disable();
#endif
  }
  ~OiioPngLeakScope() {
#ifdef BB_ASAN_BUILD
    if (active_) __lsan_enable();
#endif
  }
  OiioPngLeakScope(const OiioPngLeakScope &) = delete;
  OiioPngLeakScope &operator=(const OiioPngLeakScope &) = delete;

  static bool applies_to(const char *path) {
#ifdef BB_ASAN_BUILD
    auto png = ImageInput::create("png");
    return png && png->valid_file(path);
#else
    (void)path;
    return false;
#endif
  }

private:
  bool active_;
};

// The file a read checked (bb__input_open: a regular file, opened without
// blocking), as the IOProxy OpenImageIO's readers read through, so the file
// checked is the file read. It is an IOFile over that descriptor (the
// JPEG reader takes no other kind of proxy) that keeps the file's name for
// messages and closes the descriptor itself, once, when it goes.
class CheckedInput final : public OIIO::Filesystem::IOFile {
public:
  CheckedInput(FILE *file, const char *path) : IOFile(file, Read), file_(file) {
    m_filename = path;
  }
  ~CheckedInput() override { std::fclose(file_); }
  void close() override {} // readers never own it; the destructor closes
  CheckedInput(const CheckedInput &) = delete;
  CheckedInput &operator=(const CheckedInput &) = delete;

private:
  FILE *file_;
};

// Opens path as a CheckedInput: a missing file, a directory, a FIFO or a
// device is refused before any reader sees it (one would block on a FIFO
// and spin on /dev/zero), and so is a header that would make its reader
// allocate more than the limits in open() (header_probe.h), or, when
// `reading` pixels, declare more than a read accepts.
std::unique_ptr<CheckedInput> open_checked(const char *path, bool reading, bb_status *st,
                                           bb_error *err) {
  int fd;
  *st = bb__input_open(path, &fd, err);
  if (*st != BB_OK) return nullptr;
  bb__probe probe;
  *st = bb__probe_header(fd, path, &probe, err);
  if (*st == BB_OK) *st = bb__read_check_probe(path, &probe, reading ? 1 : 0, err);
  if (*st != BB_OK) {
    close(fd);
    return nullptr;
  }
  FILE *file = fdopen(fd, "rb");
  if (!file) {
    int e = errno;
    close(fd);
    *st = bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, std::strerror(e));
    return nullptr;
  }
  std::unique_ptr<FILE, int (*)(FILE *)> until_owned(file, std::fclose);
  std::unique_ptr<CheckedInput> checked(new CheckedInput(file, path));
  until_owned.release(); // the CheckedInput closes it now
  return checked;
}

// An opened input, the checked file it reads (which must outlive it), and
// whether it is read by OpenImageIO's PNG reader.
struct opened_input {
  std::unique_ptr<CheckedInput> file;
  std::unique_ptr<ImageInput> in; // declared after file: destroyed before it
  bool png = false;
};

// The OpenImageIO format whose reader path's extension names ("" when none
// does), from OpenImageIO's own list of its readers' extensions.
std::string format_of_extension(const char *path) {
  static const std::map<std::string, std::string> formats = [] {
    std::map<std::string, std::string> m;
    // "openexr:exr,sxr;tiff:tif,tiff;...": each format and its extensions.
    for (const std::string &entry :
         OIIO::Strutil::splits(OIIO::get_string_attribute("extension_list"), ";")) {
      const size_t colon = entry.find(':');
      if (colon == std::string::npos)
        continue;
      const std::string format = entry.substr(0, colon);
      for (const std::string &ext : OIIO::Strutil::splits(entry.substr(colon + 1), ","))
        m.emplace(ext, format);
    }
    return m;
  }();
  char ext[32];
  bb__extension_of(path, ext, sizeof ext);
  if (!ext[0])
    return std::string();
  auto it = formats.find(ext + 1);
  return it == formats.end() ? std::string() : it->second;
}

// The format the first bytes of the checked file name ("" when none).
std::string format_of_content(CheckedInput &file) {
  unsigned char head[BB_SIGNATURE_BYTES];
  const size_t n = file.pread(head, sizeof head, 0);
  const char *format = bb__format_by_content(head, n);
  return format ? format : std::string();
}

// Opens the checked file with format's reader alone (never OpenImageIO's
// walk through every reader when one refuses), through the descriptor
// where the reader reads proxies, else by the name, checked a moment
// before. nullptr and the reader's reason in *why when it refuses.
std::unique_ptr<ImageInput> open_as(const std::string &format, const char *path,
                                    CheckedInput &file, bool png, std::string *why) {
  std::unique_ptr<ImageInput> in = ImageInput::create(format); // by name: reads nothing
  if (!in) {
    *why = OIIO::geterror();
    return nullptr;
  }
  if (in->supports("ioproxy") && !in->set_ioproxy(&file)) {
    *why = in->geterror();
    return nullptr;
  }
  file.seek(0);
  ImageSpec config, spec;
  config.attribute("oiio:UnassociatedAlpha", 1);
  bool ok;
  {
    OiioPngLeakScope png_leak(png);
    ok = in->open(path, spec, config);
  }
  if (!ok) {
    *why = in->geterror();
    if (why->empty())
      *why = OIIO::geterror();
    return nullptr;
  }
  return in;
}

// Opens path through its checked descriptor, for `reading` pixels or only
// headers, and makes OpenImageIO's refusals one line. The extension's
// reader reads the file unless the file lacks that format's signature;
// when it refuses, the reader the file's first bytes name (a PNG named
// .tga) is the one other tried. A file neither names is refused at once,
// naming the format its extension promised.
opened_input open_input(const char *path, bool reading, bb_status *st, bb_error *err) {
  opened_input opened;
  opened.file = open_checked(path, reading, st, err);
  if (!opened.file)
    return opened;
  bb::oiio_setup();
  opened.png = OiioPngLeakScope::applies_to(path);
  const std::string promised = format_of_extension(path);
  const std::string content = format_of_content(*opened.file);
  std::string why;
  if (!promised.empty() &&
      (content == promised || !bb__format_has_signature(promised.c_str())))
    opened.in = open_as(promised, path, *opened.file, opened.png, &why);
  if (!opened.in && !content.empty() && content != promised) {
    std::string why_content;
    opened.in = open_as(content, path, *opened.file, opened.png, &why_content);
    if (why.empty())
      why = why_content;
  }
  if (opened.in)
    return opened;
  if (is_limit_refusal(why)) {
    *st =
        bb__fail(err, BB_ERR_SIZE,
                 "%s: too large to read: %s (bumpbake reads at most %.0f MiB of samples)",
                 path, bb::first_line(why).c_str(), oiio_imagesize_limit() / (double)MiB);
  } else if (!content.empty()) {
    *st = bb__fail(err, BB_ERR_FORMAT, "%s: not a readable image: %s", path,
                   bb::one_line(why).c_str());
  } else if (promised.empty()) {
    char ext[32];
    bb__extension_of(path, ext, sizeof ext);
    if (ext[0])
      *st = bb__fail(
          err, BB_ERR_FORMAT,
          "%s: not a readable image: no image format has the extension '%s', and "
          "its first bytes name none",
          path, ext);
    else
      *st = bb__fail(
          err, BB_ERR_FORMAT,
          "%s: not a readable image: no extension names its format, and its first "
          "bytes name none",
          path);
  } else {
    const char *name = bb__format_display_name(promised.c_str());
    if (why.empty())
      *st = bb__fail(
          err, BB_ERR_FORMAT,
          "%s: not a readable image: its extension says %s, but it does not carry "
          "%s's signature, nor any other format's",
          path, name, name);
    else
      *st = bb__fail(err, BB_ERR_FORMAT,
                     "%s: not a readable image: its extension says %s, but the %s reader "
                     "refuses it (%s), and its first bytes name no other format",
                     path, name, name, bb::one_line(why).c_str());
  }
  return opened;
}

// What the limits of read_limits.c need of a spec. format points into spec.
bb__image_header header_of(const ImageSpec &spec) {
  bb__image_header h;
  h.width = spec.width;
  h.height = spec.height;
  h.channels = spec.nchannels;
  h.depth = spec.depth;
  h.deep = spec.deep ? 1 : 0;
  h.tile_width = spec.tile_width;
  h.tile_height = spec.tile_height;
  h.file_bytes = (double)spec.image_bytes(true);
  h.sample_bytes = (int)spec.format.size();
  for (const TypeDesc &t : spec.channelformats)
    if ((int)t.size() > h.sample_bytes) h.sample_bytes = (int)t.size();
  h.format = spec.format.c_str();
  return h;
}

bb_status fill_info(const ImageInput &in, const ImageSpec &spec, bb_image_info *info,
                    const char *path, bb_error *err) {
  if (!info) return BB_OK;
  info->alpha_channel = spec.alpha_channel;
  info->is_float = spec.format.is_floating_point() ? 1 : 0;
  // oiio:BitsPerSample tells 1-, 2-, 4-, 10- or 12-bit files from their carrier type.
  info->bits_per_sample =
      spec.get_int_attribute("oiio:BitsPerSample", (int)spec.format.size() * 8);
  std::snprintf(info->format_name, sizeof info->format_name, "%s", in.format_name());
  std::string desc = spec.get_string_attribute("ImageDescription");
  if (!desc.empty()) {
    info->description = static_cast<char *>(std::malloc(desc.size() + 1));
    if (!info->description)
      return bb__fail(err, BB_ERR_MEMORY, "%s: cannot allocate the description", path);
    std::memcpy(info->description, desc.c_str(), desc.size() + 1);
    info->description =
        bb__description_join(in.format_name(), info->description,
                             spec.get_string_attribute("targa:ImageID").c_str());
    bb__description_as_read(in.format_name(), info->description);
  }
  return BB_OK;
}

// Decodes channels [first, first + out->channels) into out, band by band.
// A truncated file must fail, not come back as zeros: both the return value
// and the error queue are checked, since some readers only record a warning.
std::string read_bands(ImageInput &in, bool png, int miplevel, const ImageSpec &spec,
                       int first, bb_image *out) {
  const bb__image_header h = header_of(spec);
  const int band = bb__read_band_rows(&h, out->channels);
  const size_t row_floats = (size_t)spec.width * (size_t)out->channels;
  for (int y = 0; y < spec.height; y += band) {
    const int rows = spec.height - y < band ? spec.height - y : band;
    float *dst = out->pixels + (size_t)y * row_floats;
    const int y0 = spec.y + y, y1 = spec.y + y + rows;
    OiioPngLeakScope png_leak(png);
    bool ok = spec.tile_width > 0
                  ? in.read_tiles(0, miplevel, spec.x, spec.x + spec.width, y0, y1, spec.z,
                                  spec.z + 1, first, first + out->channels, TypeDesc::FLOAT,
                                  dst)
                  : in.read_scanlines(0, miplevel, y0, y1, spec.z, first,
                                      first + out->channels, TypeDesc::FLOAT, dst);
    if (!ok || in.has_error()) {
      std::string why = in.geterror();
      return why.empty() ? std::string("read failed") : why;
    }
  }
  return std::string();
}

// Mip levels of subimage 0 of an opened file, from its headers.
int count_levels(ImageInput &in) {
  int levels = 0;
  while (in.seek_subimage(0, levels)) levels++;
  (void)in.geterror(); // the failed seek past the last level queued a message
  return levels;
}

bb_status read_image(const char *path, int first, int count, int level, bb_image *out,
                     bb_image_info *info, int *level_count, bb_error *err) {
  bb_status st;
  opened_input opened = open_input(path, true, &st, err);
  if (!opened.in) return st;
  ImageInput *in = opened.in.get();
  if (level_count || level != 0) {
    const int levels = count_levels(*in);
    if (level_count) *level_count = levels;
    if (level < 0 || level >= levels)
      return bb__fail(err, BB_ERR_ARGUMENT, "%s: no mip level %d (the file has %d)", path,
                      level, levels);
    if (!in->seek_subimage(0, level))
      return bb__fail(err, BB_ERR_FORMAT, "%s: %s", path, bb::one_line(in->geterror()).c_str());
  }
  const ImageSpec spec = in->spec();
  if (count < 0) {
    first = 0;
    count = spec.nchannels;
  }
  const bb__image_header h = header_of(spec);
  st = bb__read_check_size(path, &h, count, err);
  if (st != BB_OK) return st;
  if (first < 0 || count < 1 || first + count > spec.nchannels)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: channels %d..%d asked of a %d-channel image",
                    path, first, first + count - 1, spec.nchannels);

  bb_error alloc_err;
  st = bb_image_alloc(out, spec.width, spec.height, count, &alloc_err);
  if (st != BB_OK) return bb__fail(err, st, "%s: %s", path, alloc_err.message);

  std::string why = read_bands(*in, opened.png, level, spec, first, out);
  if (!why.empty())
    return bb__fail(err, BB_ERR_FORMAT, "%s: corrupt or truncated image: %s", path,
                    bb::one_line(bb::first_line(why)).c_str());
  return fill_info(*in, spec, info, path, err);
}

} // namespace

namespace bb {

void oiio_setup() {
  static std::once_flag once;
  std::call_once(once, [] {
    int mb = 0, channels = 0, exr_threads = 0;
    const int our_mb = (int)(oiio_imagesize_limit() / MiB);
    if (!OIIO::getattribute("limits:imagesize_MB", mb) || mb <= 0 || mb > our_mb)
      OIIO::attribute("limits:imagesize_MB", our_mb);
    if (!OIIO::getattribute("limits:channels", channels) || channels <= 0 || channels > 64)
      OIIO::attribute("limits:channels", 64);
    if (!OIIO::getattribute("exr_threads", exr_threads) || exr_threads != -1)
      OIIO::attribute("exr_threads", -1);
  });
}

} // namespace bb

extern "C" {

bb_status bb__oiio_read(const char *path, int first, int count, int level, bb_image *out,
                        bb_image_info *info, int *level_count, bb_error *err) {
  return bb::guard(err, path, bb::READING, [&] {
    return read_image(path, first, count, level, out, info, level_count, err);
  });
}

bb_status bb__oiio_read_header(const char *path, int *width, int *height, int *channels,
                               bb_image_info *info, bb_error *err) {
  return bb::guard(err, path, bb::READING, [&] {
    bb_status st;
    opened_input opened = open_input(path, false, &st, err);
    if (!opened.in) return st;
    const ImageSpec &spec = opened.in->spec();
    const bb__image_header h = header_of(spec);
    st = bb__read_check_shape(path, &h, err);
    if (st != BB_OK) return st;
    if (width) *width = spec.width;
    if (height) *height = spec.height;
    if (channels) *channels = spec.nchannels;
    return fill_info(*opened.in, spec, info, path, err);
  });
}

bb_status bb__oiio_level_count(const char *path, int *levels, bb_error *err) {
  return bb::guard(err, path, bb::READING, [&] {
    bb_status st;
    opened_input opened = open_input(path, false, &st, err);
    if (!opened.in) return st;
    *levels = count_levels(*opened.in);
    return BB_OK;
  });
}

bb_status bb__oiio_frame_count(const char *path, int *frames, bb_error *err) {
  return bb::guard(err, path, bb::READING, [&] {
    bb_status st;
    opened_input opened = open_input(path, false, &st, err);
    if (!opened.in) return st;
    int n = 0;
    while (n < 1000000 && opened.in->seek_subimage(n, 0)) n++;
    (void)opened.in->geterror(); // seeking past the last subimage records an error
    *frames = n;
    return BB_OK;
  });
}

bb_status bb__oiio_samples_as_read(const void *samples, int depth, size_t n, float *out,
                                   bb_error *err) {
  return bb::guard(err, "samples", bb::READING, [&] {
    // OpenImageIO's own conversions, in pieces of an int's count: the
    // floats a read of such a file hands back (codes scaled by 1 / max
    // code; half floats widened), and a write's float-to-half rounding.
    const TypeDesc stored = depth == BB_DEPTH_8    ? TypeDesc::UINT8
                            : depth == BB_DEPTH_16 ? TypeDesc::UINT16
                                                   : TypeDesc::HALF;
    const size_t piece = (size_t)1 << 28;
    std::unique_ptr<std::uint16_t[]> halves;
    if (depth == BB_DEPTH_HALF) halves.reset(new std::uint16_t[n < piece ? n : piece]);
    for (size_t at = 0; at < n; at += piece) {
      const int count = (int)(n - at < piece ? n - at : piece);
      bool ok;
      if (depth == BB_DEPTH_HALF) {
        ok = OIIO::convert_pixel_values(TypeDesc::FLOAT, (const float *)samples + at,
                                        TypeDesc::HALF, halves.get(), count) &&
             OIIO::convert_pixel_values(TypeDesc::HALF, halves.get(), TypeDesc::FLOAT,
                                        out + at, count);
      } else {
        const char *from = (const char *)samples + at * stored.size();
        ok = OIIO::convert_pixel_values(stored, from, TypeDesc::FLOAT, out + at, count);
      }
      if (!ok) return bb__fail(err, BB_ERR_FORMAT, "samples: cannot convert them");
    }
    return BB_OK;
  });
}

char *bb__oiio_extension_list(void) {
  return bb::guard_value<char *>(nullptr, []() -> char * {
    const std::string list = OIIO::get_string_attribute("extension_list");
    char *copy = static_cast<char *>(std::malloc(list.size() + 1));
    if (copy) std::memcpy(copy, list.c_str(), list.size() + 1);
    return copy;
  });
}

} // extern "C"
