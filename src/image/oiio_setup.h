// oiio_setup.h: the process-wide OpenImageIO settings every image read and
// write of the library applies first (defined in oiio_read.cpp).
#ifndef BB_IMAGE_OIIO_SETUP_H
#define BB_IMAGE_OIIO_SETUP_H

namespace bb {

// Once per process, and only ever lowering them:
// - OpenImageIO's own guards against headers that declare absurd sizes,
//   which some readers check in open(), before bumpbake sees the header:
//   "limits:imagesize_MB" to BB_MAX_READ_BYTES, "limits:channels" to 64.
// - "exr_threads" to -1: OpenEXR without its own thread pool. OpenEXR 3.1's
//   IlmThread pool, started under memory pressure (a thread it could not
//   create), later posted to a semaphore it had freed: SIGSEGV in 28 of 80
//   bakes writing an EXR under `ulimit -v` 534..546 MB, none without the
//   pool. Without it OpenEXR's readers also keep one chunk buffer, not two
//   per thread. bumpbake writes its files in parallel itself; rock06's four
//   EXR maps took as long to write either way (0.68 s and 0.69 s, 5 runs
//   each, alternated).
void oiio_setup();

} // namespace bb

#endif // BB_IMAGE_OIIO_SETUP_H
