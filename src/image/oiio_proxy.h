// oiio_proxy.h: the OpenImageIO IOProxy every writer of the image family's
// C++ files encodes through, and the staged write around it
// (oiio_write.cpp).
#ifndef BB_IMAGE_OIIO_PROXY_H
#define BB_IMAGE_OIIO_PROXY_H

#include "bumpbake.h"
#include "files/safe_file.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <functional>
#include <string>

namespace bb {

// An OpenImageIO output proxy over a bb_staged_file: every byte an encoder
// produces goes through bumpbake's checked, buffered writes (safe_file.h),
// whatever the encoder itself does with a failed write.
class StagedOutput final : public OIIO::Filesystem::IOProxy {
public:
  StagedOutput(bb_staged_file *file, const std::string &name)
      : IOProxy(name, Write), file_(file) {}
  const char *proxytype() const override { return "bumpbake-safe"; }
  void close() override {} // bb__safe_finish closes, checked
  int64_t tell() override { return bb__safe_tell(file_); }
  bool seek(int64_t offset) override { return bb__safe_seek(file_, offset) == 0; }
  size_t read(void *buf, size_t size) override { return bb__safe_read(file_, buf, size); }
  size_t write(const void *buf, size_t size) override {
    return bb__safe_write(file_, buf, size);
  }
  size_t pread(void *buf, size_t size, int64_t offset) override {
    return bb__safe_pread(file_, buf, size, offset);
  }
  size_t pwrite(const void *buf, size_t size, int64_t offset) override {
    return bb__safe_pwrite(file_, buf, size, offset);
  }
  size_t size() const override { return (size_t)bb__safe_size(file_); }
  void flush() const override {} // bb__safe_finish flushes and fsyncs

private:
  bb_staged_file *file_;
};

// What an encoder does: create an ImageOutput for name (its extension picks
// the format) that writes through proxy (ImageOutput::create(name, proxy)),
// open, write and close it, and return "" or OpenImageIO's reason.
using encoder_fn =
    std::function<std::string(const std::string &name, OIIO::Filesystem::IOProxy *proxy)>;

// THE way an OpenImageIO writer puts a file on disk; every writer calls it
// (mip-mapped TIFFs aside, see oiio_mips.cpp). It opens a bb_staged_file
// for path, runs encode through a StagedOutput, and then either finishes the
// file (flushed, fsynced, closed: complete under its temporary name, for the
// caller to bb__safe_commit or bb__safe_discard) or removes it and returns
// BB_ERR_IO. A failed write is reported with the system's reason ("No space
// left on device") even when the encoder claimed success.
bb_status write_staged(const char *path, const encoder_fn &encode, bb_staged_file *f,
                       bb_error *err);

// The sample type of a file of depth.
OIIO::TypeDesc file_type_of(bb_depth depth);

// What every file bumpbake writes carries besides its pixels (unassociated
// alpha, Software, no DateTime) and the channel names of a basis of more
// than 4 directions (formats.h).
void set_common_attributes(OIIO::ImageSpec &spec);

} // namespace bb

#endif // BB_IMAGE_OIIO_PROXY_H
