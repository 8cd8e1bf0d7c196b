/* options_maps.c: the commands that turn maps into maps (normal2ssbump,
 * ssbump2normal, combine, program), their options described once and their
 * rules. */
#include "cmd/cmd_internal.h"
#include "job/job_internal.h"
#include "maps/maps_internal.h"
#include "maps/program_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define AT(member) offsetof(bb_command_options, member)
#define RECORDED BB_OPTION_RECORDED

#define ROW_OUTPUT(flags_, default_, help_)                                                \
  {.info = {.name = "output", .short_name = 'o', .value_name = "OUT",                     \
            .type = BB_OPTION_PATH, .count = 1, .values = 1,                               \
            .flags = RECORDED | BB_OPTION_FILES | (flags_),                                \
            .default_text = (default_), .help = (help_)},                                  \
   .field = BB__FIELD_STRING, .offset = AT(output)}

#define ROW_NORMAL_Y(help_)                                                                \
  {.info = {.name = "normal-y", .type = BB_OPTION_WORD, .count = 1, .values = 1,          \
            .flags = RECORDED, .default_text = "down", .help = (help_)},                   \
   .field = BB__FIELD_INT, .offset = AT(maps_normal_y_up), .names = bb__name_normal_y,     \
   .parse = bb__parse_normal_y}

#define TEXTURE_ROWS                                                                       \
  &bb__opt_texture_format, &bb__opt_vtf_version, &bb__opt_vtf_flags, &bb__opt_nomip,       \
      &bb__opt_fast_compression

/* The one output of a map command against the files it reads, with
 * --depth, --mips and the texture settings (bb__job_output_check). */
static bb_status check_output(const bb_command *c, const char *const *reads, int read_count,
                              bb_error *err) {
  const bb_command_options *o = &c->options;
  /* "output": what it holds is known when it is made (a program's) */
  const bb__job_output out = {o->output, "output", BB_RANGE_UNIT, o->job.depth, NULL,
                              o->job.mips, &o->job.texture};
  return bb__job_output_check(&out, 0, reads, read_count, err);
}

/* ------------------------------------------------------- normal2ssbump */

static const bb__option opt_n2s_output =
    ROW_OUTPUT(0, "NAME_ssbump.tga next to NORMAL, as Valve's tool",
               "weights to write (.png .tga .tif .exr)");
static const bb__option opt_n2s_normal_y =
    ROW_NORMAL_Y("green axis of NORMAL: down = Source/DirectX, up = OpenGL");

static const bb__option *const n2s_options[] = {
    &opt_n2s_output, &opt_n2s_normal_y, &bb__opt_depth_like_input, &bb__opt_mips, TEXTURE_ROWS,
    &bb__opt_quiet, &bb__opt_help, NULL};

static bb_status n2s_check(bb_command *c, bb_error *err) {
  if (c->in_memory)
    return BB_OK;
  if (!c->options.output) {
    char *name = bb__job_valve_weights_name(c->inputs[0]);
    c->options.output = name ? bb__command_keep(c, name) : NULL;
    free(name);
    if (!c->options.output)
      return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", c->inputs[0]);
  }
  return check_output(c, (const char *const *)c->inputs, 1, err);
}

const bb__command bb__command_normal2ssbump = {
    .info = {.name = "normal2ssbump",
             .summary = "Valve's tool: a normal map to basis weights",
             .synopsis = "NORMAL [-o OUT] [OPTIONS]",
             .description =
                 "Valve's normal2ssbump: the basis weights sat(N.B_c)^2 / sum_k sat(N.B_k)^2 "
                 "of a\nnormal map (no self-shadowing; bake --ssbump traces that). NORMAL's "
                 "codes\ndecode as N = 2 code / max - 1 (127.5 of 255 is 0), float files as N; "
                 "an\nalpha channel is copied. Without -o, writes NAME_ssbump.tga next to "
                 "NORMAL,\nNAME being NORMAL's file name up to its first \"_normal\" (any "
                 "case), else up\nto its first '.' (Valve's rule: wall.v2.png gives "
                 "wall_ssbump.tga).",
             .inputs = "NORMAL", .min_inputs = 1, .max_inputs = 1, .usage_exit = 2,
             .option_count = (int)(sizeof n2s_options / sizeof n2s_options[0]) - 1},
    .options = n2s_options, .check = n2s_check, .run = bb__run_normal2ssbump};

/* ------------------------------------------------------- ssbump2normal */

static const bb__option opt_s2n_output =
    ROW_OUTPUT(BB_OPTION_REQUIRED, NULL, "normal map to write (.png .tga .tif .exr); required");
static const bb__option opt_s2n_kind = {
    .info = {.name = "kind", .type = BB_OPTION_WORD, .count = 1, .values = 1, .flags = RECORDED,
             .help = "what SSBUMP holds: an ssbump (bake --ssbump, height2ssbump) or weights "
                     "(normal2ssbump)"},
    .field = BB__FIELD_ENUM, .offset = AT(ssbump_kind), .names = bb__name_ssbump_kind,
    .parse = bb__parse_ssbump_kind};
static const bb__option opt_s2n_normal_y =
    ROW_NORMAL_Y("green axis of the output: down = Source/DirectX, up = OpenGL");

static const bb__option *const s2n_options[] = {
    &opt_s2n_output, &opt_s2n_kind, &opt_s2n_normal_y, &bb__opt_depth_like_input,
    &bb__opt_mips, TEXTURE_ROWS, &bb__opt_quiet, &bb__opt_help, NULL};

static bb_status s2n_check(bb_command *c, bb_error *err) {
  return c->options.output ? check_output(c, (const char *const *)c->inputs, 1, err) : BB_OK;
}

const bb__command bb__command_ssbump2normal = {
    .info = {.name = "ssbump2normal",
             .summary = "the normal an ssbump (or weights) stands for",
             .synopsis = "SSBUMP -o OUT [OPTIONS]",
             .description =
                 "The normal of an ssbump: N = normalize(sum_c s_c B_c) over R, G, B (the\n"
                 "paper's specular normal; alpha is ignored). With --kind weights, s_c is\n"
                 "sqrt(w_c), which undoes normal2ssbump's square. Either gives back the\n"
                 "normal of an unoccluded texel wherever every N.B_c >= 0.",
             .inputs = "SSBUMP", .min_inputs = 1, .max_inputs = 1, .usage_exit = 2,
             .option_count = (int)(sizeof s2n_options / sizeof s2n_options[0]) - 1},
    .options = s2n_options, .check = s2n_check, .run = bb__run_ssbump2normal};

/* ------------------------------------------------------------- combine */

static const bb__option opt_combine_output =
    ROW_OUTPUT(BB_OPTION_REQUIRED, NULL, "combined map to write (.png .tga .tif .exr); required");
static const bb__option opt_mix = {
    .info = {.name = "mix", .value_name = "T", .type = BB_OPTION_NUMBER, .count = 1,
             .values = 1, .flags = RECORDED, .help = "blend (1 - T) A + T B"},
    .field = BB__FIELD_DOUBLE, .offset = AT(mix), .range = &bb__range_mix};
static const bb__option opt_mask = {
    .info = {.name = "mask", .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .flags = RECORDED,
             .help = "blend with T per texel from FILE (grey, or mean of R, G, B; clamped to "
                     "0..1)"},
    .field = BB__FIELD_STRING, .offset = AT(mask)};
static const bb__option opt_detail = {
    .info = {.name = "detail", .type = BB_OPTION_FLAG, .flags = RECORDED,
             .help = "overlay B on A as detail (ssbump/weights/ao: A * B / flat; normal: DOOM "
                     "3's addnormals)"},
    .field = BB__FIELD_INT, .offset = AT(detail)};
static const bb__option opt_brightness = {
    .info = {.name = "brightness", .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .flags = RECORDED,
             .help = "multiply A by FILE's grey (RGB: luma), the paper's brightness stored in "
                     "the ssbump; a texel over 1 is scaled down whole (no B)"},
    .field = BB__FIELD_STRING, .offset = AT(brightness)};
static const bb__option opt_combine_kind = {
    .info = {.name = "kind", .type = BB_OPTION_WORD, .count = 1, .values = 1, .flags = RECORDED,
             .help = "what A and B hold"},
    .field = BB__FIELD_ENUM, .offset = AT(map_kind), .names = bb__name_map_kind,
    .parse = bb__parse_map_kind};
static const bb__option opt_combine_normal_y =
    ROW_NORMAL_Y("green axis of normal maps in and out (up = OpenGL)");

static const bb__option *const combine_options[] = {
    &opt_combine_output, &opt_mix, &opt_mask, &opt_detail, &opt_brightness, &opt_combine_kind,
    &opt_combine_normal_y, &bb__opt_depth_like_input, &bb__opt_mips, TEXTURE_ROWS,
    &bb__opt_quiet, &bb__opt_help, NULL};

/* Exactly one way to combine; A and B, or A alone with --brightness; the
 * output must not replace A, B (or the brightness map) or the mask. */
static bb_status combine_check(bb_command *c, bb_error *err) {
  const bb_command_options *o = &c->options;
  const int want = o->brightness ? 1 : 2;
  if (c->in_memory)
    return bb__given(c, "mix") + (o->mask != NULL) + o->detail + (o->brightness != NULL) == 1
               ? BB_OK
               : bb__fail(err, BB_ERR_ARGUMENT,
                          "give exactly one of mix, mask, detail and brightness");
  if (c->input_count < want)
    return bb__fail(err, BB_ERR_ARGUMENT, "missing %s (usage: bumpbake combine %s)",
                    want == 1 ? "A" : "A B", bb__command_combine.info.synopsis);
  if (c->input_count > want)
    return bb__fail(err, BB_ERR_ARGUMENT, "unexpected argument '%s' (expected only %s)",
                    c->inputs[want], want == 1 ? "A" : "A B");
  const int modes = bb__given(c, "mix") + (o->mask != NULL) + o->detail + (o->brightness != NULL);
  if (modes != 1)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "give exactly one of --mix T, --mask FILE, --detail and --brightness FILE");
  if (!o->output)
    return BB_OK;
  const char *reads[3] = {c->inputs[0], o->brightness ? o->brightness : c->inputs[1], o->mask};
  return check_output(c, reads, o->mask ? 3 : 2, err);
}

const bb__command bb__command_combine = {
    .info = {.name = "combine",
             .summary = "blend two maps, or overlay a detail map",
             .synopsis = "A B -o OUT (--mix T | --mask FILE | --detail) [OPTIONS] | A "
                         "--brightness FILE -o OUT",
             .description =
                 "Combines two maps of the same size. --mix and --mask blend them,\n"
                 "(1 - T) A + T B, linear for ssbump, weights and ao (they are linear in "
                 "light),\nrenormalised for normal maps. --detail overlays B on A: A * B / flat "
                 "for\nssbump, weights and ao (flat = B's flat, unoccluded value as its file "
                 "holds\nit: 147 in an 8-bit ssbump), DOOM 3's addnormals for normal maps. A "
                 "flat B,\nT = 0 or a black mask leaves A unchanged bit for bit. Channels past "
                 "the\nkind's (an alpha) blend like the rest, or with --detail are A's.\n"
                 "--brightness multiplies one map by a grey brightness map (ssbump, weights: "
                 "a\ntexel whose largest channel would pass 1 is scaled so it is 1, its ratios "
                 "kept;\nao: clipped at 1).",
             .inputs = "A B", .min_inputs = 0, .max_inputs = -1, .usage_exit = 2,
             .option_count = (int)(sizeof combine_options / sizeof combine_options[0]) - 1},
    .options = combine_options, .check = combine_check, .run = bb__run_combine};

/* ------------------------------------------------------------- program */

static const bb__option opt_program_output =
    ROW_OUTPUT(BB_OPTION_REQUIRED, NULL,
               "image to write (.png .tga .tif .exr); a normal map as bumpbake writes them; "
               "required");
static const bb__option opt_base = {
    .info = {.name = "base", .value_name = "DIR", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .flags = RECORDED, .default_text = "the current directory",
             .help = "directory image names are relative to (a game's base/, say)"},
    .field = BB__FIELD_STRING, .offset = AT(base_dir)};
static const bb__option opt_allow_outside = {
    .info = {.name = "allow-outside-base", .type = BB_OPTION_FLAG, .flags = RECORDED,
             .default_text = "off",
             .help = "read images outside --base too (absolute paths, .., links out)"},
    .field = BB__FIELD_INT, .offset = AT(allow_outside_base)};

static const bb__option *const program_options[] = {
    &opt_program_output, &opt_base, &opt_allow_outside, &bb__opt_depth_of_format, &bb__opt_mips,
    TEXTURE_ROWS, &bb__opt_quiet, &bb__opt_help, NULL};

/* The program parses (a syntax error is a usage error), and the output
 * must not replace any image it reads: every one of them, however many. */
static bb_status program_check(bb_command *c, bb_error *err) {
  bb__program *program = NULL;
  bb_status st = bb__program_parse(c->inputs[0], &program, err);
  if (st != BB_OK) {
    bb__program_free(program);
    return BB_ERR_ARGUMENT;
  }
  if (!c->options.output) {
    bb__program_free(program);
    return BB_OK;
  }
  const size_t count = bb__program_images(program, NULL, 0);
  const char **names = malloc((count ? count : 1) * sizeof *names);
  char (*paths)[4096] = malloc((count ? count : 1) * sizeof *paths);
  const char **reads = malloc((count ? count : 1) * sizeof *reads);
  if (!names || !paths || !reads)
    st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
  int n = 0;
  if (st == BB_OK) {
    bb__program_images(program, names, count);
    for (size_t i = 0; i < count; i++) {
      /* a name too long to resolve is refused when the program runs, before
       * anything is written; a cut path is no input to compare with */
      const int len = bb__program_image_path(c->options.base_dir, names[i], paths[n],
                                            sizeof paths[n]);
      if (len >= 0 && (size_t)len < sizeof paths[n])
        reads[n] = paths[n], n++;
    }
    st = check_output(c, reads, n, err);
  }
  free(names);
  free(paths);
  free(reads);
  bb__program_free(program);
  return st;
}

const bb__command bb__command_program = {
    .info = {.name = "program",
             .summary = "evaluate a DOOM 3 image program (heightmap, addnormals...)",
             .synopsis = "EXPR -o OUT [OPTIONS]",
             .description =
                 "Evaluates a DOOM 3 image program, e.g. 'addnormals(a_local.tga, "
                 "heightmap(a_h.tga, 4))',\nwith id Tech 4's formulas "
                 "(docs/commands/program.md): heightmap(img, scale),\naddnormals(a, b), "
                 "smoothnormals(a), add(a, b), scale(a, r, g, b, a),\ninvertAlpha(a), "
                 "invertColor(a), makeIntensity(a), makeAlpha(a), _flat.\nA program that makes "
                 "a normal map is written as bumpbake writes normals\n(0.5 + 0.5 N; N in EXR), "
                 "any other as RGBA.",
             .inputs = "EXPR", .min_inputs = 1, .max_inputs = 1, .usage_exit = 2,
             .option_count = (int)(sizeof program_options / sizeof program_options[0]) - 1},
    .options = program_options, .check = program_check, .run = bb__run_program};
