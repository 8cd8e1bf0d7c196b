// oiio_gif.cpp: the OpenImageIO calls of writing a GIF animation frame by
// frame through the staged write (oiio_proxy.h). The checks of an
// animation's arguments are C (animation.c).
#include "core/internal.h"
#include "image/oiio_calls.h"
#include "image/oiio_guard.h"
#include "image/oiio_setup.h"
#include "image/oiio_proxy.h"
#include "image/quantise.h"
#include "image/oiio.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <string>

using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

// The GIF being written: OIIO's writer writes the frames through a
// StagedOutput into a staged temporary; the final name appears only once
// bb__animation_close has checked the file.
struct bb_animation {
  std::string path;
  bb_staged_file file; // the temporary; discarded unless committed
  std::unique_ptr<OIIO::Filesystem::IOProxy> proxy; // outlives out
  std::unique_ptr<ImageOutput> out;
  ImageSpec spec;
  int frames = 0;
};

namespace {

// Closes and frees a; a temporary still staged is removed (after a commit
// there is none).
void animation_destroy(bb_animation *a) {
  if (!a) return;
  bb::guard_value(false, [&] { return a->out && a->out->close(); });
  a->out.reset();
  bb__safe_discard(&a->file);
  delete a;
}

bb_status animation_open(const char *path, int width, int height, double fps,
                         bb_animation **out, bb_error *err) {
  std::unique_ptr<bb_animation> a(new bb_animation);
  a->path = path;
  bb_status st = bb__safe_open(&a->file, path, err);
  if (st != BB_OK) return st; // nothing was staged
  // From here on animation_destroy frees it, whatever happens.
  bb_animation *raw = a.release();
  struct destroy_on_failure {
    bb_animation *a;
    ~destroy_on_failure() { animation_destroy(a); }
  } pending{raw};
  raw->proxy.reset(new bb::StagedOutput(&raw->file, raw->file.temp_path));
  raw->out = ImageOutput::create(raw->file.temp_path, raw->proxy.get());
  if (!raw->out || !raw->out->supports("ioproxy")) {
    std::string why = raw->out ? std::string("the GIF writer cannot write through a checked output")
                               : bb::one_line(OIIO::geterror());
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, why.c_str());
  }
  raw->spec = ImageSpec(width, height, 3, TypeDesc::UINT8);
  // GIF delays are in 1/100 s: a rational of 100 / delay is what OIIO reads.
  int per_second[2] = {100, (int)std::lround(100.0 / fps)};
  raw->spec.attribute("FramesPerSecond", OIIO::TypeRational, per_second);
  raw->spec.attribute("gif:LoopCount", 0); // loop forever
  pending.a = nullptr;
  *out = raw;
  return BB_OK;
}

bb_status animation_add(bb_animation *a, const bb_image *frame, bb_error *err) {
  const char *path = a->path.c_str();
  if (!frame || !frame->pixels || frame->channels != 3 || frame->width != a->spec.width ||
      frame->height != a->spec.height)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: frames must be 3-channel %dx%d images", path,
                    a->spec.width, a->spec.height);
  ImageOutput::OpenMode mode = a->frames == 0 ? ImageOutput::Create : ImageOutput::AppendSubimage;
  std::unique_ptr<std::uint8_t, void (*)(void *)> codes(bb__quantise_8(frame, BB_RANGE_UNIT),
                                                       std::free);
  if (!codes) throw std::bad_alloc();
  if (!a->out->open(a->file.temp_path, a->spec, mode) ||
      !a->out->write_image(TypeDesc::UINT8, codes.get()))
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path,
                    bb::one_line(a->out->geterror()).c_str());
  a->frames++;
  return BB_OK;
}

// OIIO 2.4's GIF writer does not report a failed fwrite; the checked output
// does (bb__safe_finish), and the finished temporary is read back as well:
// a short file has fewer frames or none.
bb_status animation_close(bb_animation *a, bb_error *err) {
  const char *path = a->path.c_str();
  if (a->frames == 0) return bb__fail(err, BB_ERR_ARGUMENT, "%s: no frames to write", path);
  bool closed = a->out->close();
  std::string why = a->out->geterror();
  a->out.reset();
  if (!closed && !a->file.error)
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, bb::one_line(why).c_str());
  bb_status st = bb__safe_finish(&a->file, err);
  if (st != BB_OK) return st;
  int frames = 0;
  bb_error read_err;
  // A GIF: counted by this module's read, as bb__image_frame_count would.
  if (bb__oiio_frame_count(a->file.temp_path, &frames, &read_err) != BB_OK ||
      frames != a->frames)
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: the file holds %d of %d frames", path,
                    frames, a->frames);
  return bb__safe_commit(&a->file, err);
}

} // namespace

extern "C" {

bb_status bb__oiio_gif_open(const char *path, int width, int height, double frames_per_second,
                            bb_animation **out, bb_error *err) {
  return bb::guard(err, path, bb::WRITING, [&] {
    bb::oiio_setup();
    return animation_open(path, width, height, frames_per_second, out, err);
  });
}

bb_status bb__oiio_gif_add(bb_animation *a, const bb_image *frame, bb_error *err) {
  if (!a || !a->out) return bb__fail(err, BB_ERR_ARGUMENT, "bb__animation_add_frame: not open");
  return bb::guard(err, a->path.c_str(), bb::WRITING,
                   [&] { return animation_add(a, frame, err); });
}

bb_status bb__oiio_gif_close(bb_animation *a, bb_error *err) {
  bb_status st =
      bb::guard(err, a->path.c_str(), bb::WRITING, [&] { return animation_close(a, err); });
  animation_destroy(a);
  return st;
}

void bb__oiio_gif_abort(bb_animation *a) { animation_destroy(a); }

} // extern "C"
