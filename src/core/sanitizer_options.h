/* sanitizer_options.h: what differs in the sanitizer builds (make DEBUG=1
 * with GCC, make fuzz with clang).
 *
 * Leak policy: the one known leak that is not bumpbake's is OpenImageIO
 * 2.4's PNG reader on a truncated file (PNGInput::PngReadCallback builds an
 * error string with ImageInput::geterror() and libpng longjmps past its
 * destructor). It is not suppressed by a pattern: LeakSanitizer's fast
 * unwinder stops inside libstdc++ (built without frame pointers), so the
 * recorded stack is only operator new and std::string::_M_assign, which
 * every leaked string shows; the slow unwinder that reaches OpenImageIO's
 * frame triples the run time of every debug CLI run (0.2 -> 0.7 s of CPU at
 * start-up alone). Instead src/image/oiio_read.cpp stops counting allocations as
 * leaks while, and only while, OpenImageIO's PNG reader decodes in that
 * thread. That covers the library, the CLI and the tests alike, and leaves
 * every other leak visible.
 *
 * Assimp's readers lose memory on some error paths of hostile models (the
 * glTF reader's base64 decoder throws past the buffer it allocated). In
 * bb__mesh_load that happens in the child process of the import, which
 * exits; the in-process import (bb__mesh_import: fuzz_mesh, tests) stops
 * counting allocations as leaks while, and only while, Assimp imports or
 * post-processes in that thread (src/mesh/mesh_assimp.cpp). */
#ifndef BB_SANITIZER_OPTIONS_H
#define BB_SANITIZER_OPTIONS_H

#if defined(__SANITIZE_ADDRESS__)
#define BB_ASAN_BUILD 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define BB_ASAN_BUILD 1
#endif
#endif

#endif /* BB_SANITIZER_OPTIONS_H */
