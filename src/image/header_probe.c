/* header_probe.c: a file's header read before OpenImageIO opens it, for
 * the readers that allocate what a header declares inside open() (or at
 * the first read), where no ImageSpec, limit or hook of OpenImageIO 2.4
 * can stop them, and those that crash on what a header declares:
 *
 * - JPEG: open() runs jpeg_start_decompress, which for a progressive (or
 *   any multi-scan) file allocates and zeroes the coefficients of the whole
 *   image, 128 bytes per 8 x 8 block and component, and then reads the
 *   whole file: a 126-byte file declaring 65500 x 65500 took 8.5 GB and
 *   21 s. libjpeg itself reads the header here (jpeg_read_header), so the
 *   blocks counted are libjpeg's own.
 * - GIF: open() allocates a canvas of width x height x 4 bytes for the
 *   logical screen and decodes the first frame into it (65535 x 65535
 *   overflowed an int inside OpenImageIO: "vector::_M_default_append").
 *   The screen's size is two 16-bit numbers at offset 6 of every GIF, after
 *   the 6-byte signature ("GIF87a", "GIF89a"; giflib checks "GIF" only):
 *   a size read at a fixed place, not a parse.
 * - OpenEXR: OpenEXR's C++ reader allocates each attribute's declared size
 *   before reading it (a 91-byte file with a 2 GB string took 2.2 GB), the
 *   chunk offset table (8 bytes a chunk) and two buffers per thread of the
 *   largest chunk, all in open(). OpenEXRCore, OpenEXR's C library, reads
 *   the header here, strictly: it refuses any attribute larger than the
 *   file and any header it cannot read as a whole, and tells the chunk
 *   count and the largest unpacked chunk.
 *
 * - SGI: for an RLE file, open() sizes its two offset tables, 4 bytes for
 *   each row of each channel, from the header's ysize and zsize and zeroes
 *   them before reading them from the file: a 109-byte file declaring
 *   65292 rows of 25447 channels asked for 6.6 GB. The tables lie in the
 *   file, so they can be no larger than it; and reading a row allocates
 *   the length its table gives (0xFFFFFFFF: 4 GB), so each row must lie in
 *   the file (header_walk.c reads the sizes at their fixed offsets, then
 *   the tables).
 *
 * - DPX, Cineon: open() allocates the user data the header declares,
 *   zeroed, and copies it into the image's attributes twice, whether or
 *   not the file holds it (a 2 KB DPX declaring 768 MiB took 2.5 GB and
 *   opened): it must lie in the file (header_walk.c).
 *
 * - BMP: for an RLE file, open() decodes the whole image into width x
 *   height bytes, zeroed first (a 54-byte file of 40000 x 40000 took 1.7
 *   GB): the size and compression are at fixed offsets (header_walk.c).
 *
 * - PSD: open() allocates, zeroed, the colour mode data, image resources
 *   and each layer channel's row tables its lengths declare, and reads
 *   alpha channel names until a resource's length is used up, forever
 *   past the end of the file (OpenImageIO aborts): header_walk_psd.c
 *   walks the sections and checks each length against the file.
 *
 * - IFF: open() allocates an AUTH or DATE chunk's size, zeroed, and
 *   asserts on two table header flag combinations (Debian's build keeps
 *   the assertions: abort()); the first read allocates each tile's size:
 *   header_walk.c walks the chunks, each within the file.
 *
 * - FITS: open() sizes a vector by the NAXIS card, zeroed, before
 *   checking it, and reads a header block by block through a recursion
 *   (11000 blank blocks overflowed the stack): header_walk.c reads the
 *   cards, NAXIS within 0 to 999 and END within 1000 blocks.
 *
 * - JPEG 2000: open() decodes the whole image, 4 bytes a sample, however
 *   little the file holds (82 bytes declaring 12000 x 12000 took 707 MB):
 *   header_walk.c reads the SIZ marker's fixed fields.
 *
 * - WebP: open() allocates the canvas a VP8X chunk declares, 3 or 4
 *   bytes a texel, up to 2^24 a side (address space only: it is not
 *   written until a frame is read): header_walk.c reads its size.
 *
 * - Softimage PIC: the reader uses the FILE it closed after a scanline it
 *   cannot read (SIGSEGV), and writes runs and channels past its buffer
 *   where the file says: header_walk_pic.c walks every scanline first.
 *
 * - DDS: OpenImageIO 2.4.7's reader crashes or hangs on hostile headers
 *   (dds_read.c lists how), so bumpbake reads DDS itself and hands none to
 *   OpenImageIO (image_read.c looks at the first bytes). A DDS reaching
 *   this probe was swapped in after that look: it is refused.
 *
 * Every read goes through pread on the descriptor the read checked
 * (core/input_file.h), so the file probed is the file read. */
#include "image/header_probe.h"
#include "core/internal.h"
#include "image/header_walk.h"
#include "image/signatures.h"

#include <setjmp.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include <jpeglib.h>
#include <openexr.h>

/* -------------------------------------------------------------------- GIF */

static void probe_gif(int fd, const unsigned char *magic, bb__probe *p) {
  (void)fd;
  /* giflib takes any version after "GIF" (it compares 3 bytes), so must this. */
  if (memcmp(magic, "GIF", 3) != 0) return;
  p->format = "GIF";
  p->width = magic[6] | magic[7] << 8;
  p->height = magic[8] | magic[9] << 8;
  p->open_bytes = (double)p->width * (double)p->height * 4.0;
}

/* ------------------------------------------------------------------- JPEG */

typedef struct fd_source {
  struct jpeg_source_mgr pub;
  int fd;
  off_t offset;
  JOCTET buffer[4096];
} fd_source;

static void source_init(j_decompress_ptr cinfo) { (void)cinfo; }

static boolean source_fill(j_decompress_ptr cinfo) {
  fd_source *src = (fd_source *)cinfo->src;
  size_t n = bb__probe_read(src->fd, src->buffer, sizeof src->buffer, (double)src->offset);
  if (n == 0) { /* the file ends: an end-of-image marker, as libjpeg's own source does */
    src->buffer[0] = 0xFF;
    src->buffer[1] = JPEG_EOI;
    n = 2;
  } else {
    src->offset += (off_t)n;
  }
  src->pub.next_input_byte = src->buffer;
  src->pub.bytes_in_buffer = n;
  return TRUE;
}

static void source_skip(j_decompress_ptr cinfo, long count) {
  fd_source *src = (fd_source *)cinfo->src;
  if (count <= 0) return;
  if ((size_t)count <= src->pub.bytes_in_buffer) {
    src->pub.next_input_byte += count;
    src->pub.bytes_in_buffer -= (size_t)count;
    return;
  }
  src->offset += (off_t)((size_t)count - src->pub.bytes_in_buffer);
  src->pub.bytes_in_buffer = 0;
}

static void source_term(j_decompress_ptr cinfo) { (void)cinfo; }

typedef struct quiet_errors {
  struct jpeg_error_mgr pub;
  jmp_buf escape;
} quiet_errors;

/* libjpeg's default handlers print on stderr and exit(). */
static void jpeg_fail(j_common_ptr cinfo) { longjmp(((quiet_errors *)cinfo->err)->escape, 1); }
static void jpeg_quiet(j_common_ptr cinfo, int level) { (void)cinfo, (void)level; }
static void jpeg_no_output(j_common_ptr cinfo) { (void)cinfo; }

static void probe_jpeg(int fd, bb__probe *p) {
  struct jpeg_decompress_struct cinfo;
  quiet_errors jerr;
  fd_source src;
  memset(&src, 0, sizeof src);
  cinfo.err = jpeg_std_error(&jerr.pub);
  jerr.pub.error_exit = jpeg_fail;
  jerr.pub.emit_message = jpeg_quiet;
  jerr.pub.output_message = jpeg_no_output;
  if (setjmp(jerr.escape)) { /* a header libjpeg cannot read: the reader fails as well */
    jpeg_destroy_decompress(&cinfo);
    return;
  }
  jpeg_create_decompress(&cinfo);
  src.fd = fd;
  src.pub.init_source = source_init;
  src.pub.fill_input_buffer = source_fill;
  src.pub.skip_input_data = source_skip;
  src.pub.resync_to_restart = jpeg_resync_to_restart;
  src.pub.term_source = source_term;
  cinfo.src = &src.pub;
  if (jpeg_read_header(&cinfo, TRUE) == JPEG_HEADER_OK) {
    p->format = "JPEG";
    p->width = (int)cinfo.image_width;
    p->height = (int)cinfo.image_height;
    /* A multi-scan file is buffered whole as coefficients (jdcoefct.c):
     * each component's blocks, rounded up to its sampling factors. */
    if (jpeg_has_multiple_scans(&cinfo))
      for (int c = 0; c < cinfo.num_components; c++) {
        const jpeg_component_info *comp = &cinfo.comp_info[c];
        double w = comp->width_in_blocks, h = comp->height_in_blocks;
        if (comp->h_samp_factor > 0) w = comp->h_samp_factor * ((w + comp->h_samp_factor - 1) / comp->h_samp_factor);
        if (comp->v_samp_factor > 0) h = comp->v_samp_factor * ((h + comp->v_samp_factor - 1) / comp->v_samp_factor);
        p->open_bytes += w * h * (double)sizeof(JBLOCK);
      }
  }
  jpeg_destroy_decompress(&cinfo);
}

/* ---------------------------------------------------------------- OpenEXR */

typedef struct exr_stream {
  int fd;
  int64_t size;
  char message[256];
} exr_stream;

static int64_t exr_read(exr_const_context_t ctxt, void *user, void *buffer, uint64_t size,
                        uint64_t offset, exr_stream_error_func_ptr_t error) {
  (void)ctxt, (void)error;
  const exr_stream *s = user;
  if (offset > (uint64_t)s->size) return 0;
  return (int64_t)bb__probe_read(s->fd, buffer, size, (double)offset);
}

static int64_t exr_size(exr_const_context_t ctxt, void *user) {
  (void)ctxt;
  return ((const exr_stream *)user)->size;
}

/* OpenEXRCore's default handler prints on stderr: keep the first message,
 * on one line (it quotes names from the file, control characters and all). */
static void exr_message(exr_const_context_t ctxt, exr_result_t code, const char *msg) {
  void *user = NULL;
  if (exr_get_user_data(ctxt, &user) != EXR_ERR_SUCCESS || !user) return;
  exr_stream *s = user;
  if (s->message[0]) return;
  snprintf(s->message, sizeof s->message, "%s", msg ? msg : exr_get_default_error_message(code));
  for (char *c = s->message; *c; c++)
    if ((unsigned char)*c < 0x20 || *c == 0x7F) *c = '?';
}

static bb_status probe_exr(int fd, const char *path, bb__probe *p, bb_error *err) {
  exr_stream stream = {fd, (int64_t)p->file_bytes, {0}};
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.user_data = &stream;
  init.read_fn = exr_read;
  init.size_fn = exr_size;
  init.error_handler_fn = exr_message;
  /* Strict: the lenient parse skips what it cannot read and may then see
   * other attributes than OpenEXR's C++ reader does (the fuzzer found one
   * whose next "attribute" the C++ reader took as 1.6 GB). */
  init.flags = EXR_CONTEXT_FLAG_STRICT_HEADER;
  exr_context_t ctxt = NULL;
  exr_result_t rv = exr_start_read(&ctxt, path, &init);
  /* Any report refuses, even one OpenEXRCore would go on after. */
  if (rv != EXR_ERR_SUCCESS || stream.message[0]) {
    exr_finish(&ctxt);
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a readable image: %s", path,
                    stream.message[0] ? stream.message : exr_get_default_error_message(rv));
  }
  p->format = "OpenEXR";
  int parts = 0;
  if (exr_get_count(ctxt, &parts) != EXR_ERR_SUCCESS) parts = 0;
  for (int part = 0; part < parts; part++) {
    if (part == 0) {
      exr_attr_box2i_t dw;
      if (exr_get_data_window(ctxt, 0, &dw) == EXR_ERR_SUCCESS) {
        p->width = (int)((int64_t)dw.max.x - dw.min.x + 1);
        p->height = (int)((int64_t)dw.max.y - dw.min.y + 1);
      }
    }
    int32_t chunks = 0;
    if (exr_get_chunk_count(ctxt, part, &chunks) == EXR_ERR_SUCCESS && chunks > 0) {
      p->table_bytes += 8.0 * chunks;
      p->table_entries = "chunks";
    }
    exr_storage_t storage;
    uint64_t unpacked = 0;
    if (exr_get_storage(ctxt, part, &storage) == EXR_ERR_SUCCESS &&
        (storage == EXR_STORAGE_SCANLINE || storage == EXR_STORAGE_TILED) &&
        exr_get_chunk_unpacked_size(ctxt, part, &unpacked) == EXR_ERR_SUCCESS &&
        (double)unpacked > p->chunk_bytes)
      p->chunk_bytes = (double)unpacked;
  }
  exr_finish(&ctxt);
  return BB_OK;
}

/* ------------------------------------------------------------------ probe */

/* The formats header_walk.h reads by hand, by OpenImageIO's name for them
 * (signatures.h: the reader a file's first bytes name). */
static const struct {
  const char *format;
  void (*probe)(int fd, const unsigned char *head, bb__probe *p);
} WALKS[] = {
    {"dpx", bb__probe_dpx},   {"cineon", bb__probe_cineon},     {"bmp", bb__probe_bmp},
    {"psd", bb__probe_psd},   {"iff", bb__probe_iff},           {"fits", bb__probe_fits},
    {"webp", bb__probe_webp}, {"jpeg2000", bb__probe_jpeg2000}, {"softimage", bb__probe_softimage},
    {"ico", bb__probe_ico},
};

bb_status bb__probe_header(int fd, const char *path, bb__probe *p, bb_error *err) {
  memset(p, 0, sizeof *p);
  struct stat st;
  if (fstat(fd, &st) != 0) return BB_OK; /* the reader will say what is wrong */
  p->file_bytes = (double)st.st_size;
  unsigned char magic[12] = {0};
  const size_t got = bb__probe_read(fd, magic, sizeof magic, 0);
  if (got < 4) return BB_OK;
  if (magic[0] == 0xFF && magic[1] == 0xD8 && magic[2] == 0xFF) {
    probe_jpeg(fd, p);
    return BB_OK;
  }
  if (magic[0] == 0x76 && magic[1] == 0x2F && magic[2] == 0x31 && magic[3] == 0x01)
    return probe_exr(fd, path, p, err);
  if (memcmp(magic, "DDS ", 4) == 0)
    return bb__fail(err, BB_ERR_FORMAT, "%s: a DDS file swapped in while it was being opened",
                    path);
  if (magic[0] == 0x01 && magic[1] == 0xDA) {
    if (got == sizeof magic) bb__probe_sgi(fd, magic, p); /* shorter: the reader fails its header read */
    return BB_OK;
  }
  const char *format = bb__format_by_content(magic, (unsigned long)got);
  for (size_t i = 0; format && i < sizeof WALKS / sizeof WALKS[0]; i++)
    if (strcmp(format, WALKS[i].format) == 0) {
      WALKS[i].probe(fd, magic, p);
      return BB_OK;
    }
  probe_gif(fd, magic, p);
  return BB_OK;
}
