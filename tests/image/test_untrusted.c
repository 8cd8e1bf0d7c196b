/* test_untrusted.c: files every read must treat as hostile (docs: "Input
 * files are untrusted"): FIFOs and devices under an input's name. Each
 * call runs in a child with an alarm, so a regression that blocks fails
 * here instead of hanging the suite. */
#define _DEFAULT_SOURCE /* wait4 (child_call.h) */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw (scratch_dir.h) */

#include <criterion/criterion.h>

#include "job/job_internal.h"
#include "bumpbake.h"
#include "image/height_channel.h"
#include "child_call.h"
#include "scratch_dir.h"
#include "image/image_write.h"
#include "image/oiio.h"
#include "image/oiio_module.h"
#include "trace/basis.h"

#include <errno.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static void make_scratch_dir(void) { scratch_dir_make("bb_untrusted"); }

TestSuite(untrusted, .init = make_scratch_dir, .fini = scratch_dir_remove, .timeout = 600);

/* --------------------------------------------- every reader of the library */

static bb_status call_read(const char *path, bb_error *err) {
  bb_image img;
  bb_status st = bb_image_read(path, &img, NULL, err);
  bb_image_free(&img);
  return st;
}

static bb_status call_read_info(const char *path, bb_error *err) {
  int w, h, c;
  return bb_image_read_info(path, &w, &h, &c, NULL, err);
}

static bb_status call_read_mip(const char *path, bb_error *err) {
  bb_image img;
  int levels;
  bb_status st = bb__image_read_mip(path, 0, &img, NULL, &levels, err);
  bb_image_free(&img);
  return st;
}

static bb_status call_frame_count(const char *path, bb_error *err) {
  int frames;
  return bb__image_frame_count(path, &frames, err);
}

static bb_status call_basis_load(const char *path, bb_error *err) {
  bb_basis b;
  return bb__basis_load(path, &b, err);
}

static bb_status call_file_hash(const char *path, bb_error *err) {
  uint64_t h;
  return bb_file_hash(path, &h, err);
}

static const struct {
  const char *name;
  child_call_fn fn;
} READERS[] = {
    {"bb_image_read", call_read},       {"bb_image_read_info", call_read_info},
    {"bb__image_read_mip", call_read_mip}, {"bb__image_frame_count", call_frame_count},
    {"bb__basis_load", call_basis_load}, {"bb_file_hash", call_file_hash},
};

/* Every reader refuses path at once: BB_ERR_IO, one line naming the file
 * and saying what it is, well under a second (a FIFO with no writer used to
 * block in open() for ever, /dev/zero to be read without end). */
static void expect_refused_at_once(const char *path, const char *what) {
  for (size_t i = 0; i < sizeof READERS / sizeof READERS[0]; i++) {
    child_outcome o = child_call(READERS[i].fn, path, 10, 0);
    cr_expect_eq(o.signal, 0, "%s(%s): killed by signal %d after %.1f s (it blocked)",
                 READERS[i].name, path, o.signal, o.seconds);
    if (o.signal) continue;
    cr_expect_eq(o.status, BB_ERR_IO, "%s(%s): %s", READERS[i].name, path, o.message);
    cr_expect(strstr(o.message, path) && strstr(o.message, what), "%s: '%s'", READERS[i].name,
              o.message);
    cr_expect_null(strchr(o.message, '\n'), "%s: '%s'", READERS[i].name, o.message);
    /* (one that blocked is killed by its alarm: the signal above) */
    cr_expect_lt(o.cpu_seconds, 0.5, "%s(%s) took %.2f s of CPU", READERS[i].name, path,
                 o.cpu_seconds);
  }
}

Test(untrusted, a_fifo_is_refused_by_every_reader_without_blocking) {
  const char *fifo = in_scratch_dir("pipe.png");
  cr_assert_eq(mkfifo(fifo, 0600), 0, "mkfifo: %s", strerror(errno));
  expect_refused_at_once(fifo, "is a FIFO, not a regular file");
}

Test(untrusted, a_device_is_refused_by_every_reader) {
  const char *link = in_scratch_dir("zero.png");
  cr_assert_eq(symlink("/dev/zero", link), 0, "symlink: %s", strerror(errno));
  expect_refused_at_once(link, "is a device, not a regular file");
}

/* ------------------------------------------- large files no reader knows */

static bb_status call_height_file_read(const char *path, bb_error *err) {
  bb_image h;
  bb_status st =
      bb__height_file_read(path, BB_CHANNEL_AUTO, 8.0f, NULL, NULL, &h, NULL, err);
  bb_image_free(&h);
  return st;
}

/* A 2 GiB file of zeros (sparse: it costs no disk) under each extension,
 * and the format its message must name. OpenImageIO 2.4 handed a file its
 * extension's reader refused to every other reader, the DICOM reader last,
 * which read it to the end: minutes for 2 GiB, and the DICOM, PNM and IFF
 * readers did so under their own extensions too. */
Test(untrusted, a_large_file_no_reader_knows_is_refused_at_once) {
  static const struct {
    const char *name, *promised;
  } files[] = {
      {"z.png", "PNG"},
      {"z.exr", "OpenEXR"},
      {"z.tga", "TGA"},
      {"z.tif", "TIFF"},
      {"z.jpg", "JPEG"},
      {"z.hdr", "Radiance HDR"},
      {"z.dds", "DDS"},
      {"z.gif", "GIF"},
      {"z.ppm", "PNM"},
      {"z.iff", "IFF"},
      {"z.dcm", "DICOM"},
      {"z.bmp", "BMP"},
      {"z.unknown", "no image format has the extension '.unknown'"},
      {"z", "no extension names its format"},
  };
  static const struct {
    const char *name;
    child_call_fn fn;
  } readers[] = {
      {"bb_image_read", call_read},
      {"bb_image_read_info", call_read_info},
      {"bb__image_read_mip", call_read_mip},
      {"bb__image_frame_count", call_frame_count},
      {"bb__height_file_read", call_height_file_read},
  };
  for (size_t f = 0; f < sizeof files / sizeof files[0]; f++) {
    const char *path = in_scratch_dir(files[f].name);
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    cr_assert(fd >= 0 && ftruncate(fd, (off_t)2 << 30) == 0, "%s: %s", path,
              strerror(errno));
    close(fd);
    for (size_t i = 0; i < sizeof readers / sizeof readers[0]; i++) {
      child_outcome o = child_call(readers[i].fn, path, 10, 0);
      cr_expect_eq(o.signal, 0, "%s(%s): killed by signal %d after %.1f s",
                   readers[i].name, files[f].name, o.signal, o.seconds);
      if (o.signal)
        continue;
      cr_expect_eq(o.status, BB_ERR_FORMAT, "%s(%s): %s", readers[i].name, files[f].name,
                   o.message);
      cr_expect(strstr(o.message, path) && strstr(o.message, files[f].promised),
                "%s(%s): '%s'", readers[i].name, files[f].name, o.message);
      cr_expect_null(strchr(o.message, '\n'), "%s: '%s'", readers[i].name, o.message);
      cr_expect_lt(o.cpu_seconds, 0.5, "%s(%s) took %.2f s of CPU", readers[i].name,
                   files[f].name, o.cpu_seconds);
    }
    unlink(path);
  }
}

/* Files under another format's extension, or none, are read by what their
 * first bytes say, as before: a PNG named .tga, .foo or nothing at all. */
Test(untrusted, an_image_under_another_extension_is_read_by_its_signature) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 8, 4, 1, NULL), BB_OK);
  for (int i = 0; i < 32; i++)
    img.pixels[i] = (float)i / 31.0f;
  bb_write_options o = {BB_DEPTH_16, BB_RANGE_UNIT, NULL, NULL};
  cr_assert_eq(bb__image_write(in_scratch_dir("real.png"), &img, &o, NULL), BB_OK);
  bb_image_free(&img);
  cr_assert_eq(bb_image_read(in_scratch_dir("real.png"), &img, NULL, NULL), BB_OK);
  static const char *names[] = {"png_as.tga", "png_as.exr", "png_as.foo", "png_as"};
  for (size_t n = 0; n < sizeof names / sizeof names[0]; n++) {
    cr_assert_eq(
        rename(in_scratch_dir(n ? names[n - 1] : "real.png"), in_scratch_dir(names[n])),
        0);
    bb_image back;
    bb_image_info info;
    bb_error err;
    cr_assert_eq(bb_image_read(in_scratch_dir(names[n]), &back, &info, &err), BB_OK,
                 "%s: %s", names[n], err.message);
    cr_expect_str_eq(info.format_name, "png", "%s", names[n]);
    cr_expect(back.width == 8 && back.height == 4 && back.channels == 1, "%s", names[n]);
    cr_expect_eq(memcmp(back.pixels, img.pixels, sizeof(float) * 32), 0, "%s", names[n]);
    bb_image_free(&back);
    bb_image_info_free(&info);
  }
  bb_image_free(&img);
}

/* ------------------------------------------------------ third-party messages */

/* What the calls of fn wrote on file descriptor 2 (then restored), as a
 * malloc'd string: the library must print nothing there, whoever asks. */
static char *stderr_during(void (*fn)(const char *path), const char *path) {
  const char *capture = in_scratch_dir("stderr.txt");
  fflush(stderr);
  int saved = dup(STDERR_FILENO);
  int fd = open(capture, O_WRONLY | O_CREAT | O_TRUNC, 0600);
  cr_assert(saved >= 0 && fd >= 0);
  dup2(fd, STDERR_FILENO);
  close(fd);
  fn(path);
  fflush(stderr);
  dup2(saved, STDERR_FILENO);
  close(saved);
  FILE *f = fopen(capture, "rb");
  cr_assert_not_null(f);
  char *text = calloc(1, 4096);
  size_t n = fread(text, 1, 4095, f);
  text[n] = '\0';
  fclose(f);
  return text;
}

/* Every read of a damaged file fails with the library's own one-line
 * message, and nothing else is said. */
static void read_damaged(const char *path) {
  bb_error err;
  bb_image img, h;
  int w, ht, c;
  bb_status st = bb_image_read(path, &img, NULL, &err);
  cr_expect_neq(st, BB_OK, "%s read", path);
  cr_expect(strstr(err.message, path) != NULL, "%s", err.message);
  bb_image_free(&img);
  (void)bb_image_read_info(path, &w, &ht, &c, NULL, &err);
  st = bb__height_load(path, BB_CHANNEL_AUTO, &h, &(bb__height_loaded){0}, &err);
  cr_expect_neq(st, BB_OK, "%s height", path);
  bb_image_free(&h);
}

static void write_bytes(const char *path, const unsigned char *bytes, size_t n) {
  FILE *f = fopen(path, "wb");
  cr_assert_not_null(f);
  cr_assert_eq(fwrite(bytes, 1, n, f), n);
  cr_assert_eq(fclose(f), 0);
}

/* A PNG of noise (poorly compressible, so the pixel data spans most of the
 * file), its bytes returned (malloc'd) with their count. */
static unsigned char *noise_png(size_t *size) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 96, 64, 3, NULL), BB_OK);
  uint32_t s = 7;
  for (size_t i = 0; i < 96u * 64u * 3u; i++) {
    s = s * 1664525u + 1013904223u;
    img.pixels[i] = (float)(s >> 8) / 16777216.0f;
  }
  bb_write_options o = {BB_DEPTH_16, BB_RANGE_UNIT, NULL, NULL};
  cr_assert_eq(bb__image_write(in_scratch_dir("noise.png"), &img, &o, NULL), BB_OK);
  bb_image_free(&img);
  FILE *f = fopen(in_scratch_dir("noise.png"), "rb");
  cr_assert_not_null(f);
  unsigned char *bytes = malloc(1 << 20);
  *size = fread(bytes, 1, 1 << 20, f);
  fclose(f);
  cr_assert_gt(*size, 20000);
  return bytes;
}

/* libpng printed "libpng error: IDAT: Read error: hit end of file" (a
 * truncated file) or "libpng error: IDAT: CRC error" (a damaged one) on
 * stderr, before OpenImageIO returned the error the library reports; the
 * CLI hid it by muting stderr, a Python caller saw it. */
Test(untrusted, a_damaged_png_prints_nothing_on_stderr) {
  size_t n;
  unsigned char *png = noise_png(&n);
  const char *cut = in_scratch_dir("cut.png"), *crc = in_scratch_dir("crc.png"), *header = in_scratch_dir("ihdr.png");
  write_bytes(cut, png, n / 2);
  png[n / 2] ^= 0x55; /* inside the pixel data: the chunk's CRC no longer matches */
  write_bytes(crc, png, n);
  png[n / 2] ^= 0x55;
  png[20] ^= 0x01; /* inside IHDR (the width): its CRC no longer matches */
  write_bytes(header, png, n);
  free(png);
  const char *files[] = {cut, crc, header};
  for (size_t i = 0; i < 3; i++) {
    char *said = stderr_during(read_damaged, files[i]);
    cr_expect_str_empty(said, "%s: stderr got '%s'", files[i], said);
    free(said);
  }
}

/* ------------------------------------------ links planted in temporaries */

/* What another user who may write in the destination's directory does:
 * watch it, and the moment a temporary of bumpbake's
 * appears, replace a file by a link to `target`, and move a directory away
 * and put a link to `decoy` (a directory of theirs, holding links to
 * target under any name bumpbake might open) in its place. They cannot
 * enter bumpbake's private directory (mode 0700, another user's), so the
 * watcher does not either. */
typedef struct planter {
  const char *dir, *target, *decoy;
  atomic_int stop;
  int files, dirs; /* replaced */
} planter;

static void *plant_links(void *arg) {
  planter *p = arg;
  int in = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  cr_assert(in >= 0);
  cr_assert(inotify_add_watch(in, p->dir, IN_CREATE) >= 0);
  char buf[8192] __attribute__((aligned(__alignof__(struct inotify_event))));
  int moved = 0;
  while (!atomic_load(&p->stop)) {
    struct pollfd pfd = {in, POLLIN, 0};
    if (poll(&pfd, 1, 5) <= 0) continue;
    ssize_t n = read(in, buf, sizeof buf);
    for (char *at = buf; n > 0 && at < buf + n;) {
      const struct inotify_event *ev = (const struct inotify_event *)at;
      at += sizeof *ev + ev->len;
      if (!ev->len || strncmp(ev->name, ".bb-tmp-", 8) != 0) continue;
      char path[700], away[700];
      snprintf(path, sizeof path, "%s/%s", p->dir, ev->name);
      struct stat st;
      if (lstat(path, &st) != 0 || S_ISLNK(st.st_mode)) continue; /* gone, or its own link */
      if (S_ISDIR(st.st_mode)) {
        snprintf(away, sizeof away, "%s/moved-%d", p->dir, moved++);
        if (rename(path, away) == 0 && symlink(p->decoy, path) == 0) p->dirs++;
      } else if (unlink(path) == 0 && symlink(p->target, path) == 0) {
        p->files++;
      }
    }
  }
  close(in);
  return NULL;
}

static void write_text(const char *path, const char *text) {
  FILE *f = fopen(path, "w");
  cr_assert_not_null(f);
  fputs(text, f);
  cr_assert_eq(fclose(f), 0);
}

/* A mip-mapped TIFF is written by OpenImageIO opening a name, once per
 * level: that name was the O_EXCL temporary in the destination's directory,
 * and a link planted there between two opens was written through (9 of 9
 * trials). Now it is a name in a private directory reached through its
 * descriptor: whatever the watcher does, the target keeps its bytes, and
 * the file is written whole (or, had the watcher won the race for the
 * directory itself, refused cleanly). */
Test(untrusted, a_link_planted_at_a_temporary_is_not_written_through) {
  const char *out_dir = in_scratch_dir("shared"), *decoy = in_scratch_dir("decoy");
  char target[600];
  snprintf(target, sizeof target, "%s", in_scratch_dir("precious.txt"));
  cr_assert_eq(mkdir(out_dir, 0777), 0);
  cr_assert_eq(mkdir(decoy, 0777), 0);
  write_text(target, "precious\n");
  const char *leaves[] = {"staged.tif", "staged.TIF", "out.tif"};
  for (size_t i = 0; i < 3; i++) {
    char link[700];
    snprintf(link, sizeof link, "%s/%s", decoy, leaves[i]);
    cr_assert_eq(symlink(target, link), 0);
  }
  bb_image img, *levels = NULL;
  int count_made = 0;
  cr_assert_eq(bb_image_alloc(&img, 256, 128, 3, NULL), BB_OK);
  for (size_t i = 0; i < 256u * 128u * 3u; i++) img.pixels[i] = (float)(i % 97) / 97.0f;
  bb_error err;
  cr_assert_eq(bb_mip_chain(&img, BB_MIP_AVERAGE, &levels, &count_made, &err), BB_OK, "%s",
               err.message);
  cr_assert_eq(count_made, 9);

  planter p = {out_dir, target, decoy, 0, 0, 0};
  pthread_t watcher;
  cr_assert_eq(pthread_create(&watcher, NULL, plant_links, &p), 0);
  usleep(20000); /* the watch is in place */
  char out[700];
  snprintf(out, sizeof out, "%s/out.tif", out_dir);
  int written = 0;
  for (int trial = 0; trial < 5; trial++) {
    unlink(out);
    bb_status st = bb__image_write_mips(out, levels, count_made, NULL, &err);
    if (st == BB_OK) {
      written++;
      int count = 0;
      bb_image back;
      cr_assert_eq(bb__image_read_mip(out, 3, &back, NULL, &count, &err), BB_OK, "%s",
                   err.message);
      cr_expect(count == 9 && back.width == 32 && back.height == 16);
      bb_image_free(&back);
    } else {
      cr_expect_eq(st, BB_ERR_IO, "%s", err.message);
    }
  }
  atomic_store(&p.stop, 1);
  pthread_join(watcher, NULL);
  FILE *f = fopen(target, "r");
  char text[64] = {0};
  cr_assert_not_null(f);
  size_t n = fread(text, 1, sizeof text - 1, f);
  fclose(f);
  cr_expect(n == 9 && strcmp(text, "precious\n") == 0,
            "the target was written through (%zu bytes; %d files, %d directories replaced)", n,
            p.files, p.dirs);
  /* With the watcher gone the write goes through (while it runs, a loaded
   * machine lets it win every race: every trial then refused cleanly). */
  unlink(out);
  cr_expect_eq(bb__image_write_mips(out, levels, count_made, NULL, &err), BB_OK, "%s",
               err.message);
  cr_expect_gt(p.files + p.dirs, 0, "the watcher never acted");
  cr_log_info("%d of 5 written; the watcher replaced %d files and %d directories", written,
              p.files, p.dirs);
  bb_mip_chain_free(levels, count_made);
  bb_image_free(&img);
}

/* Short of memory, a PNG write fails somewhere inside OpenImageIO's writer:
 * then libpng's own "libpng error: No IDATs written into file" reached
 * stderr (36 of 80 bakes under `ulimit -v` 534..546 MB), since OpenImageIO
 * gives its writer's handlers to png_create_write_struct. Each write here
 * runs in a child whose data (RLIMIT_DATA: address space would count
 * reserved arenas) may grow by a margin, the margins spanning the write's
 * needs, with stderr on a file. The OpenImageIO module is loaded before
 * the children fork (its ~260 libraries' data is no part of a write's). */
static size_t data_bytes(void) {
  FILE *f = fopen("/proc/self/status", "r");
  char line[256];
  size_t kib = 0;
  while (f && fgets(line, sizeof line, f))
    if (sscanf(line, "VmData: %zu kB", &kib) == 1) break;
  if (f) fclose(f);
  return kib * 1024;
}

Test(untrusted, a_png_write_short_of_memory_prints_nothing_on_stderr) {
#ifdef CHILD_CALL_ASAN
  cr_skip_test("ASan's allocator does not fail like malloc under RLIMIT_DATA");
#endif
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 2048, 2048, 4, NULL), BB_OK);
  for (size_t i = 0; i < 2048u * 2048u * 4u; i++)
    img.pixels[i] = (float)((i * 2654435761u) >> 8 & 255) / 255.0f;
  const char *capture = in_scratch_dir("stderr.txt");
  cr_assert(bb__oiio_module() != NULL, "the OpenImageIO module does not load");
  int failed = 0, written = 0;
  for (int margin_mib = 0; margin_mib <= 40; margin_mib += 1) {
    fflush(NULL);
    pid_t pid = fork();
    cr_assert(pid >= 0);
    if (pid == 0) {
      int fd = open(capture, O_WRONLY | O_CREAT | O_TRUNC, 0600);
      dup2(fd, STDERR_FILENO);
      alarm(30);
      struct rlimit rl;
      rl.rlim_cur = rl.rlim_max = data_bytes() + ((size_t)margin_mib << 20);
      setrlimit(RLIMIT_DATA, &rl);
      bb_error err = {{0}};
      bb_status st = bb__image_write(in_scratch_dir("short.png"), &img, NULL, &err);
      if (st != BB_OK && (!err.message[0] || strchr(err.message, '\n'))) _exit(3);
      _exit(st == BB_OK ? 0 : 1);
    }
    int status = 0;
    cr_assert_eq(waitpid(pid, &status, 0), pid);
    cr_assert(WIFEXITED(status), "margin %d MiB: killed by signal %d", margin_mib,
              WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    cr_expect_neq(WEXITSTATUS(status), 3, "margin %d MiB: a bad message", margin_mib);
    if (WEXITSTATUS(status) == 0) written++; else failed++;
    FILE *f = fopen(capture, "r");
    char said[512] = {0};
    size_t n = f ? fread(said, 1, sizeof said - 1, f) : 0;
    if (f) fclose(f);
    cr_expect_eq(n, 0, "margin %d MiB: stderr got '%s'", margin_mib, said);
    /* A larger margin only writes again, the same way: past the failures,
     * three writes that went through are enough. */
    if (failed > 0 && written >= 3)
      break;
  }
  cr_log_info("%d writes failed short of memory, %d succeeded", failed, written);
  cr_expect_gt(failed, 0, "no margin was short of memory");
  cr_expect_gt(written, 0, "no margin was enough");
  bb_image_free(&img);
}
