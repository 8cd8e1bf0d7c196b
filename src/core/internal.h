/* internal.h: what every family of the library shares (not public): error
 * messages, periodic addressing, threads, hashing and the clock. Each family
 * keeps its own private headers beside its files (image/oiio.h, trace/march.h...). */
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
 * so error paths read: return bb__fail(err, BB_ERR_IO, "%s: ...", path).
 * The message is one line, safe to print: what bb_text_printable escapes
 * (controls, bytes that are not UTF-8) is written as \xNN. */
bb_status bb__fail(bb_error *err, bb_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* A failure about the file path, st with e's message (else st's name),
 * naming path once: e's message as it is when it already starts "PATH:". */
bb_status bb__fail_at(bb_error *err, bb_status st, const char *path, const bb_error *e);

/* The length of path as a message shows it (bb__fail's escapes) when
 * message starts with it and a ':', else 0. */
size_t bb__message_names(const char *message, const char *path);

/* Finds name among names[0..count-1] (NULL entries skipped), comparing
 * with or without case, into *index: BB_OK, or BB_ERR_ARGUMENT with "WHAT
 * must be one of a, b, c (got 'x')". Every enum parser of the library uses
 * it. */
bb_status bb__parse_name(const char *what, const char *name, const char *const *names,
                         int count, int ignore_case, int *index, bb_error *err);

/* -------------------------------------------------------- map kinds */

/* The map kind of an output's kind string (bb_output_file.kind,
 * bb_output_spec.kind), whose facts (bb_map_kind_info: mip rule, DDS
 * default, VTF flags) a texture of it takes; the one place such strings
 * are read. A kind string is NAME or NAME+EXTRA, a NAME map with EXTRA in
 * its last channel (Valve's "ssbump+height", "ssbump+ao", "normal+height",
 * "normal+ao", "detail-ssbump+height", "detail-ssbump+ao"; renderbumpflat's
 * "normal+coverage"). NAME is a kind's name ("normal", "weights",
 * "ssbump", ...), or "detail-ssbump" (height2ssbump -d: an ssbump). Then:
 *   - the kind NAME names, when range is its own, or it does not hold unit
 *     vectors (an ssbump with a height in alpha is still an ssbump);
 *   - PLAIN for a unit-vector kind (normal, bent) of another range: its
 *     vectors were packed into [0, 1] already (0.5 + 0.5 N, height2ssbump
 *     -n's), codes to average, not vectors to renormalise; the kind's VTF
 *     flag (NORMAL) is added to *vtf_flags (when not NULL);
 *   - any other kind ("height", "colour", "render", "comparison", "sheet",
 *     "diff", "slope_lit", "material", NULL ...) has no map of its own:
 *     NORMAL for BB_RANGE_SIGNED values (bumpbake's signed images are unit
 *     vectors), else PLAIN.
 * Names are compared exactly, as the library spells them. */
bb_map_kind bb__map_kind_of_output(const char *kind, bb_range range, uint32_t *vtf_flags);

/* What a map's provenance records of one key (bb__map_kind_records, the
 * rule's one home, map_kind.c): the key's value, nothing, or of a ray
 * set's id only the scheme and slices (ao without inter-reflection:
 * "bb-horizon-v1:a16", the lobes' power and basis leave it). */
typedef enum bb__key_use {
  BB__KEY_DROPPED = 0,
  BB__KEY_RECORDED,
  BB__KEY_SLICES
} bb__key_use;
bb__key_use bb__map_kind_key(const char *kind, const char *key, size_t key_length,
                             int bounce);

/* The length of a ray set's id (length bytes at id, not terminated) up to
 * its slices: "bb-horizon-v1:a16" of "bb-horizon-v1:a16:p1:hl2". */
size_t bb__rayset_slices_length(const char *id, size_t length);

/* ----------------------------------------------------------------- ranges */

/* The range of one parameter, written once where the parameter's struct
 * is checked (bake/options.c, render/render.c, ...) and referred to by the
 * option that sets it (cmd/), so a range has one home and one message. */
typedef struct bb__range {
  const char *what;   /* in messages of the struct's check: "filter radius" */
  double min, max;    /* max HUGE_VAL: no upper bound */
  int min_exclusive;  /* 1: > min */
  int integer;        /* 1: whole numbers only */
} bb__range;

/* 1 when v is in r (NaN never is). */
int bb__range_holds(const bb__range *r, double v);
/* BB_OK, or BB_ERR_ARGUMENT "WHO must be in 1..65536 (got 0)" (or "> 0",
 * ">= 0"); who NULL: r->what. */
bb_status bb__range_check(const bb__range *r, double v, const char *who, bb_error *err);
/* The range as help prints it: "1..65536", "> 0", "0..1e6". */
void bb__range_text(const bb__range *r, char *out, size_t cap);
/* v as messages print it: %g, with "1e6" for "1e+06". */
void bb__number_text(double v, char *out, size_t cap);

#define BB__PI 3.14159265358979323846

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
/* The threads any stage accepts: 0..BB_MAX_THREADS (parallel.c). */
extern const bb__range bb__range_threads;

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

/* A cancel point for a stage that reports no progress of its own (smooth,
 * normals): the caller's progress called with done 0 and total 0 ("a
 * checkpoint", bumpbake.h) from the calling thread every 50 ms while the
 * stage runs; a nonzero return cancels it as bb__parallel_for does. A NULL
 * checkpoint, or one without fn, is bb__parallel_for without progress. */
typedef struct bb__checkpoint {
  bb_progress_fn fn;
  void *user;
} bb__checkpoint;
bb_status bb__parallel_for_checked(int items, int threads, bb__work_fn fn, void *user,
                                   const bb__checkpoint *checkpoint, bb_error *err);

/* 64-bit FNV-1a: the hash of an empty input, and one step over the four
 * bytes of v, little-endian whatever the host (so hashes recorded on one
 * machine check on another). For bb__image_hash and bb__mesh_hash (hash.c). */
#define BB__FNV64_OFFSET 0xcbf29ce484222325ULL
uint64_t bb__fnv1a_u32(uint64_t h, uint32_t v);
/* bb__fnv1a_u32 over the bits of n floats. */
uint64_t bb__fnv1a_floats(uint64_t h, const float *v, size_t n);

/* A growable NUL-terminated text (data is NULL until the first append);
 * `failed` sticks once an allocation fails, and the caller then frees data
 * and refuses the result. Zero-initialise it: bb__text t = {0}. */
typedef struct bb__text {
  char *data;
  size_t length, capacity;
  int failed;
} bb__text;
/* Appends n bytes of s. */
void bb__text_append(bb__text *t, const char *s, size_t n);
/* Appends the string s. */
void bb__text_add(bb__text *t, const char *s);
/* Appends word quoted for a POSIX shell, as bb_text_shell_quoted spells it:
 * every command line the library spells puts its words through it. */
void bb__text_add_word(bb__text *t, const char *word);

/* Checks of images, with the same words in every family (image_checks.c). */
/* BB_ERR_VALUE naming the first texel whose channels 0..channels-1 are not
 * finite; what names the image ("normal map", "detail"). */
bb_status bb__check_finite(const bb_image *img, int channels, const char *what,
                           bb_error *err);

/* 1 when every sample of img is finite: one quick sweep, for the checks
 * that name the first bad texel in words of their own to pass the usual
 * case without walking texel by texel. */
int bb__image_all_finite(const bb_image *img);

/* BB_ERR_ARGUMENT unless a and b have the same width and height. */
bb_status bb__check_same_size(const bb_image *a, const char *name_a, const bb_image *b,
                              const char *name_b, bb_error *err);

/* BB_ERR_ARGUMENT unless img is allocated with at least min_channels. */
bb_status bb__check_channels(const bb_image *img, int min_channels, const char *what,
                             bb_error *err);

/* Scales v to unit length; a zero (or non-finite) length gives (0, 0, 1),
 * the flat normal, since such a texel has no direction to keep (vector.c). */
void bb__normalize3(double v[3]);

/* bb__memory_available, reading /proc and the cgroup files below root
 * ("" for the system's own; a test points it at a made-up tree:
 * ROOT/proc/meminfo, ROOT/proc/self/cgroup, ROOT/proc/self/mountinfo and
 * the cgroup directories at ROOT + the mount points it names). RLIMIT_AS
 * is this process's. */
bb_status bb__memory_available_at(const char *root, uint64_t *bytes, const char **source,
                                  bb_error *err);

/* BB_OK when need bytes fit in what bb__memory_available says is left, else
 * BB_ERR_MEMORY "WHAT needs about 9.1 GiB of memory; 6.0 GiB is available
 * (MemAvailable)". BB_OK when nothing can be known. */
bb_status bb__memory_check(double need, const char *what, bb_error *err);

/* What a job that fits will cost, to say before it starts: "WHAT takes
 * about 8.0 GiB of memory (20.9 GiB is available)" into out (cap bytes)
 * and 1 when need is over BB_MAX_READ_BYTES (what any read may take
 * whatever its size: past it, only a large input costs that much and a
 * while), else 0 and out empty. */
int bb__memory_note(double need, const char *what, char *out, size_t cap);

/* (text.c, beside bb__text_append and bb__text_add) */
void bb__text_printf(bb__text *t, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* The string (malloc'd, "" when empty), or NULL when an addition failed;
 * t is emptied either way. */
char *bb__text_take(bb__text *t);
void bb__text_free(bb__text *t);

/* The shortest decimal that reads back as the same float or double
 * ("36.8083", not "36.8082962"), as a user would type it: a whole number
 * plainly ("30", not the shortest %g "3e+01"). */
void bb__float_text(float v, char *buf, size_t cap);
void bb__double_text(double v, char *buf, size_t cap);

/* Monotonic wall-clock seconds. */
double bb__now_seconds(void);


/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* What this process may still allocate, in bytes: the smallest of what
 * the system has available (MemAvailable of /proc/meminfo, else its free
 * pages); under a container's or service's memory limit, the room left
 * below the limit of every cgroup from the process's own up to the top
 * (cgroup v2's memory.max, v1's memory.limit_in_bytes; the limit less the
 * group's usage, its reclaimable page cache not counted); and, under an
 * RLIMIT_AS (ulimit -v), the room left below it (the limit less the
 * address space mapped now). *source (may be NULL) receives which
 * ("MemAvailable", "sysconf free pages", "cgroup memory.max", "cgroup
 * memory.limit_in_bytes", "RLIMIT_AS"). Bakes and reads
 * check their estimate against it before allocating, so one too large is
 * refused with the figures (BB_ERR_MEMORY) instead of the kernel killing
 * the process; several processes started at once each see the same
 * figure. Errors: BB_ERR_IO (neither can be read). */
bb_status bb__memory_available(uint64_t *bytes, const char **source, bb_error *err);

/* 64-bit FNV-1a hash of an image's size, channel count and float pixels. */
uint64_t bb__image_hash(const bb_image *img);

/* The kind named name (bb_map_kind_info.name, any case); returns 0 on
 * success, BB_ERR_ARGUMENT for an unknown name (out untouched). */
bb_status bb__map_kind_parse(const char *name, bb_map_kind *out, bb_error *err);

/* The name of kind, or "unknown". */
const char *bb__map_kind_name(bb_map_kind kind);

/* The rule of what a map records in its provenance, which every writer and
 * reader of provenance follows: 1 when the pixels of a map of output kind
 * `kind` (as provenance records it under "output": "normal", "ao", ...; a
 * kind of parts, "ssbump+height", records what any part records, "height"
 * being the filtered height) can change with the bake parameter recorded
 * under `key`, 0 when they cannot: a normal map does not depend on "rays",
 * "rayset", "bias", "power", "basis", "bounce" or "brightness", the
 * filtered height on "scale" either, ao not on "normal_filter" or
 * "normal_y", and ao on "power" and "basis" only with inter-reflection
 * (bounce nonzero: the text has a "bounce" key); without it, ao's "rayset"
 * is recorded as the ray set's scheme and slices only ("bb-horizon-v1:a16").
 * A bake's outputs record only such keys (bb__provenance_format), the
 * up-to-date check (bb__output_check) and bb__provenance_diff compare only
 * them, so a parameter that does not change a map neither makes it stale
 * nor shows in its diff, also against a file written before the rule that
 * holds them all. 1 for keys that are no bake parameter (bumpbake_version,
 * input_file_hash, channel, a texture's or a render's keys) and for kinds
 * that are not a bake's maps ("render", "normal+coverage"). */
int bb__map_kind_records(const char *kind, const char *key, int bounce);

/* Negates channel 1 of a 3-channel vector image in place (+Y down <-> up). */
void bb__image_flip_green(bb_image *img);

#ifdef __cplusplus
}
#endif

#endif /* BB_INTERNAL_H */
