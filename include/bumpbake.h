/* bumpbake.h: bake normal maps, self-shadowed bump maps and ambient occlusion
 * from height maps.
 *
 * Conventions, fixed once for the whole API:
 * - Images are bb_image: float32 pixels, row-major, channels interleaved,
 *   row 0 is the TOP row of the picture, column 0 the left column.
 * - Tangent frame: x = column (right), y = row (DOWN), z = up out of the
 *   surface ("DirectX style", Source engine). --normal-y up flips y on output.
 * - Heights: a height image holds normalised heights h (integer inputs are
 *   value / max code, so h is in [0, 1]; float inputs are used as they are).
 *   Geometry is in texels: texel (x, y) is the vertex (x, y, height_scale*h).
 * - Surface model: two triangles per cell, (x,y)-(x+1,y)-(x,y+1) and
 *   (x+1,y)-(x+1,y+1)-(x,y+1), split along the (x+1,y)-(x,y+1) diagonal
 *   (the Embree peer's mesh; Valve's splits along the other diagonal, see
 *   docs/conventions.md). Addressing is periodic (the texture tiles) unless
 *   BB_ADDRESS_CLAMP extends the border texels.
 * - Normals are unit vectors in [-1, 1]; integer files store 0.5 + 0.5*N,
 *   float files store N. Visibility, ssbump, weights and ao are in [0, 1];
 *   integer files store value * max code, float files store the value.
 * - Half-Life 2 basis: B0 = (sqrt(2/3), 0, 1/sqrt(3)),
 *   B1 = (-1/sqrt(6), 1/sqrt(2), 1/sqrt(3)), B2 = (-1/sqrt(6), -1/sqrt(2),
 *   1/sqrt(3)); optional B3 = (0, 0, 1). Bakes may use other bases
 *   (bb_basis: "dirs:N", vectors of the caller's): one channel per direction.
 * - Errors: fallible calls return bb_status and, when err is not NULL, write
 *   a one-line message into it. There is no global error state.
 * - Ownership: a function that fills a bb_image allocates its pixels; the
 *   caller frees them with bb_image_free().
 * - Parsers of names ("vertex", "luma", "-y"...) return BB_OK, or
 *   BB_ERR_ARGUMENT with a message listing the names accepted.
 * docs/conventions.md gives the frame, units and formulas in full.
 *
 * The header reads family by family, each using only the ones before it:
 * the folders of src/, in the order of docs/how-it-works.md ("Layers").
 * Each family's section opens with its folder's name and what it holds;
 * `make check-layers` holds the sections to that order.
 */
#ifndef BUMPBAKE_H
#define BUMPBAKE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* =====================================================================
 * core: status, errors, limits, images
 * ===================================================================== */

#define BB_VERSION_STRING "0.4.0"
/* The ABI's number: libbumpbake.so's soname is libbumpbake.so.0.N. It
 * changes only when a change breaks programs built against the last
 * release (`make check-abi` says so), not with each release: one that
 * only adds functions keeps it. */
#define BB_ABI_VERSION 5

/* Largest accepted image: each side at most BB_MAX_DIMENSION texels and at
 * most BB_MAX_PIXELS texels in all (32768 x 32768), checked before
 * allocating. What a machine can bake is less: reads and bakes estimate
 * their memory from the sizes first and refuse, naming the estimate and
 * what is available (the machine's free memory), what will not fit. */
#define BB_MAX_DIMENSION 65536
#define BB_MAX_PIXELS (32768L * 32768L)

/* Most bytes of samples a read may take: BB_MAX_READ_BYTES_PER_TEXEL a
 * texel (an RGBA float image), and BB_MAX_READ_BYTES (1 GiB) whatever the
 * size (so 1 GiB up to 8192 x 8192, 4 GiB at 16384 x 16384): both the
 * file's own samples (texels x channels x bytes per sample, as its header
 * declares them) and the floats decoded (texels x channels read x 4) must
 * fit, checked before anything is allocated, and then what is available
 * (the machine's free memory) must hold them. What a reader allocates to open a
 * file at all (see bb_image_read_info) stays within BB_MAX_READ_BYTES
 * whatever the size. The first read or write also lowers OpenImageIO's
 * process-wide "limits:imagesize_MB" to BB_MAX_PIXELS x 16 bytes (16384)
 * and "limits:channels" to 64 when they are higher, and sets its
 * "exr_threads" to -1 (OpenImageIO leaves OpenEXR's thread pool alone: its
 * own crashed when started short of memory). The first OpenEXR write
 * installs bumpbake's provider for OpenEXR's global pool, unless the
 * process set that pool up first: it compresses the chunks of the EXR files
 * bumpbake writes on the write's threads (bb_outputs_write's, all cores for
 * any other image it writes), and leaves every other read and write of OpenEXR on its
 * own thread. */
#define BB_MAX_READ_BYTES (1L << 30)
#define BB_MAX_READ_BYTES_PER_TEXEL 16

/* Largest |height_scale x h| a bake accepts, in texels: scaled heights are
 * floats and are differenced, so they keep a factor of 4 below FLT_MAX. */
#define BB_MAX_HEIGHT_TEXELS 8.5e37

/* Most threads a bake, render or renderbump accepts (0 = all cores). */
#define BB_MAX_THREADS 4096
/* Largest smoothing radius a bake accepts, in texels: beyond a few hundred
 * the window covers any texture anyway. */
#define BB_MAX_FILTER_RADIUS 4096
/* Largest ray origin lift (texels) and lobe power a bake accepts. */
#define BB_MAX_BIAS_TEXELS 1.0e6
#define BB_MAX_POWER 1.0e6

/* Most rays a bake's budget may name (--rays), and most
 * azimuth slices: round(sqrt(65536)) = 256. */
#define BB_MAX_RAYS 65536
#define BB_MAX_SLICES 256

/* Most directions a basis may have: each costs one channel of ssbump,
 * weights and the trace's sums (memory) and one table per slice (time). */
#define BB_MAX_BASIS 16

/* Largest mesh a model file may give renderbumpflat: vertices and triangles
 * each. */
#define BB_MAX_MESH_ELEMENTS (1UL << 27)

/* What reading one model (renderbumpflat's) may take. Model files are untrusted,
 * and Assimp's importers build their own structures before bumpbake sees a
 * triangle, so the import runs in a child process held to these limits:
 * - BB_MAX_MODEL_BYTES: the model file and every file it refers to (a glTF's
 *   buffers, an OBJ's .mtl), 256 MiB together, checked before each is read;
 * - BB_MAX_MODEL_TRIANGLES: triangles after polygons are split and every
 *   instance of a mesh is placed (8 Mi), and at most three times as many
 *   vertices, checked on the importer's scene before it is post-processed
 *   or copied;
 * - BB_MAX_IMPORT_MEMORY: memory the importer may take beyond the process's
 *   own (4 GiB; Assimp takes 8 to 27 times an OBJ's size: 600 MiB for a
 *   1 M-triangle grid with normals, 76 MB; 2 GiB for 10 M triangles of
 *   "f 1 2 3", 80 MB);
 * - BB_MAX_IMPORT_SECONDS: CPU seconds of the import (120; four times as
 *   many of wall-clock time).
 * A model over one of them is refused with BB_ERR_SIZE or BB_ERR_MEMORY. */
#define BB_MAX_MODEL_BYTES (256L << 20)
#define BB_MAX_MODEL_TRIANGLES (1L << 23)
#define BB_MAX_IMPORT_MEMORY (4L << 30)
#define BB_MAX_IMPORT_SECONDS 120

/* Most rasterising a flat render bump may do: the samples its triangles
 * reach (each triangle's samples, bounded by its area and by the part of
 * its box inside the image, plus one per sample row it spans) at most 256
 * times the image's samples plus 256 per triangle drawn. A sculpt covers
 * its image a few times over; a pile of triangles drawn over one another
 * thousands of times is refused (BB_ERR_SIZE) before anything is drawn. */
#define BB_MAX_RENDERBUMP_LAYERS 256

typedef enum bb_status {
  BB_OK = 0,          /* success */
  BB_ERR_ARGUMENT,    /* a parameter is out of range or inconsistent */
  BB_ERR_IO,          /* a file is missing, unreadable or unwritable */
  BB_ERR_FORMAT,      /* corrupt, truncated or unsupported image; unknown extension */
  BB_ERR_SIZE,        /* zero width or height, or over the documented maximum */
  BB_ERR_VALUE,       /* NaN or infinite value where a finite one is needed */
  BB_ERR_MEMORY,      /* an allocation failed */
  BB_ERR_CANCELLED    /* a progress callback asked to stop; nothing was made */
} bb_status;

/* Caller-owned error message, filled where the error is detected. */
typedef struct bb_error {
  char message[512];
} bb_error;

/* Short name of a status ("ok", "bad argument", ...); never NULL. */
const char *bb_status_name(bb_status status);

/* Text from a file (a file name, a description, a VTF's KVD, a message
 * holding them) made safe to show a person: s is written into out
 * (capacity cap, always terminated, cut short when full) with every byte of
 * what could drive a terminal or reorder what it shows escaped as \xNN:
 * the C0 controls, DEL, the C1 controls U+0080..U+009F, the bidirectional
 * controls (U+061C, U+200E, U+200F, U+202A..U+202E, U+2066..U+2069, with
 * which "a\u202egnp.exe" shows as "aexe.png") and bytes that are not UTF-8.
 * Returns out. The command line prints every line through it. */
const char *bb_text_printable(const char *s, char *out, size_t cap);

/* word quoted for a POSIX shell: as it is when every byte is a letter, a
 * digit, one of "@%+=:,./-_" or a byte of UTF-8 beyond ASCII (so plain
 * paths and values keep their bytes), else in single quotes with each
 * quote in it given as '\'' ("my rock.png" -> 'my rock.png', "" -> '').
 * sh reads back the word itself, whatever its bytes. Every command line
 * the library spells (the provenance's command, bb_command_text) quotes
 * its words so; a client that records the words typed
 * (bb_command_set_record) quotes them with this. malloc'd; NULL
 * when word is NULL or out of memory. */
char *bb_text_shell_quoted(const char *word);

typedef struct bb_image {
  int width;      /* texels */
  int height;     /* texels */
  int channels;   /* interleaved floats per texel */
  float *pixels;  /* width*height*channels floats, row 0 at the top */
} bb_image;

/* The size rule of bb_image_alloc, without allocating: BB_OK, or its
 * error (BB_ERR_SIZE, BB_ERR_ARGUMENT) for an image of that size, so a
 * caller can refuse one before making it (Python checks an array's shape
 * before copying it). */
bb_status bb_image_size_check(int width, int height, int channels, bb_error *err);

/* Allocates a zeroed image. Rejects sizes <= 0, over BB_MAX_DIMENSION or
 * BB_MAX_PIXELS, and channel counts outside 1..64 (overflow-checked).
 * Returns BB_ERR_SIZE, BB_ERR_ARGUMENT or BB_ERR_MEMORY on failure, leaving
 * img->pixels NULL. */
bb_status bb_image_alloc(bb_image *img, int width, int height, int channels,
                         bb_error *err);

/* Frees the pixels and zeroes the struct; safe on a zeroed struct. */
void bb_image_free(bb_image *img);

/* Pointer to texel (x, y), channel 0. No bounds check beyond debug asserts. */
float *bb_image_texel(const bb_image *img, int x, int y);

/* Addressing of texels outside the image. */
typedef enum bb_addressing {
  BB_ADDRESS_PERIODIC = 0, /* the texture tiles: h(x + W, y) = h(x, y) */
  BB_ADDRESS_CLAMP         /* border texels extend outwards */
} bb_addressing;

/* Progress callback: done out of total work units. Return 0 to go on,
 * nonzero to cancel: the call it reports on then stops as soon as the work
 * in flight ends and returns BB_ERR_CANCELLED, making nothing. */
typedef int (*bb_progress_fn)(void *user, long done, long total);

/* A remark about an input that is not an error: which channel became the
 * height, a lossy or shallow input. path names the file (may be NULL);
 * text is one line without it. Called on the thread that reads the file. */
typedef void (*bb_note_fn)(void *user, const char *path, const char *text);

/* A rectangle of texels, x0..x0+width-1 by y0..y0+height-1. */
typedef struct bb_region {
  int x0, y0, width, height;
} bb_region;

/* How float values map to integer codes. */
typedef enum bb_range {
  BB_RANGE_UNIT = 0, /* [0, 1] stored as value * max code (ssbump, ao, height) */
  BB_RANGE_SIGNED    /* [-1, 1] stored as (0.5 + 0.5 * value) * max code (normals) */
} bb_range;

/* ----------------------------------------------------------- map kinds */

/* Every kind of map bumpbake makes, reads or writes, named once. The first
 * BB_MAP_BAKED_COUNT are the maps a bake makes, in the order of this enum
 * everywhere (the command line's options, JSON, Python's bumpbake.OUTPUTS,
 * the bits of a bake's outputs). New kinds are appended. */
typedef enum bb_map_kind {
  BB_MAP_NORMAL = 0, /* unit N, 3 channels */
  BB_MAP_WEIGHTS,    /* w_c = sat(N.B_c)^2 / sum (normal2ssbump), one channel per
                        basis direction */
  BB_MAP_SSBUMP,     /* s_c = max(0, N.B_c) vis_c, one channel per basis
                        direction (traced) */
  BB_MAP_AO,         /* ambient occlusion, 1 channel (traced) */
  BB_MAP_BENT,       /* bent normal, 3 channels (traced) */
  BB_MAP_FILTERED,   /* the smoothed height h, 1 channel */
  BB_MAP_SLOPE,      /* flipcode's slope bytes / 255 in channel 0 */
  BB_MAP_PLAIN,      /* any other image (a height, a colour, a packed map) */
  BB_MAP_KIND_COUNT  /* number of kinds, not a kind */
} bb_map_kind;

/* The kinds a bake makes: BB_MAP_NORMAL .. BB_MAP_FILTERED. */
#define BB_MAP_BAKED_COUNT 6
/* Bit of a kind in masks of maps (a bake's outputs, bb_command_set_in_memory's). */
#define BB_MAP_BIT(kind) (1u << (unsigned)(kind))
/* Every kind a bake makes. */
#define BB_MAPS_BAKED ((1u << (unsigned)BB_MAP_BAKED_COUNT) - 1u)
/* The kinds that need the tracer: ssbump, ao and bent. */
#define BB_MAPS_TRACED \
  (BB_MAP_BIT(BB_MAP_SSBUMP) | BB_MAP_BIT(BB_MAP_AO) | BB_MAP_BIT(BB_MAP_BENT))

/* What one kind is, so a client can list, name and store the maps without
 * a table of its own. Static data; never freed. */
typedef struct bb_map_kind_info {
  const char *name;        /* "normal", "weights", "ssbump", "ao", "bent",
                              "filtered", "slope", "plain": names in
                              provenance, files, JSON, options */
  const char *description; /* one line for help texts */
  int channels;            /* channels of the image; 0 = one per basis
                              direction (bb_basis.count) */
  int file_channels;       /* channels a file of the kind needs at least (3
                              for a basis map: Half-Life 2's basis); what
                              bb_combine_* and bb_render_map_read act on */
  bb_range range;          /* values: BB_RANGE_SIGNED in [-1, 1] (normal,
                              bent), else BB_RANGE_UNIT in [0, 1] (the
                              filtered height of a float input may leave it) */
  int needs_trace;         /* 1: made only by tracing (ssbump, ao, bent) */
  int unit_vectors;        /* 1: unit vectors (normal, bent): read decoded
                              (bb_normal_map_decode), mips renormalised
                              (BB_MIP_RENORMALIZE), DDS default BC5 */
  uint32_t vtf_flags;      /* the VTF flag a texture of it carries:
                              BB_VTF_FLAG_NORMAL (normal, bent),
                              BB_VTF_FLAG_SSBUMP (ssbump, weights: Source's
                              shaders then use the ssbump blend), else 0 */
} bb_map_kind_info;

/* The description of kind, or NULL for a value outside
 * 0..BB_MAP_KIND_COUNT-1. */
const bb_map_kind_info *bb_map_kind_get(bb_map_kind kind);

/* =====================================================================
 * files: checked, all-or-nothing writes of files; provenance texts read
 * ===================================================================== */

/* ---------------------------------------------------------- safe files */

/* A file written in full (and fsynced) under a temporary name next to its
 * destination, waiting to be renamed into place. A program writing several
 * files stages them all and commits only when every one was written, so a
 * failure changes nothing on disk (bumpbake bake does this). */
typedef struct bb_staged_file bb_staged_file;

/* ---------------------------------------------------- provenance texts */

/* What an image description holds, for readers of provenance. */
typedef enum bb_provenance_class {
  BB_PROVENANCE_NONE = 0, /* no text, or another tool's description */
  BB_PROVENANCE_INTACT,   /* bumpbake provenance: every line "key=value" */
  BB_PROVENANCE_DAMAGED   /* bumpbake provenance whose lines were cut or
                             re-wrapped (by a format or another tool), so a
                             key-by-key diff would mislead */
} bb_provenance_class;


/* One "key=value" line of a provenance text, as pointers into it (not
 * terminated). */
typedef struct bb_provenance_entry {
  const char *key;
  size_t key_length;
  const char *value;
  size_t value_length;
} bb_provenance_entry;


/* =====================================================================
 * texture: engine textures (VTF, DDS) and Source materials, which
 * OpenImageIO does not write
 * ===================================================================== */

/* ------------------------------- engine textures: Source VTF and DDS */

/* A texture an engine loads as it is: Valve's VTF (Source) or DirectX's DDS
 * (Unreal, Unity, Godot, id Tech and most others), with its mip chain and
 * block compression (BC1..BC5, by bumpbake's own codec). OpenImageIO reads
 * DDS but writes neither, so bumpbake writes both containers itself.
 *
 * Every format stores what the engine samples: values in [0, 1] as they
 * are and normal maps as 0.5 + 0.5 N, the float formats included (a shader
 * unpacks 2 t - 1 whatever the format; this differs from bumpbake's float
 * image files (.exr), which store N). Integer and block formats clamp to [0, 1]
 * and round to 8 bits first. Channels: 1 is grey (v, v, v), 2 are R and G,
 * 3 are R, G, B; alpha is 1 unless the image has a fourth channel. */

/* Pixel format of an engine texture. Names, as --texture-format takes them
 * (bb_option_parse), in quotes. */
typedef enum bb_texture_format {
  BB_TEXTURE_FORMAT_DEFAULT = 0, /* VTF: DXT1 (DXT5 for 4 channels), as Valve ships
                                    ssbump and normal maps. DDS: BC5 for a normal map,
                                    BC4 for 1 channel, BC5 for 2, BC1 for 3, BC3 for 4 */
  BB_TEXTURE_FORMAT_BC1,     /* "bc1" or "dxt1": R, G, B, 4 bits a texel; VTF, DDS */
  BB_TEXTURE_FORMAT_BC3,     /* "bc3" or "dxt5": R, G, B, A, 8 bits a texel; VTF, DDS */
  BB_TEXTURE_FORMAT_BC4,     /* "bc4": one channel (ao, height), 4 bits; DDS */
  BB_TEXTURE_FORMAT_BC5,     /* "bc5": two channels, 8 bits: a normal map's x and y,
                                z left to the shader (sqrt(1 - x^2 - y^2)); DDS */
  BB_TEXTURE_FORMAT_BGR8,    /* "bgr888": 24 bits; VTF */
  BB_TEXTURE_FORMAT_BGRA8,   /* "bgra8888": 32 bits; VTF */
  BB_TEXTURE_FORMAT_RGBA8,   /* "rgba8": 32 bits; DDS */
  BB_TEXTURE_FORMAT_RGBA16F, /* "rgba16f" or "rgba16161616f": half floats; VTF, DDS */
  BB_TEXTURE_FORMAT_RGBA32F  /* "rgba32f": floats; DDS */
} bb_texture_format;

/* VTF header flags (Valve's TEXTUREFLAGS_*) the writer sets, for
 * bb_texture_options.vtf_flags and bb_vtf_info.flags. */
#define BB_VTF_FLAG_ONEBITALPHA 0x00001000u  /* never written: refused in vtf_flags */
#define BB_VTF_FLAG_EIGHTBITALPHA 0x00002000u /* set when a 4-channel image keeps alpha;
                                                 refused in vtf_flags otherwise */
#define BB_VTF_FLAG_NORMAL 0x00000080u
#define BB_VTF_FLAG_NOMIP 0x00000100u         /* set, with NOLOD, without mips;
                                                 refused in vtf_flags with them */
#define BB_VTF_FLAG_NOLOD 0x00000200u
#define BB_VTF_FLAG_ENVMAP 0x00004000u        /* a cube map: refused (one face is written) */
#define BB_VTF_FLAG_SSBUMP 0x08000000u

typedef struct bb_texture_options {
  bb_texture_format format;  /* BB_TEXTURE_FORMAT_DEFAULT: see above */
  bb_map_kind map;           /* what the image is: its kind's mip rule and VTF
                                flags (bb_map_kind_info), default BB_MAP_PLAIN */
  int mips;                  /* 1: the full chain down to 1 x 1, by bb_mip_chain
                                (BB_MIP_RENORMALIZE for normal maps, BB_MIP_AVERAGE
                                otherwise); 0: the image alone */
  int fast;                  /* 1: the codec's quick fit of colour blocks (BC1,
                                BC3's colour): about 40% less time, 0.05 to 0.1 dB
                                lower PSNR; BC4 and BC5 are the same either way */
  int threads;               /* block compression threads, 0 = all cores; the bytes
                                are the same for any count */
  int vtf_version;           /* VTF minor version: 2 (7.2, the default, read by every
                                Source branch) to 5; 3 and up hold provenance */
  uint32_t vtf_flags;        /* VTF flags added to the map's (BB_VTF_FLAG_* or any
                                other TEXTUREFLAGS_* bit); those the file would
                                contradict are refused: ENVMAP, ONEBITALPHA,
                                EIGHTBITALPHA without alpha, NOMIP with mips */
  const char *description;   /* provenance text ("key=value" lines) or NULL. VTF 7.3
                                and up store it as a "KVD" (key-value data) resource,
                                "bumpbake" { "key" "value" ... }; VTF 7.2 and DDS have
                                no room for it and leave it out */
} bb_texture_options;

/* Defaults: format DEFAULT, map PLAIN, mips 1, fast 0, threads 0, VTF 7.2, no
 * extra flag, no description. */
void bb_texture_options_init(bb_texture_options *options);

/* What a VTF file's header says (info's bb_info_file.vtf). */
typedef struct bb_vtf_info {
  int version_major, version_minor; /* 7 and 0..5 */
  int header_size;          /* bytes, resource dictionary included */
  int width, height, depth; /* of the top level, in texels */
  int frames, first_frame;
  uint32_t flags;           /* TEXTUREFLAGS_* (BB_VTF_FLAG_*) */
  float reflectivity[3];
  float bump_scale;
  int format;               /* Valve's IMAGE_FORMAT_* code (13 = DXT1, 15 = DXT5,
                               3 = BGR888, 12 = BGRA8888, 24 = RGBA16161616F...) */
  char format_name[24];     /* "DXT1", "BGR888", ..., or "unknown" */
  int mip_count;
  int low_res_format;       /* IMAGE_FORMAT_* of the low-resolution image, -1 none */
  int low_res_width, low_res_height;
  int resource_count;       /* 7.3 and up; 0 before */
  long data_size;           /* bytes of image data the header declares (every level) */
  char *description;        /* provenance from a "KVD" resource written by
                               bumpbake ("key=value" lines), malloc'd, or NULL */
} bb_vtf_info;


/* What a DDS file's header says (info's bb_info_file.dds), as bb_image_read reads
 * it: the same checks, so a file this describes is one the reader takes. */
typedef struct bb_dds_info {
  int width, height;     /* of the top level, in texels */
  int mip_count;         /* levels stored, 1 when the header declares none */
  char fourcc[5];        /* the pixel format's FourCC ("DXT1", "ATI2", "DX10"),
                            "" for an uncompressed masked format */
  int dxgi_format;       /* the DX10 header's DXGI_FORMAT code, 0 without one */
  char format_name[32];  /* as read: "DXT1", "DXT5", "BC4", "BC5" (legacy
                            FourCCs), "BC1_UNORM", "R16G16B16A16_FLOAT"... (DX10),
                            and for a masked format its channels' widths:
                            "R5G6B5", "R8G8B8A8", "L8A8", "A8" */
  char compression[8];   /* "BC1" to "BC5", or "none" */
  uint32_t pixel_flags;  /* DDS_PIXELFORMAT flags: 0x1 ALPHAPIXELS, 0x2 ALPHA,
                            0x4 FOURCC, 0x40 RGB, 0x20000 LUMINANCE,
                            0x80000000 NORMAL (NVIDIA's: a tangent-space normal map) */
  uint32_t caps2;        /* DDSCAPS2 (0x200 cube map, 0x200000 volume) */
} bb_dds_info;


/* ------------------------------------------------- Source materials */

typedef struct bb_vmt_options {
  const char *materials_dir; /* the game's materials folder; the material's
                                texture paths are relative to it. NULL: the
                                nearest folder named "materials" (any case)
                                above the bump map, as in a game's tree */
  const char *bumpmap;       /* path of the bump map's .vtf, inside materials_dir */
  const char *basetexture;   /* path of the colour .vtf, inside materials_dir, or NULL */
  int ssbump;                /* 1: the bump map is a self-shadowed bump map ($ssbump 1) */
} bb_vmt_options;

/* Writes a Source material (.vmt) to path: LightmappedGeneric with
 * "$basetexture" (when given), "$bumpmap" and "$ssbump" "1" (when ssbump),
 * each texture named by its path relative to materials_dir, with '/' and
 * without ".vtf", as Source looks textures up. Paths are compared as
 * written, made absolute against the working directory, "." and ".."
 * resolved, symbolic links not followed (the textures need not exist yet).
 * Written as every file of bumpbake's: to a temporary file renamed into place. Errors: BB_ERR_ARGUMENT (no path or
 * bumpmap; a path not ending in ".vmt" (any case), or naming the same file
 * as the bump map or base texture (a hard link), which would be
 * overwritten; no materials_dir and no "materials" folder above the bump map;
 * a texture that is not a .vtf or lies outside materials_dir; a '"' or
 * control character in a path, which a material cannot quote);
 * BB_ERR_MEMORY; BB_ERR_IO. */
bb_status bb_vmt_write(const char *path, const bb_vmt_options *options, bb_error *err);

/* =====================================================================
 * image: image files in and out, mip chains, animations, the height input
 * Every read and write of an image file goes through OpenImageIO, except
 * the engine textures (VTF, DDS), which the texture family encodes.
 * ===================================================================== */

/* ------------------------------------------------------ reading images */

/* What a file held, beyond its pixels. */
typedef struct bb_image_info {
  int alpha_channel;    /* index of the alpha channel, or -1 */
  int is_float;         /* 1 when the file stores float or half samples */
  int bits_per_sample;  /* 8, 16, 32 (float or int), ... */
  char format_name[32]; /* OpenImageIO's format name: "png", "openexr", ...;
                           "vtf", "dds" for bumpbake's own texture reader */
  char *description;    /* bumpbake provenance or ImageDescription, malloc'd, or NULL */
} bb_image_info;

/* Frees info->description and clears it. */
void bb_image_info_free(bb_image_info *info);

/* Reads every channel of subimage 0 of any image OpenImageIO reads, as float
 * (integer formats scaled to [0, 1] as value / max code), and of the engine
 * textures it does not read: Valve's VTF (a .vtf name, or a file starting
 * with "VTF\0": versions 7.0 to 7.5, frame 0 and face 0 of a flat texture;
 * DXT1/3/5, ATI1N/2N, the 8-, 16- and 32-bit texel formats; alpha when the
 * flags EIGHTBITALPHA or ONEBITALPHA say the texture has one; format_name
 * "vtf", description the provenance of a 7.3+ KVD resource) and DDS (a
 * file starting with "DDS ", read by bumpbake too, as OpenImageIO 2.4's
 * reader crashes on hostile headers: DXT1 to DXT5, BC4, BC5, masked RGB,
 * luminance and alpha, and with a DX10 header RGBA16F, RGBA32F and more;
 * format_name "dds"); blocks are decoded by the exact rules of Direct3D's
 * specification (bumpbake's codec). info may be NULL.
 * The file must be a regular one (a FIFO, a device or a directory is
 * refused at once) and is read through the descriptor that was checked.
 * Errors: BB_ERR_IO (missing, unreadable, not a regular file),
 * BB_ERR_FORMAT (not an image, truncated, corrupt), BB_ERR_SIZE (zero,
 * over BB_MAX_PIXELS or over BB_MAX_READ_BYTES, or tiles of more than 64
 * MiB as floats, or a header whose reader would allocate more than
 * BB_MAX_READ_BYTES to open it: all refused before allocating). */
bb_status bb_image_read(const char *path, bb_image *out, bb_image_info *info,
                        bb_error *err);

/* Reads only the header of path: its size, channel count and what
 * bb_image_info holds, without decoding a pixel (fast on any size; a
 * truncated pixel stream is not noticed). width, height, channels and info
 * may each be NULL. Errors as bb_image_read, except that the size limits
 * BB_MAX_DIMENSION, BB_MAX_PIXELS and BB_MAX_READ_BYTES are not applied to
 * the image (its size is reported, not allocated). Some readers allocate
 * from the header to open a file at all (a progressive JPEG's whole
 * coefficients, a GIF's canvas, an OpenEXR's chunk buffers): that is
 * refused past BB_MAX_READ_BYTES (64 MiB for one OpenEXR chunk) with
 * BB_ERR_SIZE, and OpenImageIO's own limits, see BB_MAX_READ_BYTES, may
 * refuse a header declaring more than 16 GiB of samples. */
bb_status bb_image_read_info(const char *path, int *width, int *height, int *channels,
                             bb_image_info *info, bb_error *err);

/* ------------------------------------------------------ writing images */

/* Sample depth of a written file. DEFAULT is 8-bit for png/tga/tif and
 * float32 for exr. */
typedef enum bb_depth {
  BB_DEPTH_DEFAULT = 0,
  BB_DEPTH_8,     /* png, tga, tif */
  BB_DEPTH_16,    /* png, tif */
  BB_DEPTH_HALF,  /* exr */
  BB_DEPTH_FLOAT  /* exr, tif */
} bb_depth;

/* ------------------------------------------------------- texture files */

/* ---------------------------------------------------------- mip chains */

/* How a mip level is made from the one above it. */
typedef enum bb_mip_filter {
  BB_MIP_AVERAGE = 0,  /* box average of every channel: ssbump, weights, ao, heights
                          (linear in light, so averages light as the paper says) */
  BB_MIP_RENORMALIZE   /* box average, then channels 0..2 rescaled to unit length
                          (normal maps; a zero average becomes (0, 0, 1)) */
} bb_mip_filter;

/* The mip chain of img, down to 1 x 1: level 0 is a copy of img, level k + 1
 * is level k box-filtered by OpenImageIO's ImageBufAlgo::resize to
 * max(1, w / 2) x max(1, h / 2) (for even sides exactly the mean of 2 x 2
 * texels; an odd side's box covers the 3 texels under each output texel),
 * then renormalised for BB_MIP_RENORMALIZE. *levels is malloc'd with *count
 * images (1 + floor(log2(max(w, h)))); free it with bb_mip_chain_free. */
bb_status bb_mip_chain(const bb_image *img, bb_mip_filter filter, bb_image **levels,
                       int *count, bb_error *err);

void bb_mip_chain_free(bb_image *levels, int count);

/* ----------------------------------------------------------- animation */

/* An animated GIF being written (OpenImageIO's GIF writer: 8 bits per
 * channel, a palette per frame). Frames go to a temporary file in the
 * destination directory; closing the animation checks it and renames it into
 * place, so a failure leaves no partial file. GIF stores no provenance. */
typedef struct bb_animation bb_animation;

/* -------------------------------------------------------- height input */

/* Which channel of a colour image becomes the height. */
typedef enum bb_channel {
  BB_CHANNEL_AUTO = 0, /* the grey, or the mean of R, G, B; alpha where the
                          image shows Valve's convention (bake's --channel
                          in docs/commands/bake.md) */
  BB_CHANNEL_R,
  BB_CHANNEL_G,
  BB_CHANNEL_B,
  BB_CHANNEL_A,
  BB_CHANNEL_LUMA,     /* Rec. 709: 0.2126 R + 0.7152 G + 0.0722 B */
  BB_CHANNEL_MEAN,     /* (R + G + B) / 3, computed in double */
  BB_CHANNEL_VALVE     /* Valve's height2ssbump: alpha when the image has
                          one, else the grey or the mean of R, G, B */
} bb_channel;

/* Extracts a 1-channel height field from a decoded image by the channel rule.
 * Rejects NaN or infinite heights (BB_ERR_VALUE, naming the first bad texel)
 * and channels the image does not have (BB_ERR_ARGUMENT). alpha_channel is
 * the image's alpha index or -1 (from bb_image_info). */
bb_status bb_height_from_image(const bb_image *img, int alpha_channel,
                               bb_channel channel, bb_image *height,
                               bb_error *err);

/* =====================================================================
 * trace: bases, the pyramid, ray sets and the tracer
 * ===================================================================== */

/* --------------------------------------------------------------- basis */

/* The directions occlusion is projected on: one channel of ssbump and
 * weights per direction, in this order. A plain struct; copy it freely. */
typedef struct bb_basis {
  int count;                       /* directions, 3..BB_MAX_BASIS */
  double vector[BB_MAX_BASIS][3];  /* unit B_c in the tangent frame (+Y down),
                                      z >= 0; entries past count are zero */
  char name[32];                   /* "hl2", "hl2+z", "dirs:N" or
                                      "vectors:" + 16 hex digits (a hash of
                                      the vectors); recorded in provenance */
} bb_basis;

/* A basis of count (3..BB_MAX_BASIS) vectors of the caller's, each scaled
 * to unit length; named "vectors:" + the FNV-1a hash of the unit vectors'
 * bits. Rejects (BB_ERR_ARGUMENT, naming the vector's index from 0) a NaN
 * or infinite component, a zero vector and one pointing below the surface
 * (z < 0 after scaling). out is untouched on failure. */
bb_status bb_basis_from_vectors(const double (*vectors)[3], int count, bb_basis *out,
                                bb_error *err);

/* A basis as the command line names it: "hl2", "hl2+z" or "dirs:N" (a name
 * wins over a file of the same name, which ./NAME reaches), else the path
 * of a basis file (docs/conventions.md). BB_ERR_ARGUMENT for a word that is
 * neither ("basis must be hl2, hl2+z, dirs:N (N in 3..16) or a file of
 * directions (got 'x': No such file or directory)") or a dirs:N out of
 * range; a file's own errors otherwise. *from_file (may be NULL) receives 1
 * when spec named a file. out is untouched on failure. */
bb_status bb_basis_resolve(const char *spec, bb_basis *out, int *from_file, bb_error *err);

/* ------------------------------------------------------------- pyramid */

/* Max-mip pyramid over the surface z = height_texels(x, y): opaque, built
 * once per bake, read-only afterwards and safe to share between threads. */
typedef struct bb_pyramid bb_pyramid;

void bb_pyramid_free(bb_pyramid *p);

/* ------------------------------------------------------------- ray set */

/* The directions the bake integrates over, and how; opaque, built by
 * the library for a bake (bb_command_trace_input), read-only afterwards and safe to share between threads.
 * ("Ray set" is the historical name: nothing is sampled in elevation.)
 * Slice s follows the integer lattice step (a, b) nearest to the azimuth
 * 2 pi (s + 1/2) / A and stands for the azimuth sector halfway to its
 * neighbours. A texel's horizon along the step's direction (tangent t,
 * found exactly by the tracer) blocks, over the whole sector, the
 * elevations below atan(max(t, 0)); what that takes from each integral of
 * docs/conventions.md (ao: w.z; vis_c: max(0, w.B_c)^P) is exact: closed
 * form for ao, tables in t built here for the lobes (error under 1e-9 of
 * the sector's share). Then
 *   ao    = 1 - sum_s blocked_ao,s(t_s) / total_ao
 *   vis_c = 1 - sum_s blocked_c,s(t_s) / total_c
 * so an unobstructed texel gets exactly 1. */
typedef struct bb_rayset bb_rayset;

/* Frees a ray set; NULL is fine. */
void bb_rayset_free(bb_rayset *rs);

/* Its azimuth slices (A) and lobes (the basis' direction count). */
int bb_rayset_slice_count(const bb_rayset *rs);
int bb_rayset_lobe_count(const bb_rayset *rs);

/* The id that names the scheme and its parameters in provenance ("rayset"
 * key); owned by rs. */
const char *bb_rayset_id(const bb_rayset *rs);

/* --------------------------------------------------------------- trace */

typedef struct bb_trace_options bb_trace_options;

/* A trace of the caller's, which a bake calls in place of its own
 * (bb_command_hooks.trace, bb_trace_options.trace): for the pyramid and ray set the bake built, it
 * fills vis exactly as the bake's own trace of them with o would: allocated (bb_image_alloc), the pyramid's size, 1 +
 * bb_rayset_lobe_count(rs) channels. A trace split over machines does this
 * with bb_trace_horizons, bb_trace_accumulate and bb_trace_finish, so the
 * bake's maps are a single bake's bits. Returns BB_OK, or an error with err
 * filled (vis then left unallocated). Called on the thread that runs
 * the bake. */
typedef bb_status (*bb_trace_fn)(void *user, const bb_pyramid *p, const bb_rayset *rs,
                                 const bb_trace_options *o, bb_image *vis, bb_error *err);

struct bb_trace_options {
  double bias_texels;   /* origin lift above the vertex, >= 0 (default 0.55) */
  int threads;          /* 0 = all cores */
  bb_region region;     /* width 0 (default): every texel, by line sweeps;
                           else only these texels, by max-mip marches */
  bb_progress_fn progress; /* may be NULL; called from one thread as the
                              work goes (per slice, or every 50 ms); a
                              nonzero return cancels. In a bake also
                              with done 0 and total 0 (a checkpoint, no
                              progress) every 50 ms while it smooths and
                              makes normals, so those stages cancel too;
                              with inter-reflection (bounce_albedo > 0) the
                              units run once over the trace and the
                              bounces: with a trace function of the
                              caller's, the first bb_command_slices are
                              the trace's (one a slice), the rest the
                              bounces'; without one, the bounces' sweeps
                              find the horizons too and every unit is
                              theirs */
  void *progress_user;
  bb_trace_fn trace;    /* a bake's only: NULL (default) traces with
                           the library's own tracer; else the bake calls
                           trace(trace_user, ...) in its place (bb_trace_fn).
                           the library's tracer itself ignores it */
  void *trace_user;
};

/* A trace split over processes or machines: bumpbake_cluster.h. */

/* =====================================================================
 * bake: smooth -> normals -> pyramid -> trace -> derive
 * ===================================================================== */

/* ----------------------------------------------------------- smoothing */


/* ------------------------------------------------------------- normals */

typedef enum bb_normal_filter {
  BB_NORMAL_VALVE = 0, /* Valve's: mean of the 18 triangle normals of the 9 cells
                          x-1..x+1, y-1..y+1; centred on (x + 1/2, y + 1/2) */
  BB_NORMAL_CENTRAL,   /* central differences */
  BB_NORMAL_SOBEL,     /* 3x3 Sobel gradient */
  BB_NORMAL_VERTEX     /* the default: centred on the vertex (x, y) the rays
                          leave from; the triangle normals of the 16 cells
                          x-2..x+1, y-2..y+1 weighted (1,2,2,1) x (1,2,2,1),
                          i.e. Valve's sums at the 4 cell centres around the
                          vertex added; a symmetric bump's peak gives (0,0,1) */
} bb_normal_filter;

/* The normals a normal-map file holds, from the values bb_image_read
 * returns for it. Integer files hold 0.5 + 0.5 N, so N = 2 v - 1 with
 * v = code / max code: code 127.5 of 255 is 0, and code 128 (DOOM 3's zero)
 * reads as +1/255 (Valve's normal2ssbump decodes the same way). Float files
 * (is_float 1, from bb_image_info) hold N as it is. Uses channels 0..2
 * (values needs 3 or more). normal_y_up 1: the map's green is +Y up
 * (OpenGL), negated to the library's +Y down (the command line's
 * --normal-y up). normalize 1: each texel scaled to unit length, (0, 0, 0)
 * becoming (0, 0, 1) (0: as decoded, so a texel an operator copies keeps
 * its code). Non-finite values are BB_ERR_VALUE, naming the texel.
 * Allocates normals: 3 channels, same size. */
bb_status bb_normal_map_decode(const bb_image *values, int is_float, int normal_y_up,
                               int normalize, bb_image *normals, bb_error *err);

/* ---------------------------------------------------------------- bake */


/* Most bounces a bake's inter-reflection follows. */
#define BB_MAX_BOUNCES 64


/* Everything one bake makes. Images not made are zeroed (pixels NULL). */
typedef struct bb_bake_result {
  bb_image filtered;   /* smoothed h, 1 channel */
  bb_image normal;     /* 3 channels */
  bb_image weights;    /* basis count channels */
  bb_image vis;        /* 1 + basis count channels: ao, vis_c (when traced) */
  bb_image ssbump;     /* basis count channels (when traced) */
  bb_image ao;         /* 1 channel (when traced) */
  bb_image bent;       /* 3 channels (when traced) */
  double seconds_smooth, seconds_pyramid, seconds_trace, seconds_derive;
  double horizons_found;   /* texels x slices */
  char rayset_id[64];      /* empty when nothing was traced */
  bb_basis basis;          /* the basis of weights, ssbump and bent (the options') */
  int threads;             /* worker threads the stages ran on (o->trace.threads,
                              or the core count for 0) */
  int bounces;             /* passes of inter-reflection gathered: bounces,
                              or 2 when converged (0: none) */
  double seconds_bounce;   /* the inter-reflection's part, after seconds_trace */
} bb_bake_result;

void bb_bake_result_free(bb_bake_result *r);

/* ------------------------------------------------------- bake contexts */

/* What a long-running caller that bakes again and again (bumpbake serve,
 * an editor) keeps warm between bakes: the ray set of the last bake,
 * reused while slices, power and basis are the same, and, process-wide,
 * the bakes' freed buffers, kept in the heap for the next bake of the same
 * size (glibc's allocator told not to return buffers up to 32 MiB to the
 * system: no page faults or zeroing again; the memory of the largest bake
 * stays with the process). A bake with a context is a cold bake's bits.
 * One bake at a time per context. */
typedef struct bb_bake_context bb_bake_context;
bb_status bb_bake_context_new(bb_bake_context **out, bb_error *err);
void bb_bake_context_free(bb_bake_context *context);

/* Edit-local bakes. With keep 1 the bakes through context
 * (bb_command_bake's with it, and a job's after bb_job_use_context) keep what
 * they made: the height, its smoothing and max-mip pyramid, each texel's
 * horizon in every slice, its visibility and normal, and the maps; about
 * 4 x slices + 70 bytes a texel for the default maps and basis (134 at 16
 * slices: 141 MB at 1024 x 1024; 24 more with every map), while the
 * context lives (a machine that cannot hold it bakes whole, keeping
 * nothing). A bake of a height of the same size with the same options
 * then bakes again only what the change can reach (docs/how-it-works.md,
 * "Edits"): the smoothing around the changed texels, the pyramid's nodes
 * above them, along the lines of each slice that cross them the horizons
 * the change can move (out to every texel a tall new peak shadows), and
 * the texels derived from those; and it gives the bits of a whole bake of
 * the new height. A change over a quarter of the texels, inter-reflection
 * (bounce_albedo > 0) and a caller's trace (o->trace.trace) bake whole.
 * keep 0 (the default) lets what was kept go. */
void bb_bake_context_keep(bb_bake_context *context, int keep);

/* The changed rectangle of the context's last bake, as bb_command_bake
 * gives it (for a bake made through a job): the texels whose maps may
 * differ from those of the context's bake before, a rectangle inside the
 * image, the whole image after a whole bake, width 0 when nothing
 * changed; texels across the edge of a periodic map make it span the
 * whole width (or height). Width 0 before any. */
bb_region bb_bake_context_changed(const bb_bake_context *context);

/* =====================================================================
 * maps: Valve's files, converting, combining, programs, slope maps, compare
 * Every function here works on decoded values: normals as N in [-1, 1]
 * (+Y down), ssbump, weights and ao in [0, 1], colours in [0, 1].
 * ===================================================================== */

/* -------------------------------------------------- Valve's RGBA files */

/* What goes into the RGBA file Valve's height2ssbump writes. */
typedef struct bb_valve_options {
  int normal_map;  /* 0: RGB = ssbump (FILE-ssbump.tga); 1: RGB = the normal
                      map, 0.5 + 0.5 N (-n, FILE-bump.tga). Default 0 */
  int ao_in_alpha; /* 0: A = the filtered height; 1: A = ao (-A). Default 0 */
} bb_valve_options;

/* -------------------------------------------------- flipcode slope map */

/* ------------------------------------------------------------- compare */

typedef struct bb_compare_stats {
  double mean_abs, rms, max_abs;
  int worst_x, worst_y, worst_channel;
  long pixels;
  long over_fail, over_warn;  /* pixels with any channel over the threshold */
} bb_compare_stats;

/* The tolerances of a comparison, as OpenImageIO's idiff takes them (its
 * -fail, -failpercent, -hardfail, -allowfailures, -warn, -warnpercent,
 * -hardwarn). Differences are absolute, in the images' float units. */
typedef struct bb_compare_limits {
  double fail;          /* a pixel fails when a channel differs by more; 1e-6 */
  double fail_percent;  /* failing pixels allowed, % of all, 0..100; 0 */
  double hard_fail;     /* any difference above this fails; infinity */
  long allow_failures;  /* up to this many failing pixels pass, by any
                           amount (hard_fail included); 0 */
  double warn;          /* a pixel warns when a channel differs by more; 1e-6 */
  double warn_percent;  /* warning pixels allowed, % of all, 0..100; 0 */
  double hard_warn;     /* any difference above this warns; infinity */
} bb_compare_limits;

/* A comparison's outcome; the values are idiff's exit codes. */
typedef enum bb_compare_verdict {
  BB_COMPARE_PASS = 0,
  BB_COMPARE_WARN = 1,
  BB_COMPARE_FAIL = 2
} bb_compare_verdict;

/* =====================================================================
 * render: lighting the maps, pictures, panels, sheets
 * ===================================================================== */

/* ------------------------------------------------------------ lighting */

/* Lighting the baked maps as the paper's "Rendering" section (and Source's
 * shaders) do, per texel, in the tangent frame above (+Y down, viewer
 * overhead). Inputs: N (unit normal), s_c (ssbump), ao, the bent normal
 * Nb = normalize(sum_c s_c B_c), an optional albedo A. Lights: a dynamic
 * light l (unit, towards the light) of colour C, and the three lightmap
 * colours L_c of Source's static light (the light arriving along B_c).
 *   mode      static (lightmaps)        dynamic light
 *   normal    sum_c w_c L_c             max(0, N.l) C
 *   ao        ao * sum_c w_c L_c        ao * max(0, N.l) C
 *   ssbump    sum_c s_c L_c             sat(sum_c s_c (l.B_c)) C
 * with Source's weights w_c = dp_c / sum_k dp_k, dp_c = sat(N.B_c)^2 (the
 * weights map). Output = A * (static + dynamic) + specular (A by
 * bb_albedo_mode; 1 without an albedo), where the
 * Blinn-Phong specular of exponent k and strength ks sums, over every
 * light (d, K) in use (the dynamic light, and the three B_c with colours L_c
 * when the lightmaps are on), ks * K * max(0, Ns.h)^k with h = normalize(d + (0, 0, 1)),
 * counted only where Ns.d > 0; Ns is Nb for ssbump, N otherwise. A flat,
 * unoccluded texel under an overhead light gives 1 in every mode, the
 * value of N.L. */

/* How the albedo A multiplies the diffuse light (Source's detail blend
 * modes, common_ps_fxc.h TextureCombine). */
typedef enum bb_albedo_mode {
  BB_ALBEDO_MULTIPLY = 0, /* A, per channel */
  BB_ALBEDO_MOD2X,        /* 2 A per channel ($detailblendmode 0): 0.5 is neutral */
  BB_ALBEDO_SSBUMP        /* (2/3)(A_r + A_g + A_b), grey: a detail ssbump used as an
                             albedo (mode 11); a flat, unoccluded height2ssbump -d
                             detail of mid-grey input (0.5 each) gives 1 */
} bb_albedo_mode;

/* Largest specular exponent a render takes: max(0, N.h)^k is a point far
 * below one texel beyond it. */
#define BB_MAX_SPECULAR_EXPONENT 100000.0

/* What one render shows. New modes are appended. */
typedef enum bb_render_mode {
  BB_RENDER_SSBUMP = 0, /* the self-shadowed bump map (needs ssbump) */
  BB_RENDER_NORMAL,     /* plain normal mapping, no self-shadowing (needs normal) */
  BB_RENDER_NORMAL_AO,  /* normal mapping times ambient occlusion (normal, ao) */
  BB_RENDER_SLOPE       /* flipcode's 1999 slope map lit through its 16 x 16
                           table (needs slope) */
} bb_render_mode;

/* The maps a mode reads, as BB_RENDER_NEEDS_* bits (0 for an unknown mode). */
#define BB_RENDER_NEEDS_NORMAL 1u
#define BB_RENDER_NEEDS_SSBUMP 2u
#define BB_RENDER_NEEDS_AO 4u
#define BB_RENDER_NEEDS_SLOPE 8u

/* The maps a render reads; all of the same width and height. Pointers not
 * needed by the mode may be NULL. Images may have more channels than used:
 * channels past the first 3 (1 for ao) are ignored (a height2ssbump TGA
 * keeps the height in alpha), except that the ssbump holds Half-Life 2's
 * basis: one of more than 4 channels (a bake with another basis) is
 * refused. */
typedef struct bb_render_maps {
  const bb_image *normal; /* unit N, >= 3 channels, +Y down */
  const bb_image *ssbump; /* s_c, >= 3 channels */
  const bb_image *ao;     /* ao in channel 0 */
  const bb_image *bent;   /* Nb, >= 3 channels; NULL: computed from ssbump */
  const bb_image *albedo; /* NULL = white; 1 channel = grey, >= 3 = RGB */
  const bb_image *slope;  /* flipcode slope bytes / 255 in channel 0 (bake's slope) */
} bb_render_maps;

/* ------------------------------------------------------ rendering files */

/* The maps a render can read from files instead of baking a height:
 * BB_MAP_NORMAL (>= 3 channels, decoded to unit N), BB_MAP_SSBUMP (>= 3
 * channels, Half-Life 2's basis), BB_MAP_AO (channel 0), BB_MAP_BENT
 * (decoded as a normal map), BB_MAP_SLOPE (flipcode's slope bytes / 255 in
 * channel 0); their names are the command line's options and provenance's
 * map_KIND keys. */
/* Reads a map file for a render and checks it for its kind: channels
 * enough, Half-Life 2's basis for an ssbump (as ssbump2normal checks it), and the
 * size of like when like is not NULL; normal and bent maps are decoded to
 * unit N (bb_normal_map_decode; normal_y_up 1: OpenGL-style files).
 * *hash (may be NULL) receives the hash of what the file decoded to (its
 * pixels' hash, as provenance's input_hash records a decoded input).
 * Errors name the file: those of bb_image_read, BB_ERR_ARGUMENT for a map
 * that is not what its kind needs. */
bb_status bb_render_map_read(const char *path, bb_map_kind kind, int normal_y_up,
                             const bb_image *like, bb_image *out, uint64_t *hash,
                             bb_error *err);

/* =====================================================================
 * mesh: models and DOOM 3's flat render bump
 * ===================================================================== */

/* ---------------------------------------------------- flat render bump */

/* The direction a flat sculpt's front side faces, towards the viewer of an
 * orthographic projection. Each names a right-handed frame (right, up, out):
 * image columns run along right, rows run down -up, and out is the height. */
typedef enum bb_axis {
  BB_AXIS_NEG_Y = 0, /* DOOM 3's RenderBumpFlat (and Blender's front view):
                        right +X, up +Z, out -Y */
  BB_AXIS_POS_Y,     /* right -X, up +Z, out +Y (Blender's back view) */
  BB_AXIS_POS_Z,     /* right +X, up +Y, out +Z (Blender's top view) */
  BB_AXIS_NEG_Z,     /* right +X, up -Y, out -Z (Blender's bottom view) */
  BB_AXIS_POS_X,     /* right +Y, up +Z, out +X (Blender's right view) */
  BB_AXIS_NEG_X      /* right -Y, up +Z, out -X (Blender's left view) */
} bb_axis;


/* What a flat render bump makes. */
typedef struct bb_renderbump_result {
  bb_image normal;   /* 4 channels: unit N in the tangent frame (x right, y
                        DOWN, z out) and alpha = covered fraction of the
                        texel's samples; N = (0, 0, 1) where alpha is 0 */
  bb_image height;   /* 1 channel: h in [0, 1], the texel's mean height of the
                        front-most surface over its covered samples, 0 where
                        alpha is 0 */
  double rect[4];    /* the rectangle used: left, bottom, right, top */
  double depth_min, depth_max; /* model units along out that h = 0 and 1 are */
  double texel_size; /* model units per texel: sqrt(texel width * height) */
  double texel_aspect; /* texel width / texel height (1 = square texels) */
  double height_scale; /* texels of height per unit of h, (depth_max -
                          depth_min) / texel_size: the bake's height_scale
                          for this height; 0 when the surface is flat */
  int used_vertex_normals; /* 1 when some texel used interpolated normals */
  size_t triangles_drawn;  /* triangle copies rasterised (with tile copies) */
  size_t triangles, vertices; /* the mesh's counts */
  uint64_t model_hash;     /* the hash of the mesh, as its files record it */
} bb_renderbump_result;

void bb_renderbump_result_free(bb_renderbump_result *r);

/* =====================================================================
 * job: the whole job on files
 * ===================================================================== */

/* ------------------------------------------------ provenance of a bake */



/* ----------------------------------------------------------- output paths */

/* One file a command will write, as checked before any work is done. */
typedef struct bb_output_spec {
  const char *path;
  const char *kind;  /* what it holds, in messages: "normal", "render", "depfile" */
  int channels;      /* the image's channels; 0: not known yet, not checked */
  bb_depth depth;    /* as asked; BB_DEPTH_DEFAULT: the format's */
  int mips;          /* 1: a mip-mapped file */
  int text;          /* 1: a text file (a depfile): no image format rules */
  /* .vtf and .dds outputs, when the size is known (width 0: not checked
   * here, only when written): */
  int width, height; /* the image's size in texels */
  bb_range range;    /* as bb_output_file's: with kind, picks the map */
  const bb_texture_options *texture; /* NULL: the defaults */
} bb_output_spec;

/* Checks every output before any work, so a bad name costs no baking time:
 * BB_ERR_ARGUMENT (usage: an extension bumpbake does not write, a
 * depth, mip chain or channel count the format cannot hold, a .vtf or .dds
 * of a size or channels its format cannot take (with the texture options
 * of the map kind and range name), two outputs on
 * one file under any spelling: "KIND and KIND would both be written to
 * PATH"); BB_ERR_IO (an output that is one of the reads[0..read_count-1]
 * under any spelling, hard or symbolic link: "PATH: output would overwrite
 * the input file"; a directory that does not exist or is not one; an
 * output that exists and is not a regular file: a directory, a device, a
 * FIFO, a socket or a symbolic link, which the rename that puts an output
 * in place would replace: "PATH: cannot write: is a FIFO, not a regular
 * file"). Messages start with the path. Every write of the library
 * (texts, images and the staged writes) refuses such a name too, at its
 * start and again just before its rename. */
bb_status bb_outputs_check(const bb_output_spec *outputs, int count,
                           const char *const *reads, int read_count, bb_error *err);

/* ------------------------------------------------------- writing outputs */

/* One file of a set written all or nothing: an image (with its provenance)
 * or, with image NULL, text bytes (a depfile). */
typedef struct bb_output_file {
  const char *path;
  const char *kind;          /* for messages: "normal", "ssbump+height" ... */
  const bb_image *image;     /* the pixels, or NULL for text */
  bb_range range;            /* how image's values map to codes */
  bb_depth depth;            /* BB_DEPTH_DEFAULT: the format's */
  int mips;                  /* 1: the mip chain (bb_mip_chain: renormalised
                                for BB_RANGE_SIGNED, averaged otherwise) */
  const char *description;   /* provenance text stored in the file, or NULL */
  const void *text;          /* the bytes of a text file (image NULL) */
  size_t text_size;
  const bb_texture_options *texture; /* a .vtf or .dds file's settings (NULL:
                                the defaults); its map is set from kind and
                                range, its mip chain by
                                its own mips, not the file's */
} bb_output_file;

/* Writes count files all or nothing: each is encoded and synced under a
 * temporary name in its directory (up to `threads` at once, 0 = one per
 * file), and only when every one succeeded are they renamed into place, in
 * order, with the process's ending by a signal deferred until the last
 * rename (bb_signal_cleanup): an interrupted or failed write leaves every
 * destination as it was, or, should a rename itself fail (the destination
 * became a directory), says which were replaced. Errors (BB_ERR_IO,
 * BB_ERR_FORMAT, BB_ERR_MEMORY) read "PATH: reason; no output was written"
 * for sets of more than one, or "...; already written: KIND PATH, ...". */
bb_status bb_outputs_write(const bb_output_file *files, int count, int threads, bb_error *err);

/* For a SIGINT, SIGTERM or SIGHUP handler (async-signal-safe): removes the
 * temporaries of the writes in flight and ends the process by signal_number
 * with its default action; but while bb_outputs_write is renaming a set
 * into place, on any thread, the ending waits until the set is complete, so
 * a signal leaves all of a set old or all new. The handler should be
 * installed without SA_RESETHAND: this resets the action itself. */
void bb_signal_cleanup(int signal_number);

/* --------------------------------------------------- render bump files */

/* ----------------------------------------------------------- height files */

/* What a bake found out about its height file (bb_job_report.source). */
typedef struct bb_height_source {
  bb_channel channel;     /* the channel rule's choice (never AUTO or VALVE) */
  int grey;               /* 1: one colour channel (grey, or grey + alpha) */
  int channels;           /* channels of the file */
  int bits_per_sample;    /* of the file: 8, 16, 32 */
  int is_float;           /* 1: float or half samples */
  char format_name[32];   /* OpenImageIO's: "png", "openexr", ... */
  uint64_t file_hash;     /* bb_file_hash of the bytes that were decoded */
  uint64_t height_hash;   /* the hash of the height's pixels */
} bb_height_source;


/* The name of the channel a height came from: "grey" for a grey image
 * (whose mean is its grey), else the channel's word as --channel takes it. */
const char *bb_height_source_channel(const bb_height_source *source);

/* --------------------------------------------------------- comparing files */

/* What comparing two image files found (compare's bb_command_run:
 * bb_command_result.compare). */
typedef struct bb_compare_report {
  int same_shape;             /* 0: sizes or channel counts differ; nothing
                                 else was compared (idiff's exit 3) */
  int width, height, channels;       /* of A */
  int b_width, b_height, b_channels; /* of B */
  bb_compare_stats stats;     /* per pixel, as idiff computes them */
  bb_compare_verdict verdict; /* idiff's rule; FAIL when
                                 the shapes differ */
  bb_provenance_class provenance_a, provenance_b;
  int provenance_differences; /* keys that differ, or -1 when not compared
                                 (either side not intact provenance) */
  char *provenance_diff;      /* "key: A-value -> B-value" lines
                                 of the provenance, malloc'd, or NULL */
  int diff_written;           /* 1 when diff_path was written */
  bb_error diff_error;        /* why it was not, when asked */
  const char *result;         /* idiff's word for the outcome, as `bumpbake
                                 compare` prints it: "PASS", "WARNING",
                                 "FAILURE", or "DIFFERENT SIZE" (static) */
} bb_compare_report;

/* idiff's exit codes beside a comparison's verdicts (bb_compare_verdict):
 * BB_COMPARE_DIFFERENT_SIZE when the sizes or channel counts differ (a
 * report: bb_command_result.exit_code), BB_COMPARE_CANNOT_READ when a file
 * cannot be read (no report: bb_command_run fails), which compare's usage
 * errors exit with too (bb_command_info.usage_exit). */
#define BB_COMPARE_DIFFERENT_SIZE 3
#define BB_COMPARE_CANNOT_READ 4

/* ---------------------------------------------------------- golden suites */

/* A suite check (`bumpbake check`): every map of a suite compared with its
 * golden, as compare compares two files, in one run: a tree of new
 * files against a tree of goldens by relative name, or a batch baked in
 * memory (bake --out-dir GOLDEN's maps, nothing written) against the files
 * it would write. Each map is a case with idiff's verdict under limits
 * chosen per map kind or file name; a run can update the goldens where a
 * case does not pass, and writes a JUnit XML file and an HTML report. */

/* How a case ended. */
typedef enum bb_check_status {
  BB_CHECK_PASS = 0,       /* within the limits (idiff's exit 0) */
  BB_CHECK_WARNING,        /* idiff's warning (1) */
  BB_CHECK_FAILURE,        /* idiff's failure (2) */
  BB_CHECK_DIFFERENT_SIZE, /* sizes or channel counts differ (3) */
  BB_CHECK_UNREADABLE,     /* a file that cannot be read, a link leaving its
                              tree, an input that would not bake (4) */
  BB_CHECK_MISSING,        /* a golden nothing new matches (a failure: 2) */
  BB_CHECK_EXTRA           /* a new map without a golden (a failure: 2) */
} bb_check_status;

/* One case: a map and its golden. Strings belong to the check. */
typedef struct bb_check_case {
  const char *name;            /* the golden's path relative to the golden tree */
  const char *golden;          /* the golden's path */
  const char *fresh;           /* the new file's path; for a bake, the height
                                  it was baked from */
  const char *kind;            /* the map's kind, as its provenance records it
                                  ("normal"; "" when unknown) */
  bb_check_status status;
  int exit_code;               /* idiff's: 0 to 4; MISSING and EXTRA 2 */
  bb_compare_limits limits;    /* what it was judged by */
  int width, height, channels;             /* of the golden (0: not read) */
  int new_width, new_height, new_channels; /* of the new map (0: not made) */
  bb_compare_stats stats;      /* when both were compared (same size) */
  const char *provenance_diff; /* "key: golden -> new" lines of the provenance
                                  ("" when the same), NULL when not compared
                                  (either side without intact provenance) */
  const char *message;         /* why UNREADABLE, MISSING or EXTRA; else "" */
  int updated;                 /* 1: its golden was written by the update */
  const char *update_error;    /* why the update could not write it, or NULL */
  double seconds;              /* the time its comparison took */
} bb_check_case;

/* A planned check. Opaque; not thread-safe. */
typedef struct bb_check bb_check;

/* A check is planned from its command (bb_check_plan, with the commands
 * below); bb_check_free frees it. */
void bb_check_free(bb_check *check);

/* Called with each case as it is decided (and its golden updated). */
typedef void (*bb_check_case_fn)(void *user, const bb_check_case *c);

/* The heights of a check with --bake, in the order of the batch (a
 * directory's images sorted); 0 without. */
int bb_check_input_count(const bb_check *check);
/* Height i's path as the batch planned it (a directory's file: DIR/NAME),
 * or NULL. */
const char *bb_check_input(const bb_check *check, int i);

/* Bakes height i in memory (progress as bb_job_run_item's, which may
 * cancel) and decides a case for each of its maps against the file the
 * batch would write (what reading that file back would give, its
 * provenance as the batch would record it), then with --update writes the
 * maps that did not pass (and only those) as the batch writes them. An
 * input that does not bake is an UNREADABLE case per map. Errors:
 * BB_ERR_ARGUMENT (i out of range), BB_ERR_CANCELLED, BB_ERR_MEMORY. */
bb_status bb_check_run_input(bb_check *check, int i, bb_progress_fn progress,
                             void *progress_user, bb_check_case_fn each, void *user,
                             bb_error *err);

/* The cases that are not an input's: of two trees every pair (sorted by
 * name: both have it, MISSING, EXTRA); of a bake the goldens no input makes
 * (an image in GOLDEN, at any depth, whose provenance says bumpbake baked
 * it, under a name the batch's template gives a kind it writes: MISSING). Names starting with '.' and files of other extensions are
 * not cases; a link is followed only to a file inside its tree; nothing
 * else is followed. */
bb_status bb_check_run_rest(bb_check *check, bb_check_case_fn each, void *user,
                            bb_error *err);

/* The cases decided (and imported) so far, in order. */
int bb_check_case_count(const bb_check *check);
const bb_check_case *bb_check_case_get(const bb_check *check, int i);

/* The exit code of the worst case (the largest: 0 pass .. 4 unreadable;
 * MISSING and EXTRA 2), a case whose golden was updated counting as a pass;
 * 0 when there is none. */
int bb_check_exit_code(const bb_check *check);


/* What the command line prints of a case, as the command's options (json,
 * quiet) ask: a case that does not pass as "STATUS NAME (KIND): what" and
 * its provenance differences indented, one line "updated NAME" for a
 * golden written; nothing for a pass; with json one JSON line per case.
 * To free(); NULL when out of memory. */
char *bb_check_case_lines(const bb_check *check, const bb_check_case *c);

/* The summary line ("check: N maps: P passed, W warnings, F failed, ...") or
 * its JSON line; "" with quiet. To free(); NULL when out of memory. */
char *bb_check_summary_lines(const bb_check *check);

/* Writes the reports the command asked for, of every case so far: the
 * JUnit XML file (a test case per map; a failure's message carries its
 * statistics and provenance differences) and the HTML report's index.html
 * (its pictures are made as the cases are; pictures an earlier report left
 * in its folder are removed). Errors: those of writing. */
bb_status bb_check_write_reports(bb_check *check, bb_error *err);

/* The cases from first on as bytes (*size of them; malloc'd, NULL when out
 * of memory or a picture cannot be written), for another process's check
 * of the same command to import: a cluster's workers each check some inputs
 * and the client reports them all. The HTML pictures they name are files of
 * the report's directory, written first. */
char *bb_check_export(bb_check *check, int first, size_t *size);

/* Adds the cases of an export (bb_check_export), as if decided here.
 * Errors: BB_ERR_ARGUMENT (not an export of this version), BB_ERR_MEMORY. */
bb_status bb_check_import(bb_check *check, const char *data, size_t size, bb_error *err);

/* -------------------------------------------------------------- bake jobs */

/* What `bumpbake bake` does, as one plan and its run: inputs (height files,
 * or directories of them), the maps to write and where, checked before any
 * bake; inputs whose outputs are up to date skipped; each input baked once
 * (every traced map from one trace) and its maps written all or nothing
 * with provenance; a Make/Ninja depfile. A batch names its outputs from
 * out_dir and a template; a single input may name each output instead. */

/* Most files one input's bake writes: Valve's packed file, the maps, the
 * slope map and its lit preview, and a Source material. */
#define BB_JOB_MAX_OUTPUTS (BB_MAP_BAKED_COUNT + 4)
/* A batch's file names: the input's stem, the map's name, the input's
 * extension ("{{" and "}}" are braces). */
#define BB_JOB_DEFAULT_NAME "{stem}_{kind}.png"
/* The maps a batch writes unless told: Valve's trio. */
#define BB_JOB_DEFAULT_MAPS \
  (BB_MAP_BIT(BB_MAP_NORMAL) | BB_MAP_BIT(BB_MAP_SSBUMP) | BB_MAP_BIT(BB_MAP_AO))


/* A planned job: opaque. */
typedef struct bb_job bb_job;

/* What became of one input. */
typedef enum bb_job_outcome {
  BB_JOB_PENDING = 0, /* planned, not run yet */
  BB_JOB_BAKED,       /* baked and written */
  BB_JOB_CURRENT,     /* skipped: every output was up to date */
  BB_JOB_FAILED,      /* see status and error; nothing of it was written */
  BB_JOB_NOT_RUN      /* not run: an earlier input failed (keep_going 0) */
} bb_job_outcome;

/* One file of a report: its kind ("normal", ..., "slope", "slope_lit") and path. */
typedef struct bb_job_file {
  const char *kind;
  const char *path;
} bb_job_file;

/* One input's part of a job: what it will write, and once run, what
 * happened. Owned by the job. */
typedef struct bb_job_report {
  const char *input;          /* the path as planned (a directory's file: DIR/NAME) */
  int output_count;
  bb_job_file outputs[BB_JOB_MAX_OUTPUTS]; /* in bb_map_kind order, then slope */
  bb_job_outcome outcome;
  bb_status status;           /* BB_OK unless FAILED */
  bb_error error;             /* why it FAILED ("PATH: reason") */
  char reason[256];           /* why an output is not current ("scale: 8 -> 16",
                                 "no such file"), or "" */
  /* Once baked: */
  int width, height;
  bb_height_source source;    /* the channel used, the input's depth, its hashes */
  int threads;                /* threads the stages ran on */
  int slices;                 /* azimuth slices traced, 0 when nothing was */
  char rayset_id[64];         /* "" when nothing was traced */
  double horizons;            /* texels x slices */
  double seconds_load, seconds_smooth, seconds_pyramid, seconds_trace,
      seconds_derive, seconds_write;
  /* (last, so a report read through an older declaration keeps its layout) */
  int bounces;                /* bb_bake_result.bounces: passes of inter-reflection
                                 gathered, 0 when none */
  double seconds_bounce;      /* the inter-reflection's part, after seconds_trace */
  double seconds_compress;    /* the engine textures' block compression (.vtf,
                                 .dds), a part of seconds_write; 0 when none */
} bb_job_report;

void bb_job_free(bb_job *job);

/* Inputs in the plan, and input i's report (0 <= i < count). */
int bb_job_count(const bb_job *job);
const bb_job_report *bb_job_report_get(const bb_job *job, int i);

/* The stage the input running in bb_job_run_item (or bb_job_run) is at,
 * for a progress callback that names it: "bake" (reading and baking: the
 * units of bb_trace_options.progress), "compress" (the 4 x 4 blocks of
 * its .vtf and .dds files: the units are rows of blocks, over every level
 * of every such file), or NULL between them. */
const char *bb_job_stage(const bb_job *job);

/* Whether every output of input i is what baking it now would write
 * (each output's provenance, depth and mip levels, from the files' headers;
 * no pixel is decoded):
 * *current is 1 or 0, and the report's reason says why not. The input's
 * bytes are hashed, unless its header is refused: such an input is not
 * current (the reason is the refusal its bake gives). Errors: BB_ERR_IO
 * (the input cannot be read). */
bb_status bb_job_check_current(bb_job *job, int i, int *current, bb_error *err);

/* Runs input i: skips it (BB_JOB_CURRENT) when its outputs are up to date
 * and the job is not forced, else reads, bakes and writes its maps all or
 * nothing (BB_JOB_BAKED), filling its report. progress (may be NULL)
 * follows the bake, then the block compression of its engine textures
 * (units anew: bb_job_stage; called from the writer's threads, one call
 * at a time), and may cancel either; it is also called once with done 0
 * and total 0 when the input has been read and its notes given, before the
 * bake: a nonzero return there (a note the caller takes as an error)
 * cancels with nothing baked or written. Returns the report's status; a
 * failure is the input's alone (the job goes on). Thread-compatible: one
 * job, one thread at a time. */
bb_status bb_job_run_item(bb_job *job, int i, bb_progress_fn progress, void *progress_user);

/* Reads and bakes input i exactly as bb_job_run_item does, but writes
 * nothing and keeps the maps: the job's kinds and those in `also`
 * (BB_MAP_BITs; the maps of the job's kinds are the bits
 * bb_job_run_item would write) go to *result, to be freed with
 * bb_bake_result_free. Fills the report's figures (size, source, threads,
 * slices, seconds) and leaves its outcome alone; for a live view of an
 * input that changes (bumpbake serve). progress (may be NULL) may cancel:
 * BB_ERR_CANCELLED, nothing kept. err names the input. Thread-compatible
 * as bb_job_run_item. */
bb_status bb_job_bake_item(bb_job *job, int i, unsigned also, bb_progress_fn progress,
                           void *progress_user, bb_bake_result *result, bb_error *err);

/* The bakes of job (bb_job_bake_item, bb_job_run_item) use context from
 * now on (NULL: cold again). context must outlive them. */
void bb_job_use_context(bb_job *job, bb_bake_context *context);

/* Writes input i's files (maps, Valve's file, slope files, material,
 * depfile) from result, the maps bb_job_bake_item of this same job kept,
 * as bb_job_run_item would write them after its own bake: the same bytes,
 * with no second read or bake (the report's figures are the bake's). The
 * caller keeps result. Errors: BB_ERR_ARGUMENT (i not baked by this job,
 * result missing a map the job writes or of another size, Valve's detail
 * variant, which reads the input again: bb_job_run_item), and those of
 * writing. Sets the report's outcome and error as bb_job_run_item does. */
bb_status bb_job_write_item(bb_job *job, int i, const bb_bake_result *result, bb_error *err);

/* Called after each input of bb_job_run with its report. */
typedef void (*bb_job_report_fn)(void *user, const bb_job_report *report);

/* Runs every input in order (stopping at the first failure unless
 * keep_going: the rest are BB_JOB_NOT_RUN), calling each after each, then
 * writes the depfile (a rule per input baked or up to date). Returns BB_OK
 * when no input failed and the depfile was written, else the first
 * failure's status with err naming it. */
bb_status bb_job_run(bb_job *job, bb_progress_fn progress, void *progress_user,
                     bb_job_report_fn each, void *user, bb_error *err);

/* The depfile of the inputs run so far that were baked or up to date
 * ("out1 out2: input [basis file]" per input; names escaped as GCC's
 * depfiles are, for make and ninja alike), written all or nothing.
 * bb_job_run calls it; a caller running items one by one calls it at the
 * end. BB_OK when the job has no depfile. */
bb_status bb_job_write_depfile(bb_job *job, bb_error *err);

/* --------------------------------------------------- up-to-date checks */

/* What a build tool needs to skip a bake whose outputs are already what it
 * would write: a hash of the input file, recorded in every output's
 * provenance (input_file_hash), and a check of an existing output that reads
 * only its header. */

/* 64-bit FNV-1a hash of the bytes of the file at path, read in blocks (any
 * size, constant memory), into *hash. It is what provenance records as
 * input_file_hash, so a later run can tell an input is unchanged without
 * decoding it. Errors: BB_ERR_IO (missing, unreadable, not a regular file),
 * with the system's reason. */
bb_status bb_file_hash(const char *path, uint64_t *hash, bb_error *err);

/* Whether an existing output is what writing it now would make. */
typedef enum bb_output_state {
  BB_OUTPUT_CURRENT = 0, /* made from the same input bytes, with the same
                            parameters and bumpbake version, depth and mips */
  BB_OUTPUT_MISSING,     /* no file at the path */
  BB_OUTPUT_STALE        /* a file, but made otherwise, or not known to be
                            current (no or damaged provenance, unreadable) */
} bb_output_state;

/* =====================================================================
 * cmd: every command of `bumpbake`, its options and their rules,
 * described once
 * ===================================================================== */

/* Each command (bake, normal, height2ssbump, render, ...) and each of its
 * options is described here once: name, short name, value, type, range,
 * default, the mode it belongs to, whether it determines what is made,
 * when it applies, and its help. The command line's parser, --help and
 * "did you mean", the reference pages and the man page, Python's keyword
 * arguments and the cluster's hand-over are drivers over these
 * descriptions: a value is parsed and checked by the library's one
 * function for its rule (bb_command_set), the rules between options by
 * the library's (bb_command_check), and every client prints the library's
 * words. A command's options are held by the command (opaque) and read
 * back by name (bb_command_value); the commands that write files through
 * the job are planned from them in one call (bb_command_plan). */

/* What an option's value is. */
typedef enum bb_option_type {
  BB_OPTION_FLAG = 0, /* no value: given or not */
  BB_OPTION_INT,      /* a decimal integer in the option's range */
  BB_OPTION_NUMBER,   /* a finite number in the option's range */
  BB_OPTION_WORD,     /* one of the words of bb_option_info.choices */
  BB_OPTION_WORDS,    /* several of them, comma-separated ("normal,ao") */
  BB_OPTION_NUMBERS,  /* bb_option_info.count numbers: comma-separated ("135,45"),
                         or, with values > 1, as that many words ("-size 256 128") */
  BB_OPTION_TEXT,     /* any text (a template, an address, a basis name or file) */
  BB_OPTION_PATH      /* a file or directory, not empty */
} bb_option_type;

/* The type's name, as the clients show it (Python's option table, serve's
 * controls): "flag", "integer", "number", "word", "words", "numbers",
 * "text", "path"; NULL outside the enum. Static text. */
const char *bb_option_type_name(bb_option_type type);

/* Which of a command's uses an option belongs to (for --help and the
 * reference pages). The job is where the rule lives: its plan refuses a
 * single bake's options in a batch and a batch's without out_dir, for
 * every client (bb_command_plan). */
typedef enum bb_option_mode {
  BB_MODE_ANY = 0,    /* every use */
  BB_MODE_SINGLE,     /* one input, outputs named one by one */
  BB_MODE_BATCH       /* a batch (bake --out-dir) */
} bb_option_mode;

/* bb_option_info.flags */
#define BB_OPTION_RECORDED 0x1u    /* determines what the command makes (pixels, files):
                                      kept in the provenance's command; the others
                                      (-q, --json, --threads, --depfile...) are not */
#define BB_OPTION_CLIENT 0x2u      /* how a command-line client prints (--help, --json,
                                      -q) or where it runs the command (bake
                                      --scheduler): nothing for the library's run
                                      to do, and no keyword of Python's */
#define BB_OPTION_SINGLE_DASH 0x4u /* also spelled with one dash (idiff's -fail,
                                      DOOM 3's -size) */
#define BB_OPTION_REQUIRED 0x8u    /* the command refuses to run without it */
#define BB_OPTION_FILES 0x10u      /* about the files a run writes as a whole: their
                                      names, format settings, a batch, a cluster;
                                      not for images in memory (bb_command_set_in_memory) */

/* The descriptions below are the library's static data, handed out by
 * pointer only: a program never makes, copies or steps through an array of
 * them, so a release may append fields at their end and keep the ABI. */
typedef struct bb_option_info {
  const char *name;        /* the long name without "--" ("filter-radius"); Python's
                              keyword is it with '-' as '_' (filter_radius) */
  char short_name;         /* 'o', or 0 */
  const char *value_name;  /* "S", "AZ,EL", "W H"; NULL for a flag and for a word
                              (bb_option_value_text shows its choices) */
  bb_option_type type;
  int count;               /* BB_OPTION_NUMBERS: how many numbers; else 1 */
  int values;              /* words the value takes on a command line: 1 (2 for
                              renderbumpflat's -size W H, 4 for --rect); 0 for a flag */
  bb_option_mode mode;
  unsigned flags;          /* BB_OPTION_* */
  const char *help;        /* one line */
  const char *default_text; /* the default as words, when it is not a value
                              ("from --rays", "FILE-ssbump.tga (-n: FILE-bump.tga)");
                              NULL: bb_option_default_text formats the value */
  const char *range_text;  /* the range as words, when it is not a number range
                              ("{stem} {kind} {ext}"); NULL: bb_option_range_text */
  const char *applies;     /* what the option needs to do anything ("a .vtf or .dds
                              output"), or NULL: it always does; bb_command_check
                              refuses it given where it would do nothing */
} bb_option_info;

typedef struct bb_command_info {
  const char *name;        /* "bake" */
  const char *summary;     /* one line: what it does (bumpbake --help) */
  const char *synopsis;    /* the usage after "bumpbake NAME " */
  const char *description; /* a few lines for --help and the reference pages */
  const char *inputs;      /* what its positional arguments are ("HEIGHT", "FILE
                              BUMPSCALE", "A B"), for messages */
  int min_inputs, max_inputs; /* how many (max -1: any number) */
  int usage_exit;          /* the exit code of a usage error: 2, or 4 for compare
                              (idiff's "could not compare") */
  int option_count;
} bb_command_info;

/* The commands, in the order `bumpbake --help` lists them: index 0, 1, ...
 * until NULL (and NULL below 0). Static data. */
const bb_command_info *bb_command_info_get(int index);
/* The command named name, or NULL. */
const bb_command_info *bb_command_info_find(const char *name);

/* A command's options, in the order of its --help: 0 .. option_count - 1. */
const bb_option_info *bb_command_option(const bb_command_info *command, int index);
/* The option of command named name: its long name, or with '_' for '-'
 * (Python's keyword); the first `length` characters of name (0: all). NULL
 * when none. */
const bb_option_info *bb_option_find(const bb_command_info *command, const char *name,
                                     size_t length);
/* For "did you mean": the option of command whose name is nearest to the
 * first length characters of name (at most 2 edits away, '_' read as '-'),
 * or NULL. */
const bb_option_info *bb_option_nearest(const bb_command_info *command, const char *name,
                                        size_t length);
/* The option's range as help prints it ("1..65536", "> 0", "0..1e6", its
 * range_text, its choices), into out (capacity cap); "" when it has none. */
void bb_option_range_text(const bb_option_info *option, char *out, size_t cap);
/* How help shows the option's value: its value_name, else its choices
 * ("down|up"); "" for a flag. */
void bb_option_value_text(const bb_option_info *option, char *out, size_t cap);
/* The option's numeric range: 1 and *min, *max (HUGE_VAL: none),
 * *min_exclusive filled for BB_OPTION_INT, NUMBER and NUMBERS; 0 for others. */
int bb_option_bounds(const bb_option_info *option, double *min, double *max,
                     int *min_exclusive);
/* The option's default for help into out (capacity cap): its default_text,
 * else the value a new command of this kind holds, spelled as the option
 * takes it ("256", "vertex", "periodic"); "" when it has none (a flag off,
 * a path not given). */
void bb_option_default_text(const bb_command_info *command, const bb_option_info *option,
                            char *out, size_t cap);
/* Parses text as the option's value by the option's own parser, with no
 * command to set: *value is what the word or number stands for (a word's
 * enum value: bb_channel for bake's channel, bb_depth for depth,
 * bb_texture_format, bb_normal_filter, bb_axis; normal-y's 0 down and 1
 * up; vtf-version's minor number 2..5; vtf-flags' 32 bits). For the
 * options that take words (BB_OPTION_WORD, one word of a BB_OPTION_WORDS
 * list) and those integers read by a parser of their own (vtf-version,
 * vtf-flags). Errors: BB_ERR_ARGUMENT in the value's own words, which name
 * what the value is rather than the option ("channel must be one of auto,
 * r, g, b, a, luma, mean, valve (got 'z')", "VTF version must be 7.2, 7.3,
 * 7.4 or 7.5 (got '7.9')"), or "--NAME has no word or value of its own to
 * parse" for any other option (bb_command_set reads those). */
bb_status bb_option_parse(const bb_option_info *option, const char *text, long long *value,
                          bb_error *err);
/* The word the option takes for value (bb_option_parse's inverse: "vertex"
 * for normal-filter's BB_NORMAL_VERTEX, "-y" for renderbumpflat's axis
 * BB_AXIS_NEG_Y); NULL for a value without a word or an option without
 * words. Static text. */
const char *bb_option_word(const bb_option_info *option, long long value);

/* ------------------------------------------------------------ commands */

/* One use of a command: its options and inputs as set, checked, then run.
 * Opaque; not thread-safe. */
typedef struct bb_command bb_command;

/* A command named name with every option at its default. Errors:
 * BB_ERR_ARGUMENT "unknown command 'x'" (with the nearest name when one is
 * near), BB_ERR_MEMORY. Free with bb_command_free. */
bb_status bb_command_new(const char *name, bb_command **out, bb_error *err);
void bb_command_free(bb_command *command);
const bb_command_info *bb_command_describe(const bb_command *command);

/* The directions of the weights, ssbump and bent a checked command bakes,
 * where no --basis names them (Python's basis= array of vectors, made by
 * bb_basis_from_vectors): the bake planned (bb_command_plan) and a split
 * trace's input (bb_command_trace_input) use them as --basis's. Call after
 * bb_command_check, with --basis not given; a command set or checked
 * again keeps them. The text (bb_command_text) and the hand-over spell no
 * basis. Errors: BB_ERR_ARGUMENT (no command or basis; a command taking
 * no --basis, not checked, or given --basis; a basis of other than
 * 3..BB_MAX_BASIS unit directions with z >= 0). */
bb_status bb_command_set_basis(bb_command *command, const bb_basis *basis, bb_error *err);

/* A new command `name` made of from's settings: from's inputs, and each
 * option `name` takes that from holds at a value other than a new `name`
 * command's, as text; not the files it writes (-o, a map's file), which
 * the caller names. For a client that holds one command and runs another
 * of its settings (bumpbake serve's page holds a `serve` command and bakes
 * the `bake` command it is). Unchecked: set more, then bb_command_check.
 * Errors: those of bb_command_new, bb_command_add_input and
 * bb_command_set, BB_ERR_MEMORY. Free with bb_command_free. */
bb_status bb_command_derive(const bb_command *from, const char *name, bb_command **out,
                            bb_error *err);

/* What a client that holds a command reads of its bake beyond one
 * option's value (bumpbake serve's page): the library's rules, applied.
 * The azimuth slices the bake traces: --slices, else those --rays makes
 * (round(sqrt(rays))); 0 for NULL. */
int bb_command_slices(const bb_command *command);
/* The albedo (rho) the bake bounces light with: --bounce, or 1 for
 * --bounce-albedo FILE alone (the map bounces as it is); 0 when it adds
 * no inter-reflection, and for NULL. With one, the first
 * bb_command_slices(command) units of a bake's progress are the trace's. */
double bb_command_bounce(const bb_command *command);
/* The file a checked command writes map kind to: the map's own option
 * (--normal FILE) when given, else -o PREFIX's "PREFIX_KIND.png" for the
 * maps -o writes (normal, ssbump, ao); serve's write, with neither given,
 * takes HEIGHT without its extension for PREFIX. *path malloc'd, NULL for
 * none. Errors: BB_ERR_ARGUMENT (no command or path), BB_ERR_MEMORY. */
bb_status bb_command_map_file(const bb_command *command, bb_map_kind kind, char **path,
                              bb_error *err);
/* The JSON object `bake --json` prints of r, an input baked by command's
 * job (bb_command_plan), without a newline: input, status (when not NULL:
 * "written"), size, the parameters used, seconds per stage, horizons and
 * the maps written. malloc'd; NULL when out of memory or for NULL. */
char *bb_command_report_json(const bb_command *command, const bb_job_report *r,
                             const char *status);
/* The provenance ("key=value" lines) job's file of map kind ("ssbump")
 * records for input i once baked (bb_job_bake_item, bb_job_run_item),
 * whether or not the job writes that map: the command it records, the
 * input's hashes, the parameters the kind depends on (the maps the bake
 * read named by their hashes) and the ray set traced; without the texture
 * settings a .vtf or .dds adds. malloc'd; NULL when out of memory, for an
 * input not baked or out of range. */
char *bb_job_provenance(const bb_job *job, int i, const char *kind);

/* Sets option name (as bb_option_find finds it) from text, through the
 * option's parser, into the command's options: a flag takes text NULL (or
 * "1"/"0": Python's True/False); an option of several values takes them
 * separated by blanks ("256 128"). A value that does not parse is refused
 * at once; its range, and the rules between options, by bb_command_check.
 * Errors: BB_ERR_ARGUMENT with the message every client prints ("--rays
 * needs an integer (got 'x')", "unknown option '--rayz' (did you mean
 * --rays?)"). An option set again takes the new value. */
bb_status bb_command_set(bb_command *command, const char *name, const char *text,
                         bb_error *err);

/* Puts option name back at its default, as if it had never been set: the
 * rules (bb_command_check) and the text (bb_command_text) no longer see
 * it. For a client whose control goes back to the value it starts at
 * (bumpbake serve's page). Errors: BB_ERR_ARGUMENT "unknown option ..."
 * as bb_command_set says it, and "--NAME cannot be unset: leave it out"
 * for an option whose parser sets more than its one value (--basis);
 * BB_ERR_MEMORY. An option not set is left as it is. */
bb_status bb_command_unset(bb_command *command, const char *name, bb_error *err);

/* Adds a positional argument (an input file, or height2ssbump's
 * BUMPSCALE) in order. Errors: BB_ERR_ARGUMENT (one too many, a
 * BUMPSCALE that is no number), BB_ERR_MEMORY. */
bb_status bb_command_add_input(bb_command *command, const char *text, bb_error *err);

/* Checks everything that can be checked before any file is read: the
 * inputs' count, the required options, every option's range, each option's
 * mode and whether it applies, and the rules between options (one library
 * function each); then fills in the default output names (FILE-ssbump.tga,
 * NAME_ssbump.tga, MODEL_local.tga) and checks the outputs of the commands
 * that do not run through a job against what they read. BB_OK, or
 * BB_ERR_ARGUMENT with the usage error's message, BB_ERR_IO for an output
 * that would replace an input. */
bb_status bb_command_check(bb_command *command, bb_error *err);

/* The command runs on images in memory (Python's bumpbake.bake(array),
 * render(...) on arrays), not on files: its inputs are the caller's (not
 * counted), options with BB_OPTION_FILES are refused and none is required,
 * and maps (BB_MAP_BIT(kind)s; 0 for a command that bakes no maps) are
 * the maps asked, for the rules that look at them (--bounce needs a traced
 * map). Call before bb_command_check. */
void bb_command_set_in_memory(bb_command *command, unsigned maps);

/* How a command's messages name its options: as the command line spells
 * them (the default), or as keyword arguments, for a client that takes its
 * options so (Python; a page whose controls bear the options' names). */
typedef enum bb_spelling {
  BB_SPELLING_COMMAND_LINE = 0, /* "--filter-radius", "give -o PREFIX" */
  BB_SPELLING_KEYWORDS          /* "filter_radius", "give output=PREFIX" */
} bb_spelling;

/* Sets how the messages of command's calls (bb_command_set, _check, _plan,
 * _run, _picture, _renderbump, and the notes of their hooks) name the
 * command's options: the library words each refusal once, and the option
 * rows know both spellings. */
void bb_command_set_spelling(bb_command *command, bb_spelling spelling);

/* 1 when option name was set. */
int bb_command_given(const bb_command *command, const char *name);
/* The value of option name as command holds it, spelled as the option
 * takes it and as bb_command_text spells it ("256", "0.55", "vertex",
 * "1,1,1"), into out (capacity cap): the value set, else the default a new
 * command holds; a flag "1" when given, else "0"; a file not given "".
 * The options a client keeps to itself (serve's --port and --address),
 * which the library does not use, are read here too: the text set, else
 * their default (bb_option_info.default_text). Errors:
 * BB_ERR_ARGUMENT "unknown option ..." as bb_command_set words it, or a
 * value longer than cap - 1; BB_ERR_MEMORY. */
bb_status bb_command_value(const bb_command *command, const char *name, char *out,
                           size_t cap, bb_error *err);
/* The numbers option name of command holds (an option of type
 * BB_OPTION_INT, _NUMBER or _NUMBERS: render's --light "135,45",
 * renderbumpflat's --size "256 128"), the value as bb_command_value gives
 * it read back by the option's own parser: bb_option_info.count numbers
 * (1 but for _NUMBERS) into values (room for cap), their count into *count
 * (may be NULL). A float the command holds comes back as a double that
 * converts to the same float. Errors: BB_ERR_ARGUMENT for an unknown
 * option (as bb_command_set words it), one of another type, or cap too
 * small; BB_ERR_MEMORY. */
bb_status bb_command_numbers(const bb_command *command, const char *name, double *values,
                             int cap, int *count, bb_error *err);
/* What a client that takes its options as keywords asks of render's and
 * sheet's picture and no option spells (Python's light=None and tile=(NX,
 * NY)): dynamic_light 0 turns the dynamic light off, 1 leaves it as the
 * options set it; tile_y > 0 repeats the picture tile_y times down, --tile
 * NX times across (the render checks it against --tile's range), 0 leaves
 * it. Call after bb_command_check. */
void bb_command_set_picture(bb_command *command, int dynamic_light, int tile_y);
/* Input index of those added (bb_command_add_input), or NULL past the last. */
const char *bb_command_input(const bb_command *command, int index);

/* The command as text, through the descriptions: "bumpbake NAME INPUT...
 * --option value ..." with every option given, in the order of its --help,
 * spelled as it takes it; with BB_OPTION_RECORDED in flags only those that
 * determine what is made (the provenance's command), else every one (the
 * hand-over of a planned command to another process, which reads it back
 * with bb_command_set). input not NULL: that input in place of the
 * command's (a batch's provenance names each input). malloc'd; NULL when
 * out of memory. */
char *bb_command_text(const bb_command *command, const char *input, unsigned flags);

/* The command line the outputs record as their provenance's "command",
 * when it is not the one bb_command_text spells: a command-line client
 * gives the words as typed with those of options that are not
 * BB_OPTION_RECORDED left out.
 * path NULL: every output's. line: the whole command ("bumpbake bake h.png
 * --scale 8 --normal n.png"); options: the words of the options alone,
 * which a batch's outputs record after "bumpbake bake INPUT". Either may
 * be NULL.
 * path a file: the line that file records when the command writes its map
 * to several files (bake --ssbump s.png --ssbump s.vtf: one bake, each file
 * in its format): a command-line client gives the words as typed less
 * those of the map's other files, so each file records what a bake of it
 * alone records (options NULL). Without one, such a file records the
 * command as bb_command_text spells it with only that file for its map.
 * Errors: BB_ERR_MEMORY; BB_ERR_ARGUMENT (a file without its line, or
 * with options; more files than a command writes). */
bb_status bb_command_set_record(bb_command *command, const char *path, const char *line,
                                const char *options, bb_error *err);

/* What a caller hooks into a command's run; every field may be NULL. */
typedef struct bb_command_hooks {
  bb_note_fn note;      /* notes about the inputs */
  void *note_user;
  bb_progress_fn progress; /* follows the bake (bb_command_run), may cancel it */
  void *progress_user;
  bb_trace_fn trace;    /* a trace of the caller's in place of the bake's own
                           (bb_trace_options.trace): a trace split over machines */
  void *trace_user;
} bb_command_hooks;

/* Plans a checked command that writes through the job (bake, normal,
 * height2ssbump): its options as a job's, planned by the job
 * (every output named and checked against every input, provenance,
 * depths, staged all-or-nothing writes, up-to-date checks), without
 * checking again what bb_command_check checked. A single input is baked
 * even when its outputs are current, as the command line does (run it with
 * bb_job_run_item after bb_job_check_current to skip it). Run it with
 * bb_job_run; free it with bb_job_free. hooks may be NULL. Errors: those of
 * the job's plan; BB_ERR_ARGUMENT for an unchecked command or one that has no
 * job. */
bb_status bb_command_plan(bb_command *command, const bb_command_hooks *hooks, bb_job **job,
                          bb_error *err);

/* Plans a checked `check` command (bb_command_check): GOLDEN and NEW, two
 * directories (or two files), or GOLDEN and heights with --bake, a batch
 * whose out-dir is GOLDEN, planned as bake plans it (every option and name
 * checked; nothing written, no directory made) unless --update; the
 * limits (idiff's options, then --limits' rules by kind or name); the
 * reports asked (--junit FILE, --html DIR; the report's directory is made,
 * and the pictures a run of it left before removed). hooks (may be NULL):
 * the bake's notes. Free with bb_check_free. Errors: BB_ERR_ARGUMENT (not
 * a checked check command), BB_ERR_IO (GOLDEN or NEW is not there: GOLDEN
 * may be missing only with --update, which makes it), those of the bake's
 * plan. */
bb_status bb_check_plan(bb_command *command, const bb_command_hooks *hooks, bb_check **out,
                        bb_error *err);

/* What `info` found of one file (bb_command_result.info): what its header
 * says, or why it could not be read. Owned by the result. */
typedef struct bb_info_file {
  const char *path;            /* the input, as given (a copy the result owns) */
  bb_status status;            /* BB_OK, or why the header could not be read */
  const char *error;           /* then the reason, naming the file; else NULL */
  int width, height, channels;
  bb_image_info image;         /* format, sample type, alpha channel; description:
                                  the text stored (provenance or another tool's) */
  bb_provenance_class provenance; /* of image.description */
  int provenance_count;        /* intact provenance: its key=value lines, as
                                  provenance is read (a key seen again keeps its
                                  first value); else 0 */
  const bb_provenance_entry *provenance_entries; /* into image.description */
  const bb_vtf_info *vtf;      /* a VTF's header, else NULL */
  const bb_dds_info *dds;      /* a DDS's header, else NULL */
  const char *flag_names[32];  /* of the VTF's flags or the DDS's pixel format
                                  flags: each bit's name when set and named,
                                  else NULL (static text) */
} bb_info_file;

/* A piece of what a command-line client prints of a run, in order
 * (bb_command_result.prints). */
typedef struct bb_command_print {
  int error;        /* 0: lines for stdout, made printable (control characters
                       escaped), each ending in '\n'; 1: a one-line message
                       for stderr, after the client's name ("bumpbake: ") */
  const char *path; /* an error about this file, which the client names
                       before text unless text starts with it (a copy the
                       result owns); or NULL */
  char *text;
} bb_command_print;

/* What a command's run wrote, or found. */
typedef struct bb_command_result {
  int file_count;
  bb_job_file *files;    /* what was written, in order: kind ("normal", "render",
                            "orbit"...) and path; owned by the result */
  int frames;            /* render --orbit: the frames (files holds each frame, or
                            the one GIF); 0 for one picture */
  int labels_drawn;      /* 0 when a picture's labels could not be drawn (no font:
                            render --compare, sheet); else 1 */
  int exit_code;         /* the command line's exit code for what was found:
                            compare's idiff code (0 pass, 1 warning, 2 failure,
                            BB_COMPARE_DIFFERENT_SIZE), info's 1 when a file
                            could not be read; else 0 */
  const bb_compare_report *compare; /* compare: what it found; else NULL */
  int info_count;        /* info: a file each input, in order */
  const bb_info_file *info;
  int print_count;       /* compare, info: what the command line prints of the
                            report, text or one JSON line (per file for info)
                            as options.json says, none of it with quiet but
                            the errors; owned by the result */
  const bb_command_print *prints;
} bb_command_result;

/* Runs a checked command as the command line runs it: those through the
 * job (bake, normal, height2ssbump) are planned and run (stopping at the
 * first failing input; bb_command_plan and bb_job_run for each input's
 * report); render, sheet, normal2ssbump, ssbump2normal, combine, program
 * and renderbumpflat read their inputs, make their picture, map or render
 * bump and write it all or nothing with provenance (its command the
 * record, else bb_command_text's); compare compares A and B as idiff does
 * (what it will take said first through hooks->note when that is much;
 * result.compare, result.exit_code, its --diff in files), and info reads
 * each file's header (result.info; a file that cannot be read is reported
 * there, not an error): both with their report rendered as the command
 * line prints it (result.prints). hooks may be NULL. Fills result (free it
 * with bb_command_result_free) on success. Errors name the file: those of
 * the reads, the bake and the writes (compare: a file that cannot be read,
 * idiff's BB_COMPARE_CANNOT_READ); BB_ERR_ARGUMENT for an unchecked command
 * or one that runs nothing (serve); BB_ERR_MEMORY. */
bb_status bb_command_run(bb_command *command, const bb_command_hooks *hooks,
                         bb_command_result *result, bb_error *err);
void bb_command_result_free(bb_command_result *result);

/* renderbumpflat's run (bb_command_run's), handing back what it rendered
 * as well: the model (the command's input) read (its note to
 * hooks->note), rendered flat (its notes to
 * hooks->note, naming the model) into render (allocated; free with
 * bb_renderbump_result_free), and its files written by
 * the job with the command's record, listed in result (free
 * with bb_command_result_free): "normal", then "height" when asked. A
 * command set in memory (bb_command_set_in_memory, before its check)
 * writes nothing. Errors: BB_ERR_ARGUMENT (not a checked renderbumpflat),
 * those of the load and the render naming the model, those of the write;
 * render and result are then empty. */
bb_status bb_command_renderbump(bb_command *command, const bb_command_hooks *hooks,
                                bb_renderbump_result *render, bb_command_result *result,
                                bb_error *err);

/* Render's or sheet's picture of images in memory, with the options of a
 * command checked for them (bb_command_set_in_memory): height, when not
 * NULL, is a 1-channel height field (bb_height_from_image) baked as the
 * command line bakes a HEIGHT (render: the maps its picture lights, its
 * relief the filtered height); else render lights maps (decoded, as
 * bb_render_map_read gives them; maps->albedo also with a height). out
 * (allocated) receives render's picture (with the light as given: an
 * orbit's first frame) or sheet's contact sheet; *labels_drawn (may be
 * NULL) is 0 when the labels could not be drawn (no font). Errors as
 * bb_command_bake's, and render's or sheet's. */
bb_status bb_command_picture(bb_command *command, const bb_image *height,
                             const bb_render_maps *maps, const bb_command_hooks *hooks,
                             bb_image *out, int *labels_drawn, bb_error *err);

/* program's run (bb_command_run's) in memory: the DOOM 3 image program of
 * a checked `program` command (its input: "addnormals(a_local.tga,
 * heightmap(a_h.tga, 4))", docs/commands/program.md gives each function)
 * evaluated as id Tech 4 does, in float rather than bytes, its image names
 * read relative to --base and kept inside it unless --allow-outside-base;
 * nothing written. When the program makes a normal map (heightmap,
 * addnormals, smoothnormals or _flat in it, as id marks TD_BUMP), out
 * (allocated; free with bb_image_free) holds its decoded N (3 channels, +Y
 * down) and *is_normal_map is 1; otherwise RGBA colour in [0, 1] (4
 * channels) and 0. Errors: BB_ERR_ARGUMENT (not a checked program; a
 * syntax error, giving the 1-based column; an unknown function, listing
 * the known ones; an image name leaving the base), those of the reads
 * naming the file. */
bb_status bb_command_program(bb_command *command, bb_image *out, int *is_normal_map,
                             bb_error *err);

/* The map of normal2ssbump, ssbump2normal or combine (bb_command_run's) of
 * images in memory, with the options of a command checked for them
 * (bb_command_set_in_memory; combine's --mask or --brightness given as any
 * text, the images being these): nothing read or written. a holds the
 * values a file's map decodes to: normal2ssbump's unit normals (3
 * channels), the basis map ssbump2normal turns back into normals, or
 * combine's A (normals decoded, as bb_normal_map_decode gives them). b:
 * combine's B, or with --brightness the brightness map (grey, or luma of
 * R, G, B); NULL otherwise. mask: combine --mask's T per texel (1 channel,
 * clamped to 0..1), else NULL. b_depth: the depth of the file combine
 * --detail's B would be read from, whose flat texel it leaves A unchanged
 * at (an 8-bit ssbump holds 147/255); BB_DEPTH_DEFAULT: the exact flat.
 * basis: the directions normal2ssbump's weights are of (NULL: Half-Life
 * 2's, the command line's). Normals in and out follow --normal-y. out
 * (allocated; free with bb_image_free): normal2ssbump's weights (a channel
 * per direction), ssbump2normal's normals (3 channels), combine's map
 * (A's channels). Errors: BB_ERR_ARGUMENT (not a checked command of the
 * three set in memory; a or combine's b missing or empty; maps of two
 * sizes; a channel count or basis the operator refuses), BB_ERR_VALUE (a
 * NaN or infinite value, naming the texel), BB_ERR_MEMORY. */
bb_status bb_command_map(bb_command *command, const bb_image *a, const bb_image *b,
                         const bb_image *mask, bb_depth b_depth, const bb_basis *basis,
                         bb_image *out, bb_error *err);

/* bake's or normal's bake (bb_command_run's) of a height in memory, with
 * the options of a command checked for it (bb_command_set_in_memory with
 * the maps asked; --bounce-albedo or --brightness given as any text, the
 * images being these): nothing read or written. height: a 1-channel
 * height field (bb_height_from_image by the command's --channel), baked as
 * the command line bakes a HEIGHT. bounce_albedo, brightness: the images
 * those options name, NULL when not given. basis: the directions of the
 * weights, ssbump and bent (NULL: the command's --basis). hooks (may be
 * NULL): progress follows the bake and may cancel it; trace, a trace of
 * the caller's in place of the bake's own (bb_trace_fn). context (may be
 * NULL): the bake runs through it (bb_bake_context_new; warm, and
 * edit-local after bb_bake_context_keep), with the same bits. maps: an
 * array of BB_MAP_BAKED_COUNT images, by bb_map_kind: each map asked is
 * allocated (free with bb_image_free), the others are left empty.
 * changed (may be NULL): the texels whose maps may differ from the
 * context's bake before (bb_bake_context_changed); the whole image
 * without a context. Errors: BB_ERR_ARGUMENT (not a checked bake or
 * normal set in memory; no height; an image for a file option not given,
 * or none for one given; a value outside the range of bake's option for
 * it, bb_option_bounds; a bounce albedo or brightness map without pixels
 * or of another size; a basis of other than 3..BB_MAX_BASIS unit
 * directions with z >= 0), BB_ERR_VALUE (NaN heights, scale x height
 * overflowing), BB_ERR_MEMORY, and BB_ERR_CANCELLED when progress
 * cancelled it: then every map is empty. Results are bit-identical for
 * any --threads. */
bb_status bb_command_bake(bb_command *command, const bb_image *height,
                          const bb_image *bounce_albedo, const bb_image *brightness,
                          const bb_basis *basis, const bb_command_hooks *hooks,
                          bb_bake_context *context, bb_image *maps, bb_region *changed,
                          bb_error *err);

/* ------------------------------------------------- names of enums printed */

/* The word a report gives a value of its field, as the command line, its
 * JSON and Python print it: field "outcome" (bb_job_report.outcome:
 * "pending", "baked", "up to date", "failed", "not run") or "result"
 * (bb_check_case.status: "PASS", "WARNING", "FAILURE", "DIFFERENT SIZE",
 * "UNREADABLE", "MISSING", "EXTRA"); NULL for another field or a value
 * outside its enum. Static text. */
const char *bb_report_word(const char *field, int value);

#ifdef __cplusplus
}
#endif

#endif /* BUMPBAKE_H */
