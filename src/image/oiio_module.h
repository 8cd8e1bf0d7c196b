/* oiio_module.h: the OpenImageIO module, libbumpbake-oiio.so.VERSION, and
 * the two tables between it and the library.
 *
 * Why: OpenImageIO on Debian 12 loads about 260 shared libraries, and
 * loading them is most of a process's start-up (0.2 to 0.45 s of CPU). The
 * image family's OpenImageIO calls (oiio_calls.h) and the text the render
 * family draws through it (render/text.h) are built into a module of their
 * own, with OpenEXR's pool (exr_pool.cpp), which the library dlopen()s on
 * the first such call (oiio_load.c): a process that reads or writes no
 * image never loads OpenImageIO.
 *
 * The module is C++ over OpenImageIO and calls back into the library (the
 * staged files, the limits, the messages...) through the host table the
 * library hands it, since the library's internals are not exported
 * (oiio_host.c defines them in the module as calls through that table).
 * It exports one symbol, BB__OIIO_ENTRY: given the host table, it returns
 * its own table of calls. A module of another version is refused.
 *
 * Each list is an X-macro: X(return type, name, (parameters), (arguments)),
 * the calls' lists with a fifth, what the library's wrapper returns when
 * the module cannot be loaded (bb__oiio_gif_abort, void, is the table's
 * last member, outside the lists). */
#ifndef BB_IMAGE_OIIO_MODULE_H
#define BB_IMAGE_OIIO_MODULE_H

#include "bumpbake.h"
/* The declarations of every function of the lists, so that both sides
 * check the lists against them. */
#include "core/file_names.h"
#include "core/input_file.h"
#include "core/internal.h"
#include "files/safe_file.h"
#include "image/description.h"
#include "image/formats.h"
#include "image/header_probe.h"
#include "image/oiio.h"
#include "image/oiio_calls.h"
#include "image/quantise.h"
#include "image/read_limits.h"
#include "image/signatures.h"

#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The module's one export; what it returns is checked against this. */
#define BB__OIIO_ENTRY "bb__oiio_module_entry"
#define BB__OIIO_MODULE_PREFIX "libbumpbake-oiio.so."

/* The image family's calls (oiio_calls.h, oiio.h). */
#define BB__OIIO_IMAGE_CALLS(X)                                                               \
  X(bb_status, bb__oiio_read,                                                                 \
    (const char *path, int first, int count, int level, bb_image *out, bb_image_info *info,   \
     int *level_count, bb_error *err),                                                        \
    (path, first, count, level, out, info, level_count, err), return bb__oiio_failed(err))    \
  X(bb_status, bb__oiio_read_header,                                                          \
    (const char *path, int *width, int *height, int *channels, bb_image_info *info,           \
     bb_error *err),                                                                          \
    (path, width, height, channels, info, err), return bb__oiio_failed(err))                  \
  X(bb_status, bb__oiio_level_count, (const char *path, int *levels, bb_error *err),          \
    (path, levels, err), return bb__oiio_failed(err))                                         \
  X(bb_status, bb__oiio_frame_count, (const char *path, int *frames, bb_error *err),          \
    (path, frames, err), return bb__oiio_failed(err))                                         \
  X(bb_status, bb__oiio_samples_as_read,                                                      \
    (const void *samples, int depth, size_t n, float *out, bb_error *err),                    \
    (samples, depth, n, out, err), return bb__oiio_failed(err))                               \
  X(char *, bb__oiio_extension_list, (void), (), return NULL)                                 \
  X(bb_status, bb__oiio_write_image,                                                          \
    (const char *path, const bb_image *img, bb_depth depth, bb_range range,                   \
     const char *description, int threads, const char *exr_compression, bb_staged_file *f,    \
     bb_error *err),                                                                          \
    (path, img, depth, range, description, threads, exr_compression, f, err),                 \
    return bb__oiio_failed(err))                                                              \
  X(bb_status, bb__oiio_write_mips,                                                           \
    (const char *path, const bb_image *levels, int count, bb_depth depth, bb_range range,     \
     const char *description, int threads, bb_staged_file *f, bb_error *err),                 \
    (path, levels, count, depth, range, description, threads, f, err),                        \
    return bb__oiio_failed(err))                                                              \
  X(bb_status, bb__image_resize_box,                                                          \
    (const bb_image *in, int width, int height, bb_image *out, bb_error *err),                \
    (in, width, height, out, err), return bb__oiio_failed(err))                               \
  X(bb_status, bb__oiio_gif_open,                                                             \
    (const char *path, int width, int height, double frames_per_second, bb_animation **out,   \
     bb_error *err),                                                                          \
    (path, width, height, frames_per_second, out, err), return bb__oiio_failed(err))          \
  X(bb_status, bb__oiio_gif_add, (bb_animation * a, const bb_image *frame, bb_error *err),    \
    (a, frame, err), return bb__oiio_failed(err))                                             \
  X(bb_status, bb__oiio_gif_close, (bb_animation * a, bb_error *err), (a, err),               \
    return bb__oiio_failed(err))

/* The render family's text (render/text.h): without the module, no font is
 * usable and labels are left out, as without a font file. */
#define BB__OIIO_TEXT_CALLS(X)                                                                \
  X(int, bb__font_usable, (const char *font), (font), return 0)                               \
  X(int, bb__text_width, (const char *text, int size_px, const char *font),                   \
    (text, size_px, font), return 0)                                                          \
  X(bb_status, bb__text_draw,                                                                 \
    (bb_image * img, int center_x, int baseline_y, const char *text, int size_px,             \
     const float color[3], const char *font, bb_error *err),                                  \
    (img, center_x, baseline_y, text, size_px, color, font, err), return bb__oiio_failed(err))

/* The library's functions the module calls. bb__fail is variadic: the
 * module formats the message and passes it as "%s" (oiio_host.c). */
#define BB__OIIO_HOST_CALLS(X)                                                                \
  X(bb_status, bb__fail_message, (bb_error * err, bb_status status, const char *message),     \
    (err, status, message))                                                                   \
  X(bb_status, bb_image_alloc, (bb_image * img, int width, int height, int channels,          \
                                bb_error *err),                                               \
    (img, width, height, channels, err))                                                      \
  X(void, bb_image_free, (bb_image * img), (img))                                             \
  X(int, bb__thread_count, (int threads), (threads))                                          \
  X(void, bb__description_as_read, (const char *format_name, char *description),             \
    (format_name, description))                                                               \
  X(char *, bb__description_join,                                                             \
    (const char *format_name, char *description, const char *image_id),                       \
    (format_name, description, image_id))                                                     \
  X(char *, bb__description_overflow, (const char *path, const char *description),           \
    (path, description))                                                                      \
  X(char *, bb__description_to_store, (const char *path, const char *description),           \
    (path, description))                                                                      \
  X(void, bb__extension_of, (const char *path, char *out, size_t cap), (path, out, cap))      \
  X(int, bb__path_has_extension, (const char *path, const char *ext), (path, ext))            \
  X(const char *, bb__format_by_content, (const unsigned char *head, unsigned long n),        \
    (head, n))                                                                                \
  X(const char *, bb__format_display_name, (const char *format), (format))                    \
  X(int, bb__format_has_signature, (const char *format), (format))                            \
  X(const char *, bb__basis_channel_name, (int c, int count, char out[8]), (c, count, out))   \
  X(const char *, bb__exr_compression, (bb_depth depth), (depth))                             \
  X(uint8_t *, bb__quantise_8, (const bb_image *img, bb_range range), (img, range))           \
  X(uint16_t *, bb__quantise_16, (const bb_image *img, bb_range range), (img, range))         \
  X(bb_status, bb__input_open, (const char *path, int *fd, bb_error *err), (path, fd, err))   \
  X(bb_status, bb__probe_header, (int fd, const char *path, bb__probe *probe, bb_error *err), \
    (fd, path, probe, err))                                                                   \
  X(bb_status, bb__read_check_probe,                                                          \
    (const char *path, const struct bb__probe *probe, int reading, bb_error *err),            \
    (path, probe, reading, err))                                                              \
  X(bb_status, bb__read_check_shape,                                                          \
    (const char *path, const bb__image_header *h, bb_error *err), (path, h, err))             \
  X(bb_status, bb__read_check_size,                                                           \
    (const char *path, const bb__image_header *h, int channels_read, bb_error *err),          \
    (path, h, channels_read, err))                                                            \
  X(int, bb__read_band_rows, (const bb__image_header *h, int channels), (h, channels))        \
  X(bb_status, bb__safe_open, (bb_staged_file * f, const char *path, bb_error *err),          \
    (f, path, err))                                                                           \
  X(bb_status, bb__safe_open_private, (bb_staged_file * f, const char *path, bb_error *err),  \
    (f, path, err))                                                                           \
  X(bb_status, bb__safe_adopt, (bb_staged_file * f, bb_error *err), (f, err))                 \
  X(int, bb__safe_creation_begin, (sigset_t * held), (held))                                  \
  X(void, bb__safe_creation_end, (const sigset_t *held), (held))                              \
  X(size_t, bb__safe_write, (bb_staged_file * f, const void *data, size_t size),              \
    (f, data, size))                                                                          \
  X(size_t, bb__safe_pwrite,                                                                  \
    (bb_staged_file * f, const void *data, size_t size, int64_t offset),                      \
    (f, data, size, offset))                                                                  \
  X(size_t, bb__safe_read, (bb_staged_file * f, void *data, size_t size), (f, data, size))    \
  X(size_t, bb__safe_pread, (bb_staged_file * f, void *data, size_t size, int64_t offset),    \
    (f, data, size, offset))                                                                  \
  X(int, bb__safe_seek, (bb_staged_file * f, int64_t offset), (f, offset))                    \
  X(int64_t, bb__safe_tell, (bb_staged_file * f), (f))                                        \
  X(int64_t, bb__safe_size, (bb_staged_file * f), (f))                                        \
  X(bb_status, bb__safe_finish, (bb_staged_file * f, bb_error *err), (f, err))                \
  X(bb_status, bb__safe_commit, (bb_staged_file * f, bb_error *err), (f, err))                \
  X(void, bb__safe_discard, (bb_staged_file * f), (f))

#define BB__OIIO_MEMBER(ret, name, params, ...) ret(*name) params;

typedef struct bb__oiio_host {
  size_t size;         /* sizeof(bb__oiio_host) */
  const char *version; /* BB_VERSION_STRING */
  BB__OIIO_HOST_CALLS(BB__OIIO_MEMBER)
} bb__oiio_host;

typedef struct bb__oiio_table {
  size_t size;         /* sizeof(bb__oiio_table) */
  const char *version; /* BB_VERSION_STRING */
  BB__OIIO_IMAGE_CALLS(BB__OIIO_MEMBER)
  BB__OIIO_TEXT_CALLS(BB__OIIO_MEMBER)
  void (*bb__oiio_gif_abort)(bb_animation *a); /* a exists: the module is loaded */
} bb__oiio_table;

/* The library's definition of a call of the lists: the module's, loaded on
 * first use, or the list's fallback when it cannot be loaded. */
#define BB__OIIO_WRAPPER(ret, name, params, args, fallback)                                   \
  ret name params {                                                                           \
    const bb__oiio_table *t = bb__oiio_module();                                              \
    if (!t) fallback;                                                                         \
    return t->name args;                                                                      \
  }

/* The module's entry (BB__OIIO_ENTRY): keeps host, returns the calls. */
const bb__oiio_table *bb__oiio_module_entry(const bb__oiio_host *host);

/* In the module: the host table its entry was given (oiio_host_table.c). */
extern const bb__oiio_host *bb__oiio_host_table;

/* The library's side (oiio_load.c): the module's table, loaded once per
 * process on the first call; NULL when it cannot be loaded. */
const bb__oiio_table *bb__oiio_module(void);
/* BB_ERR_IO with the one line saying why the module could not be loaded
 * (naming its path). */
bb_status bb__oiio_failed(bb_error *err);
/* The host table's bb__fail_message: bb__fail(err, status, "%s", message). */
bb_status bb__fail_message(bb_error *err, bb_status status, const char *message);

#ifdef __cplusplus
}
#endif

#endif /* BB_IMAGE_OIIO_MODULE_H */
