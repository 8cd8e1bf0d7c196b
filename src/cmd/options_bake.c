/* options_bake.c: the options of the commands that bake a height (bake,
 * normal, height2ssbump; render and sheet take the same bake options),
 * each described once, and those three commands: their defaults, their
 * rules and their job. */
#include "bake/bake_internal.h"
#include "cmd/cmd_internal.h"
#include "job/job_internal.h"
#include "texture/texture.h"
#include "render/render_internal.h"

#include <arpa/inet.h>
#include <ctype.h>
#include <float.h>
#include <math.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define AT(member) offsetof(bb_command_options, member)
#define RECORDED BB_OPTION_RECORDED

/* ----------------------------------------------------------- set & print */

/* --basis: the library's rule (bb_basis_resolve): a name, else a basis
 * file. A word that is neither is a usage error; a file that is there but
 * wrong is the file's error (its own status: exit 1 on the command line). */
static bb_status set_basis(bb_command *c, const bb__option *o, const char *text,
                           double *values, int *count, bb_error *err) {
  *count = 0;
  (void)o, (void)values;
  bb_error e = {{0}};
  int from_file = 0;
  bb_basis basis;
  bb_status st = bb_basis_resolve(text, &basis, &from_file, &e);
  if (st == BB_ERR_ARGUMENT && !from_file)
    return bb__fail(err, st, "--%s", e.message);
  if (st == BB_ERR_ARGUMENT) /* a basis file that is there but wrong: the file's error */
    return bb__fail(err, BB_ERR_FORMAT, "%s", e.message);
  if (st != BB_OK)
    return bb__fail(err, st, "%s", e.message);
  c->options.job.bake.basis = basis;
  c->options.job.basis_file = NULL;
  if (from_file && !(c->options.job.basis_file = bb__command_keep(c, text)))
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  return BB_OK;
}

static void basis_range(char *out, size_t cap) {
  snprintf(out, cap, "N 3..%d", BB_MAX_BASIS);
}

/* --threads: every stage's, and the block compression's (the bytes are the
 * same for any count). */
static bb_status set_threads(bb_command *c, const bb__option *o, const char *text,
                             double *values, int *count, bb_error *err) {
  bb_status st = bb__set_generic(c, o, text, values, count, err);
  if (st != BB_OK)
    return st;
  const int n = (int)values[0];
  c->options.job.bake.trace.threads = n;
  c->options.job.texture.threads = n;
  c->options.render.threads = n;
  c->options.renderbump.threads = n;
  return BB_OK;
}

static void print_threads(const bb_command *c, const bb__option *o, bb__text *t) {
  (void)o;
  bb__text_printf(t, "%d", c->options.job.bake.trace.threads);
}

/* --vtf-version and --vtf-flags: the library's parsers of them (their rows
 * print them). */
static bb_status set_vtf_version(bb_command *c, const bb__option *o, const char *text,
                                 double *values, int *count, bb_error *err) {
  *count = 0;
  (void)o, (void)values;
  bb_error e = {{0}};
  if (bb__vtf_version_parse(text, &c->options.job.texture.vtf_version, &e) != BB_OK)
    return bb__fail(err, BB_ERR_ARGUMENT, "--vtf-version: %s", e.message);
  return BB_OK;
}

static bb_status set_vtf_flags(bb_command *c, const bb__option *o, const char *text,
                               double *values, int *count, bb_error *err) {
  *count = 0;
  (void)o, (void)values;
  bb_error e = {{0}};
  if (bb__vtf_flags_parse(text, &c->options.job.texture.vtf_flags, &e) != BB_OK)
    return bb__fail(err, BB_ERR_ARGUMENT, "--vtf-flags: %s", e.message);
  return BB_OK;
}

/* The same parsers in the value's own words, for bb_option_parse ("VTF
 * version must be 7.2, 7.3, 7.4 or 7.5 (got '7.9')"). */
static bb_status parse_vtf_version(const char *text, long long *value, bb_error *err) {
  int minor = 0;
  const bb_status st = bb__vtf_version_parse(text, &minor, err);
  if (st == BB_OK)
    *value = minor;
  return st;
}

static bb_status parse_vtf_flags(const char *text, long long *value, bb_error *err) {
  uint32_t flags = 0;
  const bb_status st = bb__vtf_flags_parse(text, &flags, err);
  if (st == BB_OK)
    *value = flags;
  return st;
}

/* --maps LIST: the bake's map names, comma-separated. */
static bb_status set_maps(bb_command *c, const bb__option *o, const char *text,
                          double *values, int *count, bb_error *err) {
  *count = 0;
  (void)values;
  unsigned maps = 0;
  for (const char *s = text; *s;) {
    const size_t n = strcspn(s, ",");
    char name[32];
    long long kind = 0;
    snprintf(name, sizeof name, "%.*s", (int)(n < sizeof name ? n : sizeof name - 1), s);
    if (n >= sizeof name || o->parse(name, &kind, NULL) != BB_OK) {
      char choices[128];
      bb__choices(o, choices, sizeof choices);
      for (char *bar = strchr(choices, '|'); bar; bar = strchr(bar, '|'))
        *bar = ',';
      return bb__fail(err, BB_ERR_ARGUMENT, "--maps: unknown map '%.*s' (one of %s)",
                      (int)(n < 64 ? n : 64), s, choices);
    }
    maps |= BB_MAP_BIT((int)kind);
    s += n + (s[n] == ',');
  }
  if (!maps)
    return bb__fail(err, BB_ERR_ARGUMENT, "--maps: no map named");
  c->options.job.maps = maps;
  return BB_OK;
}


/* ------------------------------------------------------------ the rows */

#define ROW_SCALE(flags_)                                                                 \
  {.info = {.name = bb__row_scale.name,                                                   \
            .value_name = "S", .type = BB_OPTION_NUMBER, .count = 1,                      \
            .values = 1, .flags = RECORDED | (flags_), .default_text = "(required)",      \
            .help = "height scale: texels of displacement per unit of normalised height"},\
   .job = &bb__row_scale,                                                                 \
   .range = &bb__range_height_scale,                                                      \
   .required_note = "texels of displacement per unit of height"}
const bb__option bb__opt_scale = ROW_SCALE(BB_OPTION_REQUIRED);
const bb__option bb__opt_scale_optional = ROW_SCALE(0);

#define ROW_RAYS(short_)                                                                  \
  {.info = {.name = bb__row_rays.name,                                                    \
            .short_name = (short_), .value_name = "N",                                    \
            .type = BB_OPTION_INT, .count = 1, .values = 1, .flags = RECORDED,            \
            .help = "ray budget, as Valve's -r: round(sqrt(N)) azimuth slices"},          \
   .job = &bb__row_rays, .range = &bb__range_rays}
const bb__option bb__opt_rays = ROW_RAYS(0);
static const bb__option opt_rays_valve = ROW_RAYS('r');

const bb__option bb__opt_slices = {
    .info = {.name = bb__row_slices.name,
             .value_name = "A", .type = BB_OPTION_INT, .count = 1,
             .values = 1, .flags = RECORDED, .default_text = "from --rays",
             .help = "azimuth slices, each integrated exactly above its horizon (overrides "
                     "--rays)"},
    .job = &bb__row_slices, .range = &bb__range_slices};

#define ROW_FILTER_RADIUS(short_)                                                         \
  {.info = {.name = bb__row_filter_radius.name,                                           \
            .short_name = (short_), .value_name = "R",                                    \
            .type = BB_OPTION_INT, .count = 1, .values = 1, .flags = RECORDED,            \
            .help = "bilateral smoothing radius in texels, 0 = off"},                     \
   .job = &bb__row_filter_radius,                                                         \
   .range = &bb__range_filter_radius}
const bb__option bb__opt_filter_radius = ROW_FILTER_RADIUS(0);
static const bb__option opt_filter_radius_valve = ROW_FILTER_RADIUS('f');

const bb__option bb__opt_filter_threshold = {
    .info = {.name = bb__row_filter_threshold.name,
             .value_name = "T", .type = BB_OPTION_NUMBER,
             .count = 1, .values = 1, .flags = RECORDED,
             .help = "smoothing range threshold in normalised height (2/255 = 0.00784)"},
    .job = &bb__row_filter_threshold,
    .range = &bb__range_filter_threshold};

const bb__option bb__opt_bias = {
    .info = {.name = bb__row_bias.name,
             .value_name = "B", .type = BB_OPTION_NUMBER, .count = 1,
             .values = 1, .flags = RECORDED,
             .help = "ray origin lift above the vertex in texels (0.55 = Valve's offset)"},
    .job = &bb__row_bias, .range = &bb__range_bias};

const bb__option bb__opt_power = {
    .info = {.name = bb__row_power.name,
             .value_name = "P", .type = BB_OPTION_NUMBER, .count = 1,
             .values = 1, .flags = RECORDED, .help = "exponent of the basis lobes max(0, w.B)^P"},
    .job = &bb__row_power, .range = &bb__range_power};

const bb__option bb__opt_basis = {
    .info = {.name = bb__row_basis.name,
             .value_name = "hl2|hl2+z|dirs:N|FILE", .type = BB_OPTION_TEXT,
             .count = 1, .values = 1, .flags = RECORDED,
             .help = "directions occlusion is projected on, one channel each: Half-Life 2's, N "
                     "evenly spread, or a file of x y z lines (docs/commands/bake.md, "
                     "\"Bases\")"},
    .job = &bb__row_basis, .set = set_basis, .range_words = basis_range};

const bb__option bb__opt_normal_filter = {
    .info = {.name = bb__row_normal_filter.name,
             .type = BB_OPTION_WORD, .count = 1, .values = 1,
             .flags = RECORDED,
             .help = "normal estimator (vertex: centred on the ray origin; valve: Valve's)"},
    .job = &bb__row_normal_filter, .parse = bb__parse_normal_filter};

const bb__option bb__opt_normal_y = {
    .info = {.name = bb__row_normal_y.name,
             .type = BB_OPTION_WORD, .count = 1, .values = 1,
             .flags = RECORDED,
             .help = "green axis: down = Source/DirectX, up = OpenGL (flips green)"},
    .job = &bb__row_normal_y,
    .parse = bb__parse_normal_y};

const bb__option bb__opt_threads = {
    .info = {.name = "threads", .value_name = "N", .type = BB_OPTION_INT, .count = 1,
             .values = 1, .help = "worker threads of every stage, 0 = all cores"},
    .range = &bb__range_threads, .set = set_threads, .print = print_threads};

const bb__option bb__opt_clamp = {
    .info = {.name = bb__row_clamp.name, .type = BB_OPTION_FLAG, .flags = RECORDED,
             .default_text = "periodic", .help = "extend border texels instead of tiling"},
    .job = &bb__row_clamp};

const bb__option bb__opt_channel = {
    .info = {.name = bb__row_channel.name,
             .type = BB_OPTION_WORD, .count = 1, .values = 1,
             .flags = RECORDED,
             .help = "height channel (auto: the grey; alpha where it holds the height, as "
                     "Valve's tools keep it; else the mean of R, G, B; a note says which)"},
    .job = &bb__row_channel,
    .parse = bb__parse_channel};

#define ROW_DEPTH(default_, help_)                                                        \
  {.info = {.name = bb__row_depth.name,                                                   \
            .type = BB_OPTION_WORD, .count = 1, .values = 1,                              \
            .flags = RECORDED | BB_OPTION_FILES, .default_text = (default_),              \
            .help = (help_)},                                                             \
   .job = &bb__row_depth,                                                                 \
   .parse = bb__parse_depth}
const bb__option bb__opt_depth =
    ROW_DEPTH("by format", "sample depth (default: 8 for png/tga/tif, float for exr)");
const bb__option bb__opt_depth_like_input =
    ROW_DEPTH("the input's when the format holds it, else 8 (png/tga/tif) or float (exr)",
              "sample depth of the output");
const bb__option bb__opt_depth_of_format =
    ROW_DEPTH("8 (png/tga/tif) or float (exr)", "sample depth of the output");

const bb__option bb__opt_mips = {
    .info = {.name = bb__row_mips.name,
             .type = BB_OPTION_FLAG, .flags = RECORDED | BB_OPTION_FILES, .default_text = "off",
             .help = "write mip-mapped files (.tif/.exr): each level box-filtered, normals "
                     "renormalised"},
    .job = &bb__row_mips};

const bb__option bb__opt_bounce = {
    .info = {.name = bb__row_bounce.name,
             .value_name = "RHO", .type = BB_OPTION_NUMBER, .count = 1,
             .values = 1, .flags = RECORDED,
             .default_text = "0 (none; 1 with --bounce-albedo)",
             .applies = "a traced map (--ssbump, --ao, --bent)",
             .help = "inter-reflection: ao, ssbump and bent include the light the relief "
                     "reflects, albedo RHO (docs/commands/bake.md)"},
    .job = &bb__row_bounce,
    .range = &bb__range_bounce_albedo, .applies = bb__applies_traced};

const bb__option bb__opt_bounces = {
    .info = {.name = bb__row_bounces.name,
             .value_name = "N", .type = BB_OPTION_INT, .count = 1,
             .values = 1, .flags = RECORDED, .default_text = "0 (until converged)",
             .applies = "--bounce RHO or --bounce-albedo FILE",
             .help = "bounces of reflected light to follow"},
    .job = &bb__row_bounces, .range = &bb__range_bounces,
    .applies = bb__applies_bounces};

const bb__option bb__opt_bounce_albedo = {
    .info = {.name = bb__row_bounce_albedo.name,
             .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .flags = RECORDED,
             .applies = "a traced map (--ssbump, --ao, --bent)",
             .help = "albedo map (grey; RGB: luma) of the height's size, times RHO"},
    .job = &bb__row_bounce_albedo,
    .applies = bb__applies_traced};

const bb__option bb__opt_brightness = {
    .info = {.name = bb__row_brightness.name,
             .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .flags = RECORDED, .applies = "an ssbump or weights map",
             .help = "brightness map (grey; RGB: luma) multiplying ssbump and weights (a "
                     "texel over 1 is scaled down whole)"},
    .job = &bb__row_brightness,
    .applies = bb__applies_brightness};

#define ROW_MAP_OUT(row_, help_)                                                          \
  {.info = {.name = (row_).name, .value_name = "FILE", .type = BB_OPTION_PATH,           \
            .count = 1, .values = 1, .mode = BB_MODE_SINGLE,                              \
            .flags = RECORDED | BB_OPTION_FILES,                                          \
            .help = (help_)},                                                             \
   .job = &(row_), .repeats = 1}
static const bb__option opt_out_normal =
    ROW_MAP_OUT(bb__row_normal, "write the normal map");
static const bb__option opt_out_weights =
    ROW_MAP_OUT(bb__row_weights, "write the basis weights (normal2ssbump)");
static const bb__option opt_out_ssbump =
    ROW_MAP_OUT(bb__row_ssbump, "write the self-shadowed bump map (traces)");
static const bb__option opt_out_ao =
    ROW_MAP_OUT(bb__row_ao, "write the ambient occlusion (traces)");
static const bb__option opt_out_bent =
    ROW_MAP_OUT(bb__row_bent, "write the bent normal (traces)");
static const bb__option opt_out_filtered =
    ROW_MAP_OUT(bb__row_filtered, "write the smoothed height");

static const bb__option opt_slope = {
    .info = {.name = bb__row_slope.name,
             .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .mode = BB_MODE_SINGLE, .flags = RECORDED | BB_OPTION_FILES,
             .help = "write flipcode's slope map: 1 byte per texel, dx low nibble, dy high "
                     "(8-bit .png .tga .tif)"},
    .job = &bb__row_slope};

/* --lit is an AZ,EL field (BB__FIELD_ANGLES): two doubles. */
_Static_assert(offsetof(bb_job_options, slope_lit_elevation) ==
                   offsetof(bb_job_options, slope_lit_azimuth) + sizeof(double),
               "--lit: azimuth, then elevation");

static const bb__option opt_lit = {
    .info = {.name = bb__row_lit.name,
             .value_name = "AZ,EL", .type = BB_OPTION_NUMBERS, .count = 2,
             .values = 1, .mode = BB_MODE_SINGLE, .flags = RECORDED | BB_OPTION_FILES, .default_text = "",
             .help = "also write the slope map lit through its 16x16 table as FILE_lit (AZ 0 = "
                     "light from the right, 90 = from the top, as render's --light)"},
    .job = &bb__row_lit,
    .range = &bb__range_light_elevation, .range_of = "elevation"};

static const bb__option opt_prefix = {
    .info = {.name = "output", .short_name = 'o', .value_name = "PREFIX",
             .type = BB_OPTION_PATH, .count = 1, .values = 1, .mode = BB_MODE_SINGLE,
             .flags = RECORDED | BB_OPTION_FILES,
             .help = "write PREFIX_normal.png, PREFIX_ssbump.png and PREFIX_ao.png"},
    .field = BB__FIELD_STRING, .offset = AT(job.prefix)};

static const bb__option opt_out_dir = {
    .info = {.name = bb__row_out_dir.name,
             .value_name = "DIR", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .flags = RECORDED | BB_OPTION_FILES,
             .help = "a batch: bake every HEIGHT (files, or directories of images) into DIR"},
    .job = &bb__row_out_dir};

const bb__option bb__opt_maps = {
    .info = {.name = bb__row_maps.name,
             .value_name = "LIST", .type = BB_OPTION_WORDS, .count = 1,
             .values = 1, .mode = BB_MODE_BATCH, .flags = RECORDED | BB_OPTION_FILES,
             .default_text = "normal,ssbump,ao",
             .help = "the maps a batch writes, comma-separated"},
    .job = &bb__row_maps, .parse = bb__parse_output_kind, .set = set_maps};

const bb__option bb__opt_name = {
    .info = {.name = bb__row_name.name,
             .value_name = "TEMPLATE", .type = BB_OPTION_TEXT, .count = 1,
             .values = 1, .mode = BB_MODE_BATCH, .flags = RECORDED | BB_OPTION_FILES,
             .default_text = BB_JOB_DEFAULT_NAME, .range_text = "{stem} {kind} {ext}",
             .help = "a batch's file names: the input's stem, the map, the input's extension"},
    .job = &bb__row_name};

static const bb__option opt_keep_going = {
    .info = {.name = "keep-going", .type = BB_OPTION_FLAG, .flags = BB_OPTION_FILES, .mode = BB_MODE_BATCH,
             .help = "a batch goes on after an input fails (and exits 1 at the end)"},
    .field = BB__FIELD_INT, .offset = AT(job.keep_going)};

static const bb__option opt_force = {
    .info = {.name = "force", .type = BB_OPTION_FLAG, .flags = BB_OPTION_FILES, .mode = BB_MODE_BATCH,
             .applies = "--out-dir DIR",
             .help = "a batch bakes inputs whose outputs are up to date, too"},
    .field = BB__FIELD_INT, .offset = AT(job.force), .applies = bb__applies_batch};

static const bb__option opt_depfile = {
    .info = {.name = "depfile", .value_name = "FILE", .type = BB_OPTION_PATH, .flags = BB_OPTION_FILES, .count = 1,
             .values = 1,
             .help = "write a Make/Ninja depfile: the outputs depend on the input (and "
                     "--basis FILE)"},
    .field = BB__FIELD_STRING, .offset = AT(job.depfile)};

const bb__option bb__opt_json = {
    .info = {.name = "json", .type = BB_OPTION_FLAG, .flags = BB_OPTION_CLIENT,
             .default_text = "off", .help = "print one JSON line describing the bake on stdout"},
    .field = BB__FIELD_INT, .offset = AT(json)};

#define ROW_QUIET(short_, help_)                                                           \
  {.info = {.name = "quiet", .short_name = (short_), .type = BB_OPTION_FLAG,              \
            .flags = BB_OPTION_CLIENT, .help = (help_)},                                   \
   .field = BB__FIELD_INT, .offset = AT(quiet)}
static const bb__option opt_quiet_bake =
    ROW_QUIET('q', "no progress bar, no list of files written");
const bb__option bb__opt_quiet = ROW_QUIET('q', "no list of files written");

const bb__option bb__opt_help = {
    .info = {.name = "help", .short_name = 'h', .type = BB_OPTION_FLAG,
             .flags = BB_OPTION_CLIENT, .help = "print this help and exit"}};

/* Engine textures (.vtf, .dds) and a Source material. */
const bb__option bb__opt_texture_format = {
    .info = {.name = bb__row_texture_format.name,
             .value_name = "NAME", .type = BB_OPTION_WORD,
             .count = 1, .values = 1, .flags = RECORDED | BB_OPTION_FILES, .default_text = "default",
             .range_text = "dxt1 dxt5 bgr888 bgra8888 rgba16f (vtf); bc1 bc3 bc4 bc5 rgba8 "
                           "rgba16f rgba32f (dds)",
             .applies = "a .vtf or .dds output",
             .help = ".vtf/.dds format; default: VTF DXT1 (DXT5 with alpha); DDS BC5 normals, "
                     "BC4 grey, BC1 colour (docs/textures.md)"},
    .job = &bb__row_texture_format, .parse = bb__parse_texture_format,
    .applies = bb__applies_texture};

const bb__option bb__opt_vtf_version = {
    .info = {.name = bb__row_vtf_version.name,
             .value_name = "7.N", .type = BB_OPTION_TEXT, .count = 1,
             .values = 1, .flags = RECORDED | BB_OPTION_FILES, .default_text = "7.2", .range_text = "7.2..7.5",
             .applies = "a .vtf output",
             .help = "VTF version: 7.2 loads in every Source branch; 7.3 and up keep "
                     "provenance"},
    .job = &bb__row_vtf_version, .parse = parse_vtf_version, .set = set_vtf_version,
    .applies = bb__applies_vtf};

const bb__option bb__opt_vtf_flags = {
    .info = {.name = bb__row_vtf_flags.name,
             .value_name = "HEX", .type = BB_OPTION_TEXT, .count = 1,
             .values = 1, .flags = RECORDED | BB_OPTION_FILES, .default_text = "0",
             .applies = "a .vtf output",
             .help = "TEXTUREFLAGS_* bits added to the map's own (SSBUMP, NORMAL), e.g. 0x4 "
                     "= CLAMPS"},
    .job = &bb__row_vtf_flags, .parse = parse_vtf_flags, .set = set_vtf_flags,
    .applies = bb__applies_vtf};

const bb__option bb__opt_nomip = {
    .info = {.name = bb__row_nomip.name,
             .type = BB_OPTION_FLAG, .flags = RECORDED | BB_OPTION_FILES, .default_text = "off",
             .applies = "a .vtf or .dds output",
             .help = "write .vtf/.dds without their mip chain (vtex's nomip)"},
    .job = &bb__row_nomip, .applies = bb__applies_texture};

const bb__option bb__opt_fast_compression = {
    .info = {.name = bb__row_fast_compression.name,
             .type = BB_OPTION_FLAG, .flags = RECORDED | BB_OPTION_FILES,
             .default_text = "off", .applies = "a .vtf or .dds output",
             .help = "block-compress DXT1/DXT5 colour with a quicker fit: ~40% less time "
                     "writing, ~0.1 dB lower PSNR"},
    .job = &bb__row_fast_compression, .applies = bb__applies_texture};

static const bb__option opt_vmt = {
    .info = {.name = bb__row_vmt.name,
             .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .mode = BB_MODE_SINGLE, .flags = RECORDED | BB_OPTION_FILES,
             .help = "also write a Source material (LightmappedGeneric) naming the .vtf bump "
                     "map"},
    .job = &bb__row_vmt};

static const bb__option opt_materials = {
    .info = {.name = bb__row_materials.name,
             .value_name = "DIR", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .mode = BB_MODE_SINGLE, .flags = RECORDED | BB_OPTION_FILES,
             .default_text = "the folder named materials above the bump map",
             .help = "the game's materials folder the material's paths are relative to"},
    .job = &bb__row_materials};

static const bb__option opt_basetexture = {
    .info = {.name = bb__row_basetexture.name,
             .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .mode = BB_MODE_SINGLE, .flags = RECORDED | BB_OPTION_FILES,
             .help = "the colour .vtf the material names as $basetexture"},
    .job = &bb__row_basetexture};

/* --scheduler: a Dask scheduler's address as `dask-scheduler` prints it,
 * PROTOCOL://HOST:PORT or HOST:PORT (tcp), checked here so that a usage
 * error is one line and exit 2 before any Python or Dask starts: the host a
 * name, an IPv4 address or [an IPv6 one], the port 1..65535. */
#define SCHEDULER_EXAMPLE                                                                \
  "tcp://HOST:PORT, e.g. tcp://10.0.0.1:8786 (dask-scheduler prints it)"

static int is_host_name(const char *host, size_t n) {
  if (n < 1 || n > 253)
    return 0;
  for (size_t i = 0; i < n; i++) {
    const char ch = host[i];
    const int word = isalnum((unsigned char)ch) || ch == '_';
    if (!word && ((ch != '.' && ch != '-') || i == 0 || i == n - 1))
      return 0;
  }
  return 1;
}

static bb_status check_scheduler(const char *text, bb_error *err) {
  char shown[80];
  bb_text_printable(text, shown, sizeof shown);
  const char *rest = strstr(text, "://");
  char scheme[16] = "tcp";
  size_t len = strlen(text);
  int blank = 1;
  for (size_t i = 0; i < len; i++)
    blank &= isspace((unsigned char)text[i]) != 0;
  if (blank)
    return bb__fail(err, BB_ERR_ARGUMENT, "--scheduler: an empty address: give %s",
                    SCHEDULER_EXAMPLE);
  for (size_t i = 0; i < len; i++)
    if ((unsigned char)text[i] <= 0x20 || (unsigned char)text[i] == 0x7f)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "--scheduler '%s': control characters or spaces in the address",
                      shown);
  if (rest) {
    const size_t n = (size_t)(rest - text);
    if (n >= sizeof scheme)
      return bb__fail(
          err, BB_ERR_ARGUMENT,
          "--scheduler '%s': unknown protocol (one of tcp, tls, ws, wss, ucx); "
          "give %s",
          shown, SCHEDULER_EXAMPLE);
    for (size_t i = 0; i < n; i++)
      scheme[i] = (char)tolower((unsigned char)text[i]);
    scheme[n] = '\0';
    rest += 3;
  } else {
    rest = text;
  }
  if (!strcmp(scheme, "inproc"))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--scheduler '%s': inproc:// addresses exist only inside one Python "
                    "process; give %s",
                    shown, SCHEDULER_EXAMPLE);
  static const char *const schemes[] = {"tcp", "tls", "ws", "wss", "ucx"};
  int known = 0;
  for (size_t i = 0; i < sizeof schemes / sizeof schemes[0]; i++)
    known |= !strcmp(scheme, schemes[i]);
  if (!known)
    return bb__fail(
        err, BB_ERR_ARGUMENT,
        "--scheduler '%s': unknown protocol '%s' (one of tcp, tls, ws, wss, ucx); "
        "give %s",
        shown, scheme, SCHEDULER_EXAMPLE);
  if (strpbrk(rest, "/?#@"))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--scheduler '%s': an address has no path, query or user: give %s",
                    shown, SCHEDULER_EXAMPLE);
  const char *port;
  if (rest[0] == '[') {
    const char *end = strchr(rest, ']');
    if (!end)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "--scheduler '%s': '[' without ']' around the IPv6 address", shown);
    char host[64];
    unsigned char any[sizeof(struct in6_addr)];
    const size_t n = (size_t)(end - rest - 1);
    if (n >= sizeof host ||
        (memcpy(host, rest + 1, n), host[n] = '\0', inet_pton(AF_INET6, host, any) != 1))
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "--scheduler '%s': '%.*s' is not an IPv6 address", shown,
                      (int)(n < 64 ? n : 64), rest + 1);
    if (end[1] != ':')
      return bb__fail(err, BB_ERR_ARGUMENT, "--scheduler '%s': no port: give %s", shown,
                      SCHEDULER_EXAMPLE);
    port = end + 2;
  } else {
    const char *colon = strrchr(rest, ':');
    if (!colon)
      return bb__fail(err, BB_ERR_ARGUMENT, "--scheduler '%s': no port: give %s", shown,
                      SCHEDULER_EXAMPLE);
    const size_t n = (size_t)(colon - rest);
    if (memchr(rest, ':', n))
      return bb__fail(
          err, BB_ERR_ARGUMENT,
          "--scheduler '%s': an IPv6 address goes in brackets: %s://[%.*s]:%s", shown,
          scheme, (int)(n < 64 ? n : 64), rest, colon + 1);
    if (!is_host_name(rest, n))
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "--scheduler '%s': '%.*s' is not a host name or address", shown,
                      (int)(n < 64 ? n : 64), rest);
    port = colon + 1;
  }
  long number = 0;
  int digits = port[0] != '\0';
  for (const char *d = port; *d && digits; d++) {
    digits = isdigit((unsigned char)*d) != 0;
    if (number <= 65535)
      number = number * 10 + (*d - '0');
  }
  if (!digits || number < 1 || number > 65535)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--scheduler '%s': the port '%.16s' is not a number from 1 to 65535",
                    shown, port);
  return BB_OK;
}

static bb_status set_scheduler(bb_command *c, const bb__option *o, const char *text,
                               double *values, int *count, bb_error *err) {
  *count = 0;
  bb_status st = check_scheduler(text, err);
  return st == BB_OK ? bb__set_generic(c, o, text, values, count, err) : st;
}

static const bb__option opt_scheduler = {
    .info =
        {.name = "scheduler",
         .value_name = "ADDRESS",
         .type = BB_OPTION_TEXT,
         .flags = BB_OPTION_CLIENT | BB_OPTION_FILES,
         .count = 1,
         .values = 1,
         .help =
             "bake on the Dask cluster of this scheduler (tcp://host:8786): a batch's "
             "inputs on its workers, a single map's trace split over them "
             "(docs/cluster.md)"},
    .field = BB__FIELD_STRING,
    .offset = AT(scheduler),
    .set = set_scheduler};

/* -------------------------------------------------------------- bake */

static const bb__option *const bake_options[] = {
    &bb__opt_scale, &bb__opt_rays, &bb__opt_slices, &bb__opt_filter_radius,
    &bb__opt_filter_threshold, &bb__opt_bias, &bb__opt_power, &bb__opt_basis,
    &bb__opt_normal_filter, &bb__opt_normal_y, &bb__opt_threads, &bb__opt_clamp,
    &bb__opt_channel, &bb__opt_depth, &bb__opt_mips, &bb__opt_bounce, &bb__opt_bounces,
    &bb__opt_bounce_albedo, &bb__opt_brightness, &opt_out_normal, &opt_out_weights, &opt_out_ssbump,
    &opt_out_ao, &opt_out_bent, &opt_out_filtered, &opt_slope, &opt_lit, &opt_prefix,
    &opt_out_dir, &bb__opt_maps, &bb__opt_name, &opt_keep_going, &opt_force, &opt_depfile,
    &bb__opt_json, &opt_quiet_bake, &bb__opt_texture_format, &bb__opt_vtf_version,
    &bb__opt_vtf_flags, &bb__opt_nomip, &bb__opt_fast_compression, &opt_vmt, &opt_materials,
    &opt_basetexture, &opt_scheduler, &bb__opt_help, NULL};

static void bake_init(bb_command_options *o) {
  (void)o; /* the library's defaults (bb__job_options_init) */
}

/* A single bake always bakes; a batch skips what is up to date unless
 * --force. */
static bb_status bake_job(bb_command *c, bb_job_options *o, bb_error *err) {
  (void)err;
  *o = c->options.job;
  o->force |= !o->out_dir;
  return BB_OK;
}

const bb__command bb__command_bake = {
    .info = {.name = "bake",
             .summary = "bake normal, ssbump, ao, bent normal, ... in one pass",
             .synopsis = "HEIGHT --scale S [OPTIONS] (-o PREFIX | --normal FILE | --ssbump FILE "
                         "| ... | --out-dir DIR)",
             .description =
                 "Bakes the requested maps from HEIGHT in one pass; tracing runs only when\n"
                 "ssbump, ao or bent is asked for. Tracing finds each texel's exact horizon\n"
                 "in each azimuth slice and integrates the slice above it exactly; what is\n"
                 "left is azimuth sampling. Cost and mean |error| against converged truth\n"
                 "(rock06, 1024 x 1024 at scale 128, 2 cores; error on its 256 x 256 "
                 "downsample):\n"
                 "  budget       slices   trace     ao      ssbump\n"
                 "  64 rays         8     ~0.4 s   0.0015   0.0030\n"
                 "  256 rays       16     ~0.7 s   0.0004   0.0010   (the default)\n"
                 "  1024 rays      32     ~2.6 s   0.0001   0.0004\n"
                 "With --clamp the trace takes 2.3 to 3.4 times as long. See\n"
                 "docs/performance.md and docs/accuracy.md.\n"
                 "\n"
                 "A map option given again writes the bake's map to a further file, in\n"
                 "its own format: --ssbump s.png --ssbump s.vtf traces once.\n"
                 "\n"
                 "Batches: bumpbake bake HEIGHT|DIR... --scale S --out-dir DIR [--maps LIST]\n"
                 "bakes every HEIGHT (a directory: the images in it, sorted, not below it)\n"
                 "in one process into DIR/--name, and skips an input whose outputs are\n"
                 "up to date: their provenance names the same input bytes, parameters\n"
                 "and bumpbake version (--force bakes anyway).",
             .inputs = "HEIGHT", .min_inputs = 1, .max_inputs = -1, .usage_exit = 2,
             .option_count = (int)(sizeof bake_options / sizeof bake_options[0]) - 1},
    .options = bake_options, .init = bake_init, .job = bake_job};

/* -------------------------------------------------------------- normal */

static const bb__option opt_normal_output = {
    .info = {.name = "output", .short_name = 'o', .value_name = "OUT", .type = BB_OPTION_PATH,
             .count = 1, .values = 1, .flags = RECORDED | BB_OPTION_REQUIRED | BB_OPTION_FILES,
             .help = "normal map to write (.png .tga .tif .exr); required"},
    .field = BB__FIELD_STRING, .offset = AT(job.paths[BB_MAP_NORMAL]), .repeats = 1};

static const bb__option opt_quiet_normal = {
    .info = {.name = "quiet", .short_name = 'q', .type = BB_OPTION_FLAG,
             .flags = BB_OPTION_CLIENT, .default_text = "off", .help = "no \"wrote ...\" line"},
    .field = BB__FIELD_INT, .offset = AT(quiet)};

static const bb__option *const normal_options[] = {
    &opt_normal_output, &bb__opt_scale, &bb__opt_filter_radius, &bb__opt_filter_threshold,
    &bb__opt_normal_filter, &bb__opt_normal_y, &bb__opt_threads, &bb__opt_clamp,
    &bb__opt_channel, &bb__opt_depth, &bb__opt_mips, &bb__opt_texture_format,
    &bb__opt_vtf_version, &bb__opt_vtf_flags, &bb__opt_nomip, &bb__opt_fast_compression,
    &bb__opt_json, &opt_quiet_normal, &bb__opt_help, NULL};

static void normal_init(bb_command_options *o) {
  o->job.bake.outputs = BB_MAP_BIT(BB_MAP_NORMAL); /* no rays, nothing else */
}

static bb_status normal_job(bb_command *c, bb_job_options *o, bb_error *err) {
  (void)err;
  *o = c->options.job;
  o->force = 1;
  return BB_OK;
}

const bb__command bb__command_normal = {
    .info = {.name = "normal",
             .summary = "bake a tangent-space normal map from a height map",
             .synopsis = "HEIGHT -o OUT --scale S [OPTIONS]",
             .description = "Smooths HEIGHT and writes its tangent-space normals (0.5 + 0.5 N "
                            "in integer\nfiles, N in EXR).",
             .inputs = "HEIGHT", .min_inputs = 1, .max_inputs = 1, .usage_exit = 2,
             .option_count = (int)(sizeof normal_options / sizeof normal_options[0]) - 1},
    .options = normal_options, .init = normal_init, .job = normal_job};

/* ------------------------------------------------------- height2ssbump */

static const bb__option opt_valve_normal = {
    .info = {.name = "normal-map", .short_name = 'n', .type = BB_OPTION_FLAG,
             .flags = RECORDED | BB_OPTION_FILES, .default_text = "off",
             .help = "write FILE-bump.tga: RGB = normal map (0.5 + 0.5 N)"},
    .field = BB__FIELD_INT, .offset = AT(job.valve.normal_map)};
static const bb__option opt_valve_ao = {
    .info = {.name = "ao-alpha", .short_name = 'A', .type = BB_OPTION_FLAG, .flags = RECORDED | BB_OPTION_FILES,
             .default_text = "off", .help = "put ambient occlusion in alpha, not the height"},
    .field = BB__FIELD_INT, .offset = AT(job.valve.ao_in_alpha)};
static const bb__option opt_valve_dump = {
    .info = {.name = "dump-filtered", .short_name = 'D', .type = BB_OPTION_FLAG,
             .flags = RECORDED | BB_OPTION_FILES, .default_text = "off",
             .help = "also write the filtered height as ./filtered.tga"},
    .sets = {BB__FIELD_STRING, AT(job.paths[BB_MAP_FILTERED]), 0, "filtered.tga"}};
static const bb__option opt_valve_detail = {
    .info = {.name = "detail", .short_name = 'd', .type = BB_OPTION_FLAG, .flags = RECORDED | BB_OPTION_FILES,
             .default_text = "off",
             .help = "detail variant: RGB times (R+G+B)/sqrt(3) of the filtered input colour"},
    .field = BB__FIELD_INT, .offset = AT(job.valve_detail)};
static const bb__option opt_valve_quiet = {
    .info = {.name = "quiet", .short_name = 'q', .type = BB_OPTION_FLAG,
             .flags = BB_OPTION_CLIENT, .default_text = "off",
             .help = "no list of files written"},
    .field = BB__FIELD_INT, .offset = AT(quiet)};
static const bb__option opt_valve_output = {
    .info = {.name = "output", .short_name = 'o', .value_name = "FILE", .type = BB_OPTION_PATH,
             .count = 1, .values = 1, .flags = RECORDED | BB_OPTION_FILES,
             .default_text = "FILE-ssbump.tga (-n: FILE-bump.tga)",
             .help = "write FILE instead, in its extension's format (.vtf: a Source texture)"},
    .field = BB__FIELD_STRING, .offset = AT(job.valve_path)};

static const bb__option *const h2s_options[] = {
    &opt_rays_valve, &opt_valve_normal, &opt_valve_ao, &opt_filter_radius_valve,
    &opt_valve_dump, &opt_valve_detail, &opt_valve_quiet, &opt_valve_output,
    &bb__opt_texture_format, &bb__opt_vtf_version, &bb__opt_vtf_flags, &bb__opt_nomip,
    &bb__opt_fast_compression, &opt_vmt, &opt_materials, &opt_basetexture, &bb__opt_help,
    NULL};

/* Valve's defaults: 250 rays (-r), filter radius 10 (-f), Valve's normal
 * filter, Valve's channel rule (alpha when there is one, else the grey or
 * the mean of R, G, B, which a note says); 8-bit files. */
static void h2s_init(bb_command_options *o) {
  o->job.bake.rays = 250;
  o->job.bake.smooth.radius_texels = 10;
  o->job.bake.normal_filter = BB_NORMAL_VALVE;
  o->job.channel = BB_CHANNEL_VALVE;
}

/* FILE BUMPSCALE: the second is the height scale. */
static bb_status h2s_input(bb_command *c, int i, const char *text, bb_error *err) {
  if (i != 1)
    return BB_OK; /* an input */
  char *end = NULL;
  const double scale = strtod(text, &end);
  if (end == text || *end != '\0' || !isfinite(scale))
    return bb__fail(err, BB_ERR_ARGUMENT, "BUMPSCALE needs a number (got '%.64s')", text);
  bb_status st = bb__range_check(&bb__range_height_scale, scale, "BUMPSCALE", err);
  if (st == BB_OK)
    c->options.job.bake.height_scale = (float)scale;
  return st;
}

/* The file Valve's tool writes, next to FILE, unless -o names another. */
static bb_status h2s_job(bb_command *c, bb_job_options *o, bb_error *err) {
  *o = c->options.job;
  o->force = 1;
  if (!o->valve_path) {
    char *path = bb__path_with_suffix(c->inputs[0], o->valve.normal_map ? "-bump.tga"
                                                                       : "-ssbump.tga");
    if (!path || !(o->valve_path = bb__command_keep(c, path))) {
      free(path);
      return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", c->inputs[0]);
    }
    free(path);
  }
  return BB_OK;
}

const bb__command bb__command_height2ssbump = {
    .info = {.name = "height2ssbump",
             .summary = "drop-in for Valve's height2ssbump",
             .synopsis = "[-r N] [-n] [-A] [-f R] [-D] [-d] FILE BUMPSCALE",
             .description =
                 "Valve-compatible: bakes FILE-ssbump.tga (RGB = ssbump, A = filtered height)\n"
                 "next to FILE. The height is FILE's alpha channel, or the mean of R, G, B when\n"
                 "it has none. BUMPSCALE (> 0) is the height scale in texels. -o names another\n"
                 "file; with -o NAME-ssbump.vtf --vmt NAME.vmt it goes straight into a Source\n"
                 "game's materials (docs/textures.md).",
             .inputs = "FILE BUMPSCALE", .min_inputs = 2, .max_inputs = 2, .usage_exit = 2,
             .option_count = (int)(sizeof h2s_options / sizeof h2s_options[0]) - 1},
    .options = h2s_options, .init = h2s_init, .add_input = h2s_input, .job = h2s_job};

/* --------------------------------------- render's light, shared with serve */

static bb_status set_light_color(bb_command *c, const bb__option *o, const char *text,
                                 double *values, int *count, bb_error *err) {
  bb_status st = bb__parse_numbers(o, text, 3, 0, values, err);
  for (int k = 0; k < 3 && st == BB_OK; k++)
    c->options.render.light_color[k] = (float)values[k];
  *count = 3;
  return st;
}

static void print_light_color(const bb_command *c, const bb__option *o, bb__text *t) {
  (void)o;
  bb__print_floats(t, c->options.render.light_color, 3);
}

const bb__option bb__opt_light_color = {
    .info = {.name = "light-color", .value_name = "R,G,B", .type = BB_OPTION_NUMBERS,
             .count = 3, .values = 1, .flags = RECORDED, .help = "colour of the dynamic light"},
    .range = &bb__range_colour, .set = set_light_color, .print = print_light_color};

const bb__option bb__opt_albedo = {
    .info = {.name = "albedo", .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .flags = RECORDED, .default_text = "white",
             .help = "colour map multiplying the diffuse light (same size as the maps)"},
    .field = BB__FIELD_STRING, .offset = AT(albedo)};

/* --------------------------------------------------------------- serve */

/* Where serve listens: serve's own options, in no field of the options
 * (BB__FIELD_KEPT): serve reads them with bb_command_value. */
static const bb__range range_port = {"port", 0, 65535, 0, 1};

/* --address: an IPv4 or IPv6 address (not a name to look up). */
static bb_status set_address(bb_command *c, const bb__option *o, const char *text,
                             double *values, int *count, bb_error *err) {
  (void)c, (void)values;
  *count = 0;
  unsigned char any[sizeof(struct in6_addr)];
  if (inet_pton(AF_INET, text, any) != 1 && inet_pton(AF_INET6, text, any) != 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "--%s: '%.64s' is not an IPv4 or IPv6 address",
                    o->info.name, text);
  return BB_OK; /* bb_command_set keeps the text */
}

static const bb__option opt_port = {
    .info = {.name = "port", .value_name = "N", .type = BB_OPTION_INT, .count = 1, .values = 1,
             .default_text = "8077",
             .help = "the port to listen on, 0 = any free one (the URL printed says which)"},
    .field = BB__FIELD_KEPT, .range = &range_port};
static const bb__option opt_address = {
    .info = {.name = "address", .value_name = "A", .type = BB_OPTION_TEXT, .count = 1,
             .values = 1, .default_text = "127.0.0.1",
             .help = "listen on this IPv4 or IPv6 address instead: the URL then carries a "
                     "random token every request needs"},
    .field = BB__FIELD_KEPT, .set = set_address};
static const bb__option opt_serve_quiet = ROW_QUIET('q', "print only the URL, not each bake");

/* The maps serve's write names: -o PREFIX's, or each map's file given;
 * with neither, PREFIX is HEIGHT without its extension (the default
 * output names, filled in as the check fills every command's). */
static bb_status serve_check(bb_command *c, bb_error *err) {
  bb_job_options *o = &c->options.job;
  const int prefix = bb__option_find(c->def, opt_prefix.info.name);
  if (c->in_memory || c->input_count < 1 || c->given[prefix])
    return BB_OK;
  int named = 0;
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    named |= o->paths[k] != NULL;
  o->prefix = NULL;
  if (named)
    return BB_OK;
  char *stem = bb__path_with_suffix(c->inputs[0], "");
  o->prefix = stem ? bb__command_keep(c, stem) : NULL;
  free(stem);
  return o->prefix ? BB_OK : bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", c->inputs[0]);
}

static const bb__option *const serve_options[] = {
    &bb__opt_scale, &bb__opt_rays, &bb__opt_slices, &bb__opt_filter_radius,
    &bb__opt_filter_threshold, &bb__opt_bias, &bb__opt_power, &bb__opt_basis,
    &bb__opt_normal_filter, &bb__opt_normal_y, &bb__opt_threads, &bb__opt_clamp,
    &bb__opt_channel, &bb__opt_depth, &bb__opt_mips, &bb__opt_bounce, &bb__opt_bounces,
    &bb__opt_bounce_albedo, &bb__opt_brightness, &opt_out_normal, &opt_out_weights, &opt_out_ssbump,
    &opt_out_ao, &opt_out_bent, &opt_out_filtered, &opt_slope, &opt_lit, &opt_prefix,
    &bb__opt_texture_format, &bb__opt_vtf_version, &bb__opt_vtf_flags, &bb__opt_nomip,
    &bb__opt_fast_compression, &bb__opt_light_color, &bb__opt_albedo, &opt_port, &opt_address,
    &opt_serve_quiet, &bb__opt_help, NULL};

const bb__command bb__command_serve = {
    .info = {.name = "serve",
             .summary = "bake live: re-bake on save, see the maps lit in the browser",
             .synopsis = "HEIGHT --scale S [OPTIONS]",
             .description =
                 "Bakes HEIGHT, serves a page that shows its maps lit in the browser (the\n"
                 "ssbump under a light you drag, normal-mapped, ao, bent normal, basis\n"
                 "weights, relief; tiled to show seams; --albedo and --light-color as\n"
                 "render's) and re-bakes when HEIGHT, or a map the options read, is saved,\n"
                 "or when a control on the page changes.\n"
                 "Nothing is written until the page's \"write\" asks: then the maps are\n"
                 "written as the `bumpbake bake` line the page shows would write them\n"
                 "(PREFIX_normal.png, PREFIX_ssbump.png, PREFIX_ao.png by default, PREFIX\n"
                 "being HEIGHT without its extension). Listens on 127.0.0.1 unless told;\n"
                 "Ctrl-C stops. See docs/commands/serve.md.",
             .inputs = "HEIGHT", .min_inputs = 1, .max_inputs = 1, .usage_exit = 2,
             .option_count = (int)(sizeof serve_options / sizeof serve_options[0]) - 1},
    .options = serve_options, .check = serve_check,
    .maps_asked = BB_MAPS_BAKED /* its page shows every map */};
