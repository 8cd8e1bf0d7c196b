// exr_pool.h: OpenEXR's chunks compressed on the writing job's threads
// (exr_pool.cpp, the one file that uses OpenEXR's IlmThread library).
#ifndef BB_IO_EXR_POOL_H
#define BB_IO_EXR_POOL_H

namespace bb {

// While one lives, OpenEXR files opened and written on this thread (through
// OpenImageIO) compress their chunks on up to `threads` worker threads (0 =
// all cores) of bumpbake's own provider for OpenEXR's global thread pool,
// installed at the first one. Reads, and writes on any other thread, see a
// pool of no threads, as with OpenImageIO's "exr_threads" -1.
//
// Why a provider of our own: OpenEXR 3.1's default pool, started short of
// memory (a thread it could not create: `ulimit -v` 534..546 MB), left its
// started threads waiting on a semaphore it had freed (SIGSEGV in 28 of 80
// bakes), so OpenImageIO's "exr_threads" stays -1. This provider starts its
// threads one at a time and runs with those it got (none: the tasks run on
// the writing thread); in a forked child, whose threads are gone, tasks run
// where they are added. Readers keep OpenEXR's single chunk buffer, so the
// header probe's bounds (header_probe.c) hold as before. A process that set
// up OpenEXR's pool itself before bumpbake's first EXR write keeps its own.
class ExrWriteThreads {
public:
  explicit ExrWriteThreads(int threads);
  ~ExrWriteThreads();
  ExrWriteThreads(const ExrWriteThreads &) = delete;
  ExrWriteThreads &operator=(const ExrWriteThreads &) = delete;

private:
  int previous_;
};

} // namespace bb

#endif // BB_IO_EXR_POOL_H
