/* test_hostile_headers.c: headers that declare what their readers would
 * allocate in open(), before any size check: a 126-byte
 * progressive JPEG of 65500 x 65500 (8.5 GB and 21 s for `info`), a 1 x 1
 * TIFF of 16384 x 16384 tiles (8.5 GB for `bake`), a 91-byte EXR with a
 * 2 GB string attribute (2.2 GB for `info`), GIFs of 65535 x 65535
 * ("vector::_M_default_append"), an RLE SGI declaring 6.6 GB of offset
 * tables in 109 bytes. Each read says what is wrong in one line,
 * at once, with bounded memory; the CLI does too under `ulimit -v
 * 2000000`. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath (cli_harness.h) */
#define _DEFAULT_SOURCE    /* wait4 (child_call.h, cli_harness.h) */

#include <criterion/criterion.h>

#include "bumpbake.h"
#include "image/height_channel.h"
#include "child_call.h"
#include "cli_harness.h"
#include "hostile_headers.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

TestSuite(hostile_headers, .init = harness_setup, .fini = harness_teardown, .timeout = 600);

/* ------------------------------------------------------- the library */

static bb_status read_info(const char *path, bb_error *err) {
  int w, h, c;
  return bb_image_read_info(path, &w, &h, &c, NULL, err);
}

static bb_status read_pixels(const char *path, bb_error *err) {
  bb_image img;
  bb_status st = bb_image_read(path, &img, NULL, err);
  bb_image_free(&img);
  return st;
}

static bb_status load_height(const char *path, bb_error *err) {
  bb_image h;
  bb_status st = bb__height_load(path, BB_CHANNEL_AUTO, &h, &(bb__height_loaded){0}, err);
  bb_image_free(&h);
  return st;
}

/* A memory safety net for the child (the refusals need ~150 MB): a
 * regression fails at the limit instead of taking the machine's memory. */
static const long SAFETY_NET = 3L << 30;

static void expect_refusal(child_call_fn fn, const char *what, const char *path,
                           bb_status want, const char *part) {
  child_outcome o = child_call(fn, path, 30, SAFETY_NET);
  cr_expect_eq(o.signal, 0, "%s(%s): signal %d", what, path, o.signal);
  cr_expect_eq(o.status, want, "%s(%s): status %s, '%s'", what, path, bb_status_name(o.status),
               o.message);
  cr_expect(strstr(o.message, path) && strstr(o.message, part), "%s: '%s' lacks '%s'", what,
            o.message, part);
  cr_expect_null(strchr(o.message, '\n'), "%s: '%s'", what, o.message);
  cr_expect_lt(o.cpu_seconds, 1.0, "%s(%s) took %.2f s of CPU", what, path, o.cpu_seconds);
  cr_expect_lt(o.max_rss_kib, 400L * 1024, "%s(%s) took %ld MiB", what, path,
               o.max_rss_kib / 1024);
}

static void expect_every_read_refuses(const char *path, bb_status want, const char *part) {
  expect_refusal(read_info, "bb_image_read_info", path, want, part);
  expect_refusal(read_pixels, "bb_image_read", path, want, part);
  expect_refusal(load_height, "bb__height_load", path, want, part);
}

/* Each of `count` cases (`size` bytes apart, a reason `reason_at` bytes
 * into each), written to path by `write`, is refused by every read,
 * saying its reason. */
static void expect_each_refused(const char *path, const void *cases, size_t size, size_t count,
                                size_t reason_at, int (*write)(const char *, const void *)) {
  for (size_t i = 0; i < count; i++) {
    const char *c = (const char *)cases + i * size;
    cr_assert_eq(write(path, c), 0, "%s: case %zu", path, i);
    expect_every_read_refuses(path, BB_ERR_FORMAT, *(const char *const *)(c + reason_at));
  }
}

/* A valid file reads: its size, and each sample the `count` values of
 * `want` in turn (none checked when want is NULL). */
static void expect_reads(const char *path, int width, int height, int channels,
                         const float *want, int count) {
  bb_image img;
  bb_error err;
  cr_assert_eq(bb_image_read(path, &img, NULL, &err), BB_OK, "%s", err.message);
  cr_expect(img.width == width && img.height == height && img.channels == channels,
            "%s: %dx%d, %d channels", path, img.width, img.height, img.channels);
  const int samples = img.width * img.height * img.channels;
  for (int i = 0; want && i < samples; i++)
    cr_expect_float_eq(img.pixels[i], want[i % count], 1e-6, "%s: sample %d: %g", path, i,
                       img.pixels[i]);
  bb_image_free(&img);
}

Test(hostile_headers, a_progressive_jpeg_is_refused_from_its_header) {
  const char *path = tmp("p.jpg");
  cr_assert_eq(write_progressive_jpeg(path, 65500, 65500), 0);
  expect_every_read_refuses(path, BB_ERR_SIZE, "a JPEG of 65500x65500 needs 8184 MiB to open");
}

/* The same file at 3000 x 2000 is a real one: it opens, and its pixels
 * (the DC scan of zeros, then the end) read as a mid grey. */
Test(hostile_headers, a_small_progressive_jpeg_still_reads) {
  const char *path = tmp("small.jpg");
  cr_assert_eq(write_progressive_jpeg(path, 3000, 2000), 0);
  int w = 0, h = 0, c = 0;
  bb_error err;
  cr_assert_eq(bb_image_read_info(path, &w, &h, &c, NULL, &err), BB_OK, "%s", err.message);
  cr_expect(w == 3000 && h == 2000 && c == 1);
}

Test(hostile_headers, huge_tiles_are_refused_before_decoding) {
  const char *path = tmp("t.tif");
  cr_assert_eq(write_tiled_tiff(path, 1, 1, 16384, 16384), 0);
  /* The header alone is fine: it describes a 1 x 1 image. */
  int w = 0, h = 0, c = 0;
  bb_error err;
  cr_assert_eq(bb_image_read_info(path, &w, &h, &c, NULL, &err), BB_OK, "%s", err.message);
  cr_expect(w == 1 && h == 1 && c == 1);
  const char *part = "tiles of 16384x16384 with 1 channel need 1024 MiB each";
  expect_refusal(read_pixels, "bb_image_read", path, BB_ERR_SIZE, part);
  expect_refusal(load_height, "bb__height_load", path, BB_ERR_SIZE, part);
}

Test(hostile_headers, an_exr_attribute_larger_than_its_file_is_refused) {
  const char *path = tmp("a.exr");
  cr_assert_eq(write_exr_with_huge_attribute(path, 0x7FFFFFF0u), 0);
  expect_every_read_refuses(path, BB_ERR_FORMAT, "'comment'");
}

Test(hostile_headers, an_exr_attribute_of_no_type_is_refused) {
  const char *path = tmp("u.exr");
  cr_assert_eq(write_exr_with_untyped_attribute(path, 0x6E697274u), 0);
  expect_every_read_refuses(path, BB_ERR_FORMAT, "attribute type for attribute 'junk'");
}

Test(hostile_headers, a_gif_screen_too_large_to_open_says_so) {
  const char *path = tmp("g.gif");
  cr_assert_eq(write_gif_screen(path, 65535, 65535), 0);
  expect_every_read_refuses(path, BB_ERR_SIZE, "a GIF of 65535x65535 needs 16384 MiB to open");
  /* giflib reads any version after "GIF" (the fuzzer's "GIF\x939a"). */
  FILE *f = fopen(path, "r+b");
  cr_assert(f && fseek(f, 3, SEEK_SET) == 0 && fwrite("\x93" "9a", 1, 3, f) == 3 && fclose(f) == 0);
  expect_every_read_refuses(path, BB_ERR_SIZE, "a GIF of 65535x65535 needs 16384 MiB to open");
  /* A screen within what may be opened and read, on a machine that has
   * the memory: where it has not (1.5 GB of address space here), the read
   * refuses it from the header, before OpenImageIO allocates its 1 GiB
   * canvas, naming what it needs. (AddressSanitizer builds run uncapped.) */
#ifndef CHILD_CALL_ASAN
  const char *mid = tmp("m.gif");
  cr_assert_eq(write_gif_screen(mid, 16384, 16384), 0);
  child_outcome o = child_call(read_pixels, mid, 30, 1536L << 20);
  cr_expect_eq(o.signal, 0, "signal %d", o.signal);
  cr_expect_eq(o.status, BB_ERR_MEMORY, "status %s, '%s'", bb_status_name(o.status), o.message);
  cr_expect(strstr(o.message, mid) && strstr(o.message, "a GIF of 16384x16384 needs about") &&
                strstr(o.message, "of memory"),
            "'%s'", o.message);
  cr_expect_lt(o.cpu_seconds, 1.0, "took %.2f s of CPU", o.cpu_seconds);
  cr_expect_lt(o.max_rss_kib, 400L * 1024, "took %ld MiB", o.max_rss_kib / 1024);
#endif
}

/* An RLE SGI's offset tables lie in the file: a header declaring more
 * rows and channels than the file can list is refused before OpenImageIO
 * zeroes 8 bytes for each (65535 x 65535 of them: 34 GB), and the same
 * file declaring what it holds reads. */
Test(hostile_headers, sgi_offset_tables_longer_than_the_file_are_refused) {
  const char *path = tmp("r.sgi");
  cr_assert_eq(write_sgi_rle(path, 65535, 65535), 0);
  expect_every_read_refuses(path, BB_ERR_FORMAT,
                            "declares 4294836225 RLE rows, more than the file of 544 bytes");
  const char *fine = tmp("f.sgi");
  cr_assert_eq(write_sgi_rle(fine, 2, 1), 0);
  /* SGI's rows run bottom to top: the file's first row is the image's last. */
  const float want[4] = {90 / 255.f, 30 / 255.f, 10 / 255.f, 200 / 255.f};
  expect_reads(fine, 2, 2, 1, want, 4);
}

/* Reading an RLE SGI's row allocates the length its table gives, an int:
 * a row running past the end of the file is refused from the header
 * (0xFFFFFFFF asked for 4 GB at the first row read; 0x7FFFFFF0 for 2 GB),
 * and the same file whose row lies in it reads (above). */
Test(hostile_headers, sgi_rle_rows_past_the_end_of_the_file_are_refused) {
  const char *path = tmp("l.sgi");
  cr_assert_eq(write_sgi_rle_rows(path, 2, 1, 0xFFFFFFFFu), 0);
  expect_every_read_refuses(path, BB_ERR_FORMAT,
                            "corrupt image: SGI RLE row 1 of channel 0 declares 4294967295 "
                            "bytes at byte 532, past the end of the file of 544 bytes");
  cr_assert_eq(write_sgi_rle_rows(path, 2, 1, 0x7FFFFFF0u), 0);
  expect_every_read_refuses(path, BB_ERR_FORMAT, "declares 2147483632 bytes at byte 532");
  cr_assert_eq(write_sgi_rle_rows(path, 2, 1, 13), 0); /* one byte past the end */
  expect_every_read_refuses(path, BB_ERR_FORMAT, "declares 13 bytes at byte 532");
}

/* DPX and Cineon readers allocate the user data their header declares,
 * zeroed, in open(), and copy it twice (a 2 KB DPX declaring 768 MiB took
 * 2.5 GB and opened): user data running past the end of the file is
 * refused from the header, in either byte order, and the same files whose
 * 16 bytes of user data lie in them read. */
Test(hostile_headers, dpx_and_cineon_user_data_past_the_end_of_the_file_is_refused) {
  const char *dpx = tmp("u.dpx"), *cin = tmp("u.cin");
  for (int little = 0; little <= 1; little++) {
    cr_assert_eq(write_dpx_user(dpx, 0xC0000000u, 16, little), 0);
    expect_every_read_refuses(dpx, BB_ERR_FORMAT,
                              "corrupt image: its DPX user data of 3221225472 bytes after the "
                              "2048-byte header runs past the end of the file of 2068 bytes");
    cr_assert_eq(write_dpx_user(dpx, 21, 16, little), 0); /* one byte past the end */
    expect_every_read_refuses(dpx, BB_ERR_FORMAT, "user data of 21 bytes");
  }
  cr_assert_eq(write_cineon_user(cin, 0x80000000u, 16), 0);
  expect_every_read_refuses(cin, BB_ERR_FORMAT,
                            "corrupt image: its Cineon user data of 2147483648 bytes after "
                            "the 2048-byte header runs past the end of the file of 2068 bytes");
  for (int little = 0; little <= 1; little++) {
    cr_assert_eq(write_dpx_user(dpx, 16, 16, little), 0);
    const float want[3] = {200 / 255.f, 100 / 255.f, 50 / 255.f};
    expect_reads(dpx, 1, 1, 3, want, 3);
  }
  cr_assert_eq(write_cineon_user(cin, 16, 16), 0);
  expect_reads(cin, 1, 1, 1, NULL, 0); /* Cineon's samples are log: not checked */
}

/* OpenImageIO decodes an RLE BMP whole into width x height bytes, zeroed,
 * in open() (a 54-byte file of 40000 x 40000 took 1.7 GB): that is held to
 * BB_MAX_READ_BYTES from the header, and a small one reads. */
Test(hostile_headers, an_rle_bmp_too_large_to_open_says_so) {
  const char *path = tmp("r.bmp");
  cr_assert_eq(write_bmp_rle8(path, 50000, -50000), 0);
  expect_every_read_refuses(path, BB_ERR_SIZE, "a BMP of 50000x50000 needs 2384 MiB to open");
  cr_assert_eq(write_bmp_rle8(path, 65536, 65536), 0); /* past INT_MAX bytes */
  expect_every_read_refuses(path, BB_ERR_SIZE, "a BMP of 65536x65536 needs 4096 MiB to open");
  cr_assert_eq(write_bmp_rle8(path, 2, 2), 0);
  /* BMP's rows run bottom to top: the white row is the image's last. */
  const float want[4] = {0, 0, 1, 1};
  expect_reads(path, 2, 2, 1, want, 4);
}

typedef struct psd_case {
  uint32_t colour, id, length, name, bottom;
  const char *reason;
} psd_case;

static int write_psd_case(const char *path, const void *c) {
  const psd_case *k = c;
  return write_psd(path, k->colour, k->id, k->length, k->name, k->bottom);
}

/* OpenImageIO's PSD reader allocates, zeroed, in open(): the colour mode
 * data's length (4 GiB took 4.3 GB), each image resource's, a thumbnail's
 * less its 28-byte header, and 8 bytes for each row of each layer
 * channel; it reads alpha channel names until a block's length is used
 * up, forever past the end of the file. Each length must lie in the file,
 * a layer within 300000 a side, its rows within its channel's data; and
 * the same file declaring what it holds reads. */
Test(hostile_headers, psd_lengths_past_the_end_of_the_file_are_refused) {
  const char *path = tmp("h.psd");
  static const psd_case files[] = {
      {0xFFFFFFFFu, 1006, 2, 1, 2,
       "corrupt image: its PSD colour mode data of 4294967295 bytes runs past the end of the "
       "file of 126 bytes"},
      {0, 1058, 0x60000000u, 1, 2,
       "corrupt image: PSD image resource 1058 declares 1610612736 bytes at byte 46, past the "
       "end of the file of 126 bytes"},
      {0, 1006, 2, 255, 2,
       "corrupt image: PSD alpha channel names (resource 1006) run past the end of the file"},
      {0, 1036, 2, 1, 2, "corrupt image: PSD thumbnail resource 1036 of 2 bytes is shorter"},
      {0, 1006, 2, 1, 0x08000000u,
       "corrupt image: PSD layer 0's channel 0 is 2x134217728, past the largest a PSB may be"},
      {0, 1006, 2, 1, 200000, "corrupt image: PSD layer 0's channel 0 declares 200000 rows in 6 "
                              "bytes"},
  };
  expect_each_refused(path, files, sizeof files[0], sizeof files / sizeof files[0],
                      offsetof(psd_case, reason), write_psd_case);
  cr_assert_eq(write_psd(path, 0, 1006, 2, 1, 2), 0);
  const float want[4] = {50 / 255.f, 60 / 255.f, 70 / 255.f, 80 / 255.f}; /* the merged image */
  expect_reads(path, 2, 2, 1, want, 4);
}

typedef struct iff_case {
  uint32_t flags;
  unsigned bytes;
  uint32_t auth, rgba;
  const char *reason;
} iff_case;

static int write_iff_case(const char *path, const void *c) {
  const iff_case *k = c;
  return write_iff(path, k->flags, k->bytes, k->auth, k->rgba);
}

/* OpenImageIO's IFF reader allocates an AUTH or DATE chunk's size, zeroed,
 * in open() (a 52-byte file declaring 1.5 GiB took 1.7 GB), and each tile's
 * RGBA chunk's at the first read; and Debian's build keeps two assertions
 * on the table header's flags, which abort() the process. Each is refused
 * from the header, and the same file without them reads. */
Test(hostile_headers, iff_chunks_past_the_end_and_aborting_flags_are_refused) {
  const char *path = tmp("h.iff");
  static const iff_case files[] = {
      {1, 0, 0x60000000u, 20,
       "corrupt image: IFF AUTH chunk of 1610612736 bytes at byte 52 runs past the end of the "
       "file of 96 bytes"},
      {1, 0, 0xFFFFFFFEu, 20, "IFF AUTH chunk of 4294967294 bytes"}, /* rounds up to 0 */
      {1, 0, 2, 0x60000000u, "corrupt image: IFF tile 0's RGBA chunk of 1610612736 bytes"},
      {1, 0, 2, 4, "corrupt image: IFF tile 0's RGBA chunk of 4 bytes"}, /* less 8: 4 GiB */
      {0x11, 0, 2, 20, "corrupt image: IFF table header flags 0x11 set RGB or alpha with black"},
      {0x04, 1, 2, 20, "corrupt image: IFF table header flags a Z buffer with a byte count of 1"},
  };
  expect_each_refused(path, files, sizeof files[0], sizeof files / sizeof files[0],
                      offsetof(iff_case, reason), write_iff_case);
  cr_assert_eq(write_iff(path, 1, 0, 2, 20), 0);
  const float want[3] = {200 / 255.f, 100 / 255.f, 50 / 255.f};
  expect_reads(path, 2, 2, 3, want, 3);
}

/* OpenImageIO's FITS reader sizes a vector of ints by NAXIS, zeroed, in
 * open() (400000000 took 1.7 GB), and recurses once a 2880-byte block
 * until END (11000 blank blocks overflowed the stack): NAXIS outside 0 to
 * 999 and a header of 1000 blocks without END are refused; a header whose
 * END is in its 1000th block, and a small image, read. */
Test(hostile_headers, fits_axes_and_endless_headers_are_refused) {
  const char *path = tmp("h.fits");
  cr_assert_eq(write_fits(path, "400000000", 0), 0);
  expect_every_read_refuses(path, BB_ERR_FORMAT,
                            "corrupt image: FITS header declares 400000000 axes (NAXIS is 0 to "
                            "999)");
  cr_assert_eq(write_fits(path, "-1", 0), 0);
  expect_every_read_refuses(path, BB_ERR_FORMAT, "FITS header declares -1 axes");
  cr_assert_eq(write_fits(path, "2", -1000), 0);
  expect_every_read_refuses(path, BB_ERR_FORMAT,
                            "corrupt image: FITS header at byte 0 has no END card in its first "
                            "1000 blocks");
  const float want = 200 / 255.f;
  for (int blank = 0; blank <= 999; blank += 999) {
    cr_assert_eq(write_fits(path, "2", blank), 0);
    expect_reads(path, 2, 2, 1, &want, 1);
  }
}

/* OpenImageIO's JPEG 2000 reader decodes the whole image in open(), 4
 * bytes a sample, however little the file holds (82 bytes declaring
 * 12000 x 12000 took 707 MB and opened): held to BB_MAX_READ_BYTES from
 * the SIZ marker, raw or in a JP2 file's jp2c box; the same small files
 * read. */
Test(hostile_headers, a_jpeg2000_too_large_to_open_says_so) {
  const char *j2k = tmp("h.j2k"), *jp2 = tmp("h.jp2");
  cr_assert_eq(write_jpeg2000(j2k, 30000, 30000, 0), 0);
  expect_every_read_refuses(j2k, BB_ERR_SIZE, "a JPEG 2000 of 30000x30000 needs 3433 MiB to open");
  cr_assert_eq(write_jpeg2000(jp2, 30000, 30000, 1), 0);
  expect_every_read_refuses(jp2, BB_ERR_SIZE, "a JPEG 2000 of 30000x30000 needs 3433 MiB to open");
  for (int wrapped = 0; wrapped <= 1; wrapped++) {
    const char *path = wrapped ? jp2 : j2k;
    cr_assert_eq(write_jpeg2000(path, 4, 4, wrapped), 0);
    expect_reads(path, 4, 4, 1, NULL, 0); /* empty code blocks: no value to check */
  }
}

/* OpenImageIO's WebP reader allocates the canvas an animated WebP's VP8X
 * chunk declares, 3 bytes a texel, in open(), whatever its frames hold
 * (up to 2^24 a side; under `ulimit -v` an 88-byte file of 30000 x 30000
 * ran out of memory): held to BB_MAX_READ_BYTES from the header, and the
 * same file of a 2 x 2 canvas reads. */
Test(hostile_headers, a_webp_canvas_too_large_to_open_says_so) {
  const char *path = tmp("c.webp");
  cr_assert_eq(write_webp_canvas(path, 30000, 30000), 0);
  expect_every_read_refuses(path, BB_ERR_SIZE, "a WebP of 30000x30000 needs 2575 MiB to open");
  cr_assert_eq(write_webp_canvas(path, 2, 2), 0);
  const float want[3] = {204 / 255.f, 103 / 255.f, 50 / 255.f};
  expect_reads(path, 2, 2, 3, want, 3);
}

typedef struct pic_case {
  unsigned type, code, run, cut;
  const char *reason;
} pic_case;

static int write_pic_case(const char *path, const void *c) {
  const pic_case *k = c;
  return write_softimage(path, k->type, k->code, k->run, k->cut);
}

/* OpenImageIO's Softimage PIC reader, given a scanline it cannot read
 * (the file ends early; a pure run-length packet of RGB), asks the FILE it
 * has closed for its position (SIGSEGV: the load fuzzer's find), and
 * writes a run longer than its scanline, or alpha alone, past its buffer:
 * each is refused from a walk of the scanlines, and the file read whole
 * reads. */
Test(hostile_headers, softimage_scanlines_the_reader_cannot_read_are_refused) {
  const char *path = tmp("h.pic");
  static const pic_case files[] = {
      {2, 0xE0, 129, 1, "corrupt image: Softimage PIC scanline 1: it runs past the end of the file"},
      {2, 0xE0, 130, 0, "Softimage PIC scanline 0: a run runs past the end of its scanline"},
      {2, 0x10, 129, 0, "corrupt image: its Softimage PIC packets name channel 4 of 1"},
      {1, 0xE0, 2, 0, "a pure run-length packet of more than one byte a pixel"},
  };
  expect_each_refused(path, files, sizeof files[0], sizeof files / sizeof files[0],
                      offsetof(pic_case, reason), write_pic_case);
  cr_assert_eq(write_softimage(path, 2, 0xE0, 129, 0), 0);
  const float want[3] = {200 / 255.f, 100 / 255.f, 50 / 255.f};
  expect_reads(path, 2, 2, 3, want, 3);
}

/* OpenImageIO 2.4's ICO reader fills a bitmap icon's 1-bit mask 8 texels
 * at a time: in an icon under 32 bits whose width is not a multiple of 8
 * it writes past its buffer (the load fuzzer's heap overflow, on a valid
 * file). Refused, saying why; the same icon 8 texels wide reads. */
Test(hostile_headers, an_icon_its_reader_would_overrun_is_refused) {
  const char *path = tmp("three.ico");
  cr_assert_eq(write_ico_bitmap(path, 3, 2), 0);
  expect_every_read_refuses(path, BB_ERR_FORMAT,
                            "icon 0 is a 24-bit bitmap 3 texels wide, which OpenImageIO 2.4's "
                            "ICO reader writes past its buffer");
  const char *fine = tmp("eight.ico");
  cr_assert_eq(write_ico_bitmap(fine, 8, 2), 0);
  const float want[4] = {200 / 255.f, 100 / 255.f, 50 / 255.f, 1.f};
  expect_reads(fine, 8, 2, 4, want, 4);
}

/* The load fuzzer's finds and an audit's files (fuzz/regressions/load/, a
 * byte for the extension index, then the file): each made OpenImageIO's
 * reader allocate 1.6 to 4.3 GB at once in open() or at the first read
 * (zeroed, most of them), or abort (PSD's alpha names),
 * and now is refused from its header, saying why, at once and in little
 * memory. (libpng skips a chunk it cannot allocate: the PNG's read then
 * ends at the end of the file, as before, but without the 1.8 GB.) */
Test(hostile_headers, the_load_fuzzers_finds_are_refused_from_their_headers) {
  static const struct {
    const char *input, *ext, *reason;
  } finds[] = {
      {"exr-attribute-with-no-type", ".exr", "attribute type for attribute 'Softwar?'"},
      {"exr-attribute-name-with-a-newline", ".exr", "attribute type for attribute '?'"},
      {"exr-header-two-parsers-read-differently", ".exr", "'compression' attribute not found"},
      {"gif-of-another-version-with-a-huge-screen", ".gif", "a GIF of 14616x29285 needs 1633 MiB"},
      {"png-text-chunk-of-1.7-gb", ".png", "Read error: hit end of file"},
      {"sgi-rle-offset-tables-of-6.6-gb", ".sgi",
       "declares 1661485524 RLE rows, more than the file of 108 bytes can list"},
      {"dpx-user-data-of-2.2-gb", ".dpx",
       "its DPX user data of 2196890670 bytes after the 2048-byte header runs past"},
      {"fits-naxis-of-400000000", ".fits", "FITS header declares 400000000 axes"},
      {"jpeg2000-of-30000-x-30000-in-82-bytes", ".jp2", "a JPEG 2000 of 30000x30000 needs 3433"},
      {"iff-auth-chunk-of-1.5-gib", ".iff", "IFF AUTH chunk of 1610612736 bytes at byte 52"},
      {"iff-rgb-flags-with-black-abort", ".iff", "IFF table header flags 0x11 set RGB or alpha"},
      {"psd-alpha-names-block-past-the-end-aborts", ".psd",
       "PSD image resource 1006 declares 16 bytes at byte 46, past the end of the file"},
      {"psd-colour-data-of-4-gib", ".psd", "its PSD colour mode data of 4294967295 bytes"},
      {"psd-layer-of-134217728-rows", ".psd", "PSD layer 0's channel 0 is 1x134217728"},
      {"softimage-unreadable-scanline-segv", ".pic",
       "its Softimage PIC channel packets differ in size (248 and 8 bits)"},
      {"sgi-rle-row-length-of-4-gb", ".sgi",
       "SGI RLE row 0 of channel 0 declares 4294967295 bytes at byte 1870300560"},
  };
  for (size_t i = 0; i < sizeof finds / sizeof finds[0]; i++) {
    char from[256];
    snprintf(from, sizeof from, "fuzz/regressions/load/%s", finds[i].input);
    FILE *f = fopen(from, "rb");
    cr_assert_not_null(f, "%s (tests run from the project root)", from);
    unsigned char bytes[4096];
    size_t n = fread(bytes, 1, sizeof bytes, f);
    fclose(f);
    cr_assert_gt(n, 1);
    char name[64];
    snprintf(name, sizeof name, "find%zu%s", i, finds[i].ext);
    const char *path = tmp(name);
    write_bytes(path, bytes + 1, n - 1);
    child_outcome o = child_call(read_info, path, 30, SAFETY_NET);
    cr_expect_eq(o.signal, 0, "%s: signal %d", finds[i].input, o.signal);
    cr_expect(o.status == BB_ERR_FORMAT || o.status == BB_ERR_SIZE, "%s: %s",
              finds[i].input, o.message);
    cr_expect(strstr(o.message, finds[i].reason), "%s: '%s' lacks '%s'", finds[i].input,
              o.message, finds[i].reason);
    cr_expect_null(strchr(o.message, '\n'), "%s: '%s'", finds[i].input, o.message);
    cr_expect_lt(o.cpu_seconds, 1.0, "%s took %.2f s of CPU", finds[i].input, o.cpu_seconds);
    cr_expect_lt(o.max_rss_kib, 400L * 1024, "%s took %ld MiB", finds[i].input,
                 o.max_rss_kib / 1024);
  }
}

/* ---------------------------------------------------------- the CLI */

/* info and bake of each file under `ulimit -v 2000000` (KiB): exit 1, one
 * line naming the file and the reason, well under two seconds of CPU (they
 * take ~0.4 s, start-up). Wall-clock time is not asserted: at load 7 to 10
 * these runs took 2.6 s and failed make test (make hostile bounds the
 * wall clock). */
Test(hostile_headers, info_and_bake_answer_at_once_in_2_gb) {
  const char *jpg = tmp("p.jpg"), *tif = tmp("t.tif"), *exr = tmp("a.exr"), *gif = tmp("g.gif");
  cr_assert_eq(write_progressive_jpeg(jpg, 65500, 65500), 0);
  cr_assert_eq(write_tiled_tiff(tif, 1, 1, 16384, 16384), 0);
  cr_assert_eq(write_exr_with_huge_attribute(exr, 0x7FFFFFF0u), 0);
  cr_assert_eq(write_gif_screen(gif, 65535, 65535), 0);
  const struct {
    const char *path, *reason;
    int info_ok; /* the tiled TIFF's header is a fine 1 x 1 image */
  } files[] = {
      {jpg, "needs 8184 MiB to open", 0},
      {tif, "tiles of 16384x16384", 1},
      {exr, "Attribute 'comment', type 'string': Invalid size", 0},
      {gif, "needs 16384 MiB to open", 0},
  };
  /* ASan reserves terabytes of address space: no cap there, only the
   * peak memory is bounded. */
#ifdef CHILD_CALL_ASAN
  const run_limits two_gb = {-1, -1};
  const long rss_bound_kib = 768L * 1024;
#else
  const run_limits two_gb = {-1, 2000000L * 1024};
  const long rss_bound_kib = 400L * 1024;
#endif
  for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
    const char *const info[] = {"info", files[i].path, NULL};
    const char *const bake[] = {"bake", files[i].path, "--scale", "8", "--normal",
                                tmp("n.png"), NULL};
    for (int k = 0; k < 2; k++) {
      const int is_info = k == 0;
      cli_result r = harness_run_limited(NULL, &two_gb, is_info ? info : bake);
      cr_expect_lt(r.cpu_seconds, 2.0, "%s %s took %.1f s of CPU", is_info ? "info" : "bake",
                   files[i].path, r.cpu_seconds);
      cr_expect_lt(r.max_rss_kib, rss_bound_kib, "%s %s took %ld MiB",
                   is_info ? "info" : "bake", files[i].path, r.max_rss_kib / 1024);
      if (is_info && files[i].info_ok) {
        cr_expect_eq(r.code, 0, "%s", r.err);
      } else {
        cr_expect_eq(r.code, 1, "%s: %s", files[i].path, r.err);
        cr_expect_eq(harness_lines(r.err), 1, "%s", r.err);
        cr_expect(strstr(r.err, files[i].path) && strstr(r.err, files[i].reason), "%s", r.err);
      }
      cli_result_free(&r);
    }
  }
  cr_expect_not(file_exists(tmp("n.png")));
}
