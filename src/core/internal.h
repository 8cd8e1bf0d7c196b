/* internal.h: helpers shared between bumpbake's source files (not public). */
#ifndef BB_INTERNAL_H
#define BB_INTERNAL_H

#include "bumpbake.h"

#include <assert.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Writes a printf-style message into err (when not NULL) and returns status,
 * so error paths read: return bb__fail(err, BB_ERR_IO, "%s: ...", path); */
bb_status bb__fail(bb_error *err, bb_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#define BB__PI 3.14159265358979323846

/* Largest |a| or |b| of a ray set's lattice steps (and of what sweep.c takes). */
#define BB__MAX_LATTICE_STEP 128

/* Non-negative remainder: the periodic index of i in [0, n). */
static inline int bb__wrap(int i, int n) {
  int r = i % n;
  return r < 0 ? r + n : r;
}

/* bb__wrap for an index known to lie within a few periods of [0, n):
 * a subtraction or two instead of a division, for the tracer's inner loops. */
static inline int bb__wrap_near(int i, int n) {
  while (i >= n) i -= n;
  while (i < 0) i += n;
  return i;
}

/* Greatest common divisor of |a| and |b| (gcd(0, n) = |n|). */
static inline long bb__gcd(long a, long b) {
  a = a < 0 ? -a : a;
  b = b < 0 ? -b : b;
  while (b) {
    const long r = a % b;
    a = b;
    b = r;
  }
  return a;
}

static inline int bb__clampi(int i, int lo, int hi) {
  return i < lo ? lo : (i > hi ? hi : i);
}

/* Texel index for addressing mode a (periodic wrap or clamp to the border). */
static inline int bb__address(int i, int n, bb_addressing a) {
  return a == BB_ADDRESS_PERIODIC ? bb__wrap(i, n) : bb__clampi(i, 0, n - 1);
}

/* Number of worker threads to use for a request of `threads` (0 = all cores). */
int bb__thread_count(int threads);

/* Runs fn(user, item) for item = 0 .. items-1 on `threads` threads; items
 * are handed out in order from a shared counter. Each item's result must
 * depend only on the item, which keeps outputs identical for any thread
 * count. progress (may be NULL) is called from the calling thread; when it
 * returns nonzero no further item starts and BB_ERR_CANCELLED is returned
 * (the items already running finish first). */
typedef void (*bb__work_fn)(void *user, int item);
bb_status bb__parallel_for(int items, int threads, bb__work_fn fn, void *user,
                           bb_progress_fn progress, void *progress_user,
                           bb_error *err);

/* The stages of a bake with the bake's thread count (0 = all cores); the
 * public functions of the same name without "bb__" call them with 0.
 * Every stage splits its work into items whose results do not depend on
 * the split, so any thread count gives the same bits. */
bb_status bb__smooth_bilateral(const bb_image *in, const bb_image *guide,
                               const bb_smooth_options *o, int threads, bb_image *out,
                               bb_error *err);
bb_status bb__normals_compute(const bb_image *height, float height_scale,
                              bb_normal_filter filter, bb_addressing addressing, int threads,
                              bb_image *out, bb_error *err);
bb_status bb__pyramid_build(const bb_image *height_texels, bb_addressing addressing,
                            int threads, bb_pyramid **out, bb_error *err);
bb_status bb__rayset_make(int slices, double power, const bb_basis *basis, int threads,
                          bb_rayset *out, bb_error *err);
bb_status bb__derive_weights(const bb_image *normals, const bb_basis *basis, int threads,
                             bb_image *out, bb_error *err);
bb_status bb__derive_ssbump(const bb_image *normals, const bb_image *vis,
                            const bb_basis *basis, int threads, bb_image *out, bb_error *err);
bb_status bb__derive_ao(const bb_image *vis, int threads, bb_image *out, bb_error *err);
bb_status bb__derive_bent(const bb_image *ssbump, const bb_basis *basis, int threads,
                          bb_image *out, bb_error *err);

/* 64-bit FNV-1a: the hash of an empty input, and one step over the four
 * bytes of v, little-endian whatever the host (so hashes recorded on one
 * machine check on another). For bb_image_hash and bb_mesh_hash. */
#define BB__FNV64_OFFSET 0xcbf29ce484222325ULL
uint64_t bb__fnv1a_u32(uint64_t h, uint32_t v);
/* bb__fnv1a_u32 over the bits of n floats. */
uint64_t bb__fnv1a_floats(uint64_t h, const float *v, size_t n);

/* BB_OK when b has 3..BB_MAX_BASIS unit vectors with z >= 0 (a basis
 * filled by hand is checked before it is used), else BB_ERR_ARGUMENT with a
 * message starting "who: ". */
bb_status bb__basis_check(const bb_basis *b, const char *who, bb_error *err);

/* Consumers of basis maps (render, ssbump2normal, combine's detail,
 * Valve's files) read channels 0..2 as Half-Life 2's B0, B1, B2 and leave a
 * fourth alone (Valve's alpha, hl2+z's B3). BB_OK when img (named what)
 * has at most 4 channels, else BB_ERR_ARGUMENT saying so; with a basis
 * (may be NULL: not known) also when it is not Half-Life 2's. */
bb_status bb__check_hl2_map(const bb_image *img, const bb_basis *basis, const char *what,
                            bb_error *err);

/* Monotonic wall-clock seconds. */
double bb__now_seconds(void);

/* Text through OpenImageIO (io_oiio.cpp). font is a font file or a name
 * OpenImageIO searches for (its font path and /usr/share/fonts). */
/* 1 when OpenImageIO can draw text with font. */
int bb__font_usable(const char *font);
/* Width in pixels of text at size_px, or -1 when it cannot be measured. */
int bb__text_width(const char *text, int size_px, const char *font);
/* Draws text into a 3-channel img, centred on center_x, its baseline at
 * baseline_y (so labels with and without descenders line up). */
bb_status bb__text_draw(bb_image *img, int center_x, int baseline_y, const char *text,
                        int size_px, const float color[3], const char *font, bb_error *err);

/* Fits the "key=value" lines of a provenance text into `rows` rows of at
 * most `row_chars` characters (TGA's comment field: 4 rows of 80), whole
 * lines only: the keys that affect pixels first, then the others, each line
 * in the first row it fits; lines joined by '\n' within a row. Row r is
 * written NUL-terminated at out + r * (row_chars + 1), which must hold
 * rows * (row_chars + 1) bytes. Returns how many lines did not fit. */
int bb__provenance_pack(const char *description, int rows, int row_chars, char *out);

/* 1 when two provenance texts differ in a key not in `ignored` (a
 * NULL-terminated list): a key of want missing from have or holding
 * another value there, or a key have holds and want lacks (first
 * occurrences count). reason (capacity cap, may be NULL) receives the first
 * such key as "key: have-value -> want-value" ("(none)" for a missing one).
 * 0 when they agree. */
int bb__provenance_mismatch(const char *have, const char *want, const char *const *ignored,
                            char *reason, size_t cap);

/* The id bb_rayset_make gives a rayset of these parameters, into out
 * (capacity cap), without building it. */
void bb__rayset_id(int slices, double power, const bb_basis *basis, char *out, size_t cap);

/* Image headers for bb_output_check (io_oiio.cpp): the depth bb_image_write
 * stores for `depth` in path's format (BB_DEPTH_DEFAULT resolved), or -1
 * for an unknown extension; and the number of mip levels of subimage 0 of
 * the file at path, from its headers. */
int bb__path_resolved_depth(const char *path, bb_depth depth);
bb_status bb__image_level_count(const char *path, int *levels, bb_error *err);

/* ------------------------------------------------- safe file writing
 * Every writer (src/safe_file.c; OpenImageIO writers reach it through
 * write_safely() in src/io_oiio.cpp) puts bytes on disk this way, so that
 * no failure leaves a partial file at the final name:
 *
 *   bb_staged_file f;
 *   if (bb__safe_open(&f, path, err) != BB_OK) return ...;  temp created
 *   bb__safe_write(&f, bytes, n); ...          checked; errors are kept
 *   return bb__safe_commit(&f, err);           or bb__safe_discard(&f)
 *
 * - The bytes go to "DIR/.bb-tmp-XXXXXX.EXT" next to path (same
 *   filesystem, so the rename is atomic), registered for
 *   bb_tempfiles_remove() (signal handlers) while it exists.
 * - Writes are buffered; every write(2) is checked and retried on short
 *   counts. The first failure (ENOSPC, EFBIG under RLIMIT_FSIZE, EIO...) is
 *   kept and later writes return 0, so a codec that ignores a failed write
 *   cannot hide it: bb__safe_finish reports it.
 * - bb__safe_finish flushes, fsyncs and closes (checked) the temporary;
 *   bb__safe_commit finishes and renames it to path. Both remove the
 *   temporary on failure and return BB_ERR_IO with "PATH: cannot write:
 *   REASON". After finish alone the complete file waits under its temporary
 *   name (that is what bb_staged_file is): commit or discard it later.
 * - A bb_staged_file may be used from several threads (each call locks). */
struct bb_staged_file {
  pthread_mutex_t lock;
  int lock_ready;
  int fd;               /* -1 once closed */
  int error;            /* first errno seen, 0 when none */
  int slot;             /* registry slot for bb_tempfiles_remove, or -1 */
  int64_t pos;          /* position of the next bb__safe_write / read */
  int64_t size;         /* bytes in the file (highest byte written + 1) */
  unsigned char *buffer;
  size_t buffered;      /* bytes waiting in buffer */
  int64_t buffer_pos;   /* file offset of buffer[0] */
  char *path;           /* final name, malloc'd */
  char *temp_path;      /* temporary name, malloc'd */
};

/* Creates the temporary for path (f is the caller's; nothing to free on
 * failure). Errors: BB_ERR_IO (directory missing or not writable). */
bb_status bb__safe_open(bb_staged_file *f, const char *path, bb_error *err);
/* Writes at the current position / at offset; returns size, or 0 once any
 * write has failed. */
size_t bb__safe_write(bb_staged_file *f, const void *data, size_t size);
size_t bb__safe_pwrite(bb_staged_file *f, const void *data, size_t size, int64_t offset);
/* Reads back what was written (some encoders patch headers). */
size_t bb__safe_read(bb_staged_file *f, void *data, size_t size);
size_t bb__safe_pread(bb_staged_file *f, void *data, size_t size, int64_t offset);
int bb__safe_seek(bb_staged_file *f, int64_t offset); /* 0, or -1 if offset < 0 */
int64_t bb__safe_tell(bb_staged_file *f);
int64_t bb__safe_size(bb_staged_file *f);
/* Marks the file failed (an encoder's own error): finish will refuse it. */
void bb__safe_fail(bb_staged_file *f, int error);
bb_status bb__safe_finish(bb_staged_file *f, bb_error *err);
bb_status bb__safe_commit(bb_staged_file *f, bb_error *err);
/* Removes the temporary; safe after a failed open, finish or commit. */
void bb__safe_discard(bb_staged_file *f);
/* A zeroed heap bb_staged_file for the public handle API (NULL when out of
 * memory). */
bb_staged_file *bb__staged_new(void);

/* ------------------------------------------------------ bounded reads */

/* Reads channels [first_channel, first_channel + channel_count) of path as
 * float (the bounds of bb_image_read apply: the bytes of the whole file's
 * samples and of what is read). info may be NULL. Messages name the file. */
bb_status bb__image_read_channels(const char *path, int first_channel, int channel_count,
                                  bb_image *out, bb_image_info *info, bb_error *err);

/* Checks that height_scale * h is a finite float with room to spare for
 * differences (|S h| <= BB_MAX_HEIGHT_TEXELS) at every texel of a 1-channel
 * height; BB_ERR_VALUE names the first texel over it. */
bb_status bb__check_scaled_height(const bb_image *height, float height_scale, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BB_INTERNAL_H */
