/* png_hooks.c: what the library sets on every png_struct OpenImageIO makes:
 * error handlers that do not print, and allocations bounded.
 *
 * Why: libpng's png_error() calls the error handler its user set with
 * png_set_error_fn() and, if that handler returns, its own
 * png_default_error(), which prints "libpng error: MESSAGE" on stderr and
 * then longjmps (libpng 1.6.39 pngerror.c). OpenImageIO's PNG handlers
 * (rderr_handler, wrerr_handler in png_pvt.h, the same in 2.4 and in its
 * newest sources) record the message and return, so every corrupt or
 * truncated PNG printed that line before OpenImageIO reported the error we
 * report. And libpng checks a chunk's length against its 8 MB chunk limit
 * with a benign error, which on read is a warning: a 211-byte PNG whose
 * tEXt chunk declared 1.7 GB was allocated and zeroed whole (5 s, 1.8 GB)
 * in OpenImageIO's open(). OpenImageIO offers no attribute for either and
 * never shows its png_struct; libpng's user may set both on the struct.
 *
 * How: the library defines png_set_error_fn (OpenImageIO's PNG reader
 * calls it right after creating its struct) and png_create_write_struct
 * (its writer passes its handlers there) itself: exported, the two non-bb_
 * symbols of libbumpbake.so. OpenImageIO's calls reach them first, since
 * the program, or libbumpbake.so ahead of its own dependencies, comes
 * before libpng in the dynamic linker's search order. They pass the call on
 * to libpng's (dlsym RTLD_NEXT) and, for calls from OpenImageIO (dladdr of
 * the return address), wrap the handler so that after it returns the wrapper does what
 * libpng does, png_longjmp(), minus the print, and sets allocation
 * functions (png_set_mem_fn; the C heap, as libpng's own) that refuse any
 * single allocation over BB__MAX_CHUNK_BYTES: libpng then skips an
 * ancillary chunk it cannot hold ("insufficient memory to read chunk") and
 * fails on anything else. Other libpng users of the process are left
 * alone. It does not take effect when OpenImageIO was loaded and bound to
 * libpng before libbumpbake (a program that dlopen()s OpenImageIO first,
 * then bumpbake); the process's file descriptors are never touched. */
#define _GNU_SOURCE /* RTLD_NEXT */

#include <dlfcn.h>
#include <png.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "image/png_hooks.h"
#include "image/read_limits.h"

/* Distinct handlers seen: OpenImageIO has two (read and write); each gets
 * its own wrapper, since libpng passes the wrapper nothing to tell them
 * apart. Past the table's end handlers are passed on unwrapped. */
enum { SLOTS = 8 };
static _Atomic(png_error_ptr) handlers[SLOTS];

static void PNGCBAPI call_then_jump(int slot, png_structp png, png_const_charp message) {
  png_error_ptr handler = atomic_load(&handlers[slot]);
  handler(png, message);
  png_longjmp(png, 1);
}

#define WRAPPER(k)                                                                    \
  static void PNGCBAPI quiet_##k(png_structp png, png_const_charp message) {          \
    call_then_jump(k, png, message);                                                  \
  }
WRAPPER(0)
WRAPPER(1)
WRAPPER(2)
WRAPPER(3)
WRAPPER(4)
WRAPPER(5)
WRAPPER(6)
WRAPPER(7)
static const png_error_ptr WRAPPERS[SLOTS] = {quiet_0, quiet_1, quiet_2, quiet_3,
                                              quiet_4, quiet_5, quiet_6, quiet_7};

/* The wrapper of handler, or handler itself when the table is full (or it
 * is one of ours already). */
static png_error_ptr wrapped(png_error_ptr handler) {
  for (int k = 0; k < SLOTS; k++)
    if (handler == WRAPPERS[k]) return handler;
  for (int k = 0; k < SLOTS; k++) {
    png_error_ptr seen = atomic_load(&handlers[k]);
    if (seen == handler) return WRAPPERS[k];
    if (!seen) {
      png_error_ptr expected = NULL;
      if (atomic_compare_exchange_strong(&handlers[k], &expected, handler) ||
          expected == handler)
        return WRAPPERS[k];
    }
  }
  return handler;
}

/* libpng's allocations on OpenImageIO's structs: the C heap, as libpng's
 * defaults are (so what was allocated before is freed alike), but never
 * one block over the bound. */
static png_voidp PNGCBAPI bounded_malloc(png_structp png, png_alloc_size_t size) {
  (void)png;
  return size <= (png_alloc_size_t)BB__MAX_CHUNK_BYTES ? malloc((size_t)size) : NULL;
}

static void PNGCBAPI heap_free(png_structp png, png_voidp block) {
  (void)png;
  free(block);
}

/* 1 when the code at address belongs to OpenImageIO's library. */
static int in_openimageio(const void *address) {
  Dl_info info;
  return dladdr(address, &info) != 0 && info.dli_fname &&
         strstr(info.dli_fname, "libOpenImageIO") != NULL;
}

typedef void(PNGAPI *set_error_fn_t)(png_structrp, png_voidp, png_error_ptr, png_error_ptr);

void PNGAPI png_set_error_fn(png_structrp png, png_voidp error_ptr, png_error_ptr error_fn,
                             png_error_ptr warning_fn) {
  static _Atomic(set_error_fn_t) libpngs;
  set_error_fn_t real = atomic_load(&libpngs);
  if (!real) {
    /* The ISO C cast of a data pointer to a function pointer, as POSIX allows. */
    void *found = dlsym(RTLD_NEXT, "png_set_error_fn");
    *(void **)&real = found;
    if (!real) return; /* no libpng after us: nothing calls this */
    atomic_store(&libpngs, real);
  }
  if (!png || !in_openimageio(__builtin_return_address(0))) {
    real(png, error_ptr, error_fn, warning_fn);
    return;
  }
  real(png, error_ptr, error_fn ? wrapped(error_fn) : NULL, warning_fn);
  png_set_mem_fn(png, NULL, bounded_malloc, heap_free);
}

/* OpenImageIO's PNG writer hands its handlers to png_create_write_struct
 * and never calls png_set_error_fn: the same hooks, at creation. */
typedef png_structp(PNGAPI *create_write_t)(png_const_charp, png_voidp, png_error_ptr,
                                            png_error_ptr);

png_structp PNGAPI png_create_write_struct(png_const_charp version, png_voidp error_ptr,
                                           png_error_ptr error_fn, png_error_ptr warning_fn) {
  static _Atomic(create_write_t) libpngs;
  create_write_t real = atomic_load(&libpngs);
  if (!real) {
    void *found = dlsym(RTLD_NEXT, "png_create_write_struct");
    *(void **)&real = found;
    if (!real) return NULL; /* no libpng after us: nothing calls this */
    atomic_store(&libpngs, real);
  }
  if (!in_openimageio(__builtin_return_address(0)))
    return real(version, error_ptr, error_fn, warning_fn);
  png_structp png = real(version, error_ptr, error_fn ? wrapped(error_fn) : NULL, warning_fn);
  if (png) png_set_mem_fn(png, NULL, bounded_malloc, heap_free);
  return png;
}



/* Something a read refers to: a program linking libbumpbake.a gets this
 * file only for a symbol one of its objects asks for (OpenImageIO's call
 * to png_set_error_fn comes from a shared library and pulls nothing). */
int bb__png_hooks_set(void) { return atomic_load(&handlers[0]) != NULL; }
