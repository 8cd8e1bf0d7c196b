/* run_maps.c: the runs of the commands that turn maps into maps
 * (normal2ssbump, ssbump2normal, combine, program): read, convert, and
 * the result written by the job (job/output.c: depth, provenance, staged
 * write), its path checked against the inputs before (bb_command_check);
 * or, in memory, the same operators on a client's images (bb_command_map,
 * bb_command_program). */
#include "cmd/cmd_internal.h"
#include "job/job_internal.h"
#include "bake/bake_internal.h"
#include "core/internal.h"
#include "maps/maps_internal.h"
#include "maps/program_internal.h"
#include "trace/basis.h"

#include <stdlib.h>
#include <string.h>

static bb_status read_map(const char *path, bb_image *img, bb_image_info *info, bb_error *err) {
  bb_error e = {{0}};
  bb_status st = bb_image_read(path, img, info, &e);
  return st == BB_OK ? BB_OK : bb__fail_at(err, st, path, &e);
}

/* A map read as Half-Life 2's basis (bb__basis_map_check). */
static bb_status check_hl2(const char *path, const bb_image *img, const bb_image_info *info,
                           bb_error *err) {
  bb_error e = {{0}};
  bb_status st = bb__basis_map_check(img, info ? info->description : NULL, &e);
  return st == BB_OK ? BB_OK : bb__fail_at(err, st, path, &e);
}

/* The command's one output, as the job writes it (bb__job_write): the
 * depth asked, else like's where the format holds it; provenance of the
 * command line, the input (input: a file's path, or text: a program's
 * text) and the hash of its decoded pixels, the kind; no bake parameters
 * (the command holds every option). */
static bb_status write_map(const bb_command *c, const char *input, const char *text,
                           const bb_image *pixels, const bb_image_info *like, const char *kind,
                           const bb_image *img, bb_range range, bb_command_result *r,
                           bb_error *err) {
  const bb_command_options *o = &c->options;
  char *record = bb__command_record(c);
  if (!record)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", o->output);
  const bb__job_source source = {.command = record,
                                 .input = input,
                                 .input_text = text,
                                 .input_hash = pixels ? bb__image_hash(pixels) : 0};
  const bb__job_output out = {o->output, kind, range, o->job.depth, like, o->job.mips,
                              &o->job.texture};
  bb_status st = bb__job_write(&out, img, &source, err);
  free(record);
  return st == BB_OK ? bb__result_add(r, kind, o->output, err) : st;
}

/* -------------------------------------------------------- normal2ssbump */

/* Appends the input's alpha (channel 3 of RGBA) to the weights, as Valve's
 * tool rewrites only R, G and B. */
static bb_status with_alpha(const bb_image *input, const bb_image_info *info,
                            bb_image *weights, bb_error *err) {
  const int alpha =
      info->alpha_channel >= 3 ? info->alpha_channel : (input->channels >= 4 ? 3 : -1);
  if (alpha < 0)
    return BB_OK;
  bb_image rgba;
  bb_status st = bb_image_alloc(&rgba, weights->width, weights->height, 4, err);
  if (st != BB_OK)
    return st;
  const size_t n = (size_t)weights->width * (size_t)weights->height;
  for (size_t i = 0; i < n; i++) {
    memcpy(rgba.pixels + 4 * i, weights->pixels + 3 * i, 3 * sizeof(float));
    rgba.pixels[4 * i + 3] = input->pixels[i * (size_t)input->channels + (size_t)alpha];
  }
  bb_image_free(weights);
  *weights = rgba;
  return BB_OK;
}

bb_status bb__run_normal2ssbump(bb_command *c, const bb_command_hooks *hooks,
                                bb_command_result *r, bb_error *err) {
  (void)hooks;
  const bb_command_options *o = &c->options;
  const char *input = c->inputs[0];
  bb_image values = {0}, normals = {0}, weights = {0};
  bb_image_info info = {0};
  bb_status st = read_map(input, &values, &info, err);
  if (st == BB_OK) {
    bb_error e = {{0}};
    st = bb_normal_map_decode(&values, info.is_float, o->maps_normal_y_up, 1, &normals, &e);
    if (st == BB_OK)
      st = bb__derive_weights_all_cores(&normals, NULL, &weights, &e);
    if (st == BB_OK)
      st = with_alpha(&values, &info, &weights, &e);
    if (st != BB_OK)
      bb__fail_at(err, st, input, &e);
  }
  if (st == BB_OK)
    st = write_map(c, input, NULL, &values, &info, "weights", &weights, BB_RANGE_UNIT, r, err);
  bb_image_free(&weights);
  bb_image_free(&normals);
  bb_image_free(&values);
  bb_image_info_free(&info);
  return st;
}

/* -------------------------------------------------------- ssbump2normal */

/* The normal a basis map stands for, by --kind, +Y as --normal-y says. */
static bb_status ssbump_normal(const bb_command_options *o, const bb_image *ssbump,
                               bb_image *normals, bb_error *err) {
  bb_status st = bb__ssbump_to_normal(ssbump, o->ssbump_kind, normals, err);
  if (st == BB_OK && o->maps_normal_y_up)
    bb__image_flip_green(normals);
  return st;
}

bb_status bb__run_ssbump2normal(bb_command *c, const bb_command_hooks *hooks,
                                bb_command_result *r, bb_error *err) {
  (void)hooks;
  const bb_command_options *o = &c->options;
  const char *input = c->inputs[0];
  bb_image ssbump = {0}, normals = {0};
  bb_image_info info = {0};
  bb_status st = read_map(input, &ssbump, &info, err);
  if (st == BB_OK)
    st = check_hl2(input, &ssbump, &info, err);
  if (st == BB_OK) {
    bb_error e = {{0}};
    if ((st = ssbump_normal(o, &ssbump, &normals, &e)) != BB_OK)
      bb__fail_at(err, st, input, &e);
  }
  if (st == BB_OK)
    st = write_map(c, input, NULL, &ssbump, &info, "normal", &normals, BB_RANGE_SIGNED, r, err);
  bb_image_free(&normals);
  bb_image_free(&ssbump);
  bb_image_info_free(&info);
  return st;
}

/* -------------------------------------------------------------- combine */

/* A map as read, and the values the library combines (normals decoded). */
typedef struct map_input {
  bb_image file, values;
  bb_image_info info;
} map_input;

static void map_input_free(map_input *m) {
  bb_image_free(&m->file);
  bb_image_free(&m->values);
  bb_image_info_free(&m->info);
}

static bb_status load_map(const bb_command_options *a, const char *path, map_input *m,
                          bb_error *err) {
  bb_status st = read_map(path, &m->file, &m->info, err);
  /* --detail scales Half-Life 2's three channels; a blend is linear in
   * every channel, so it takes maps of any basis (of the same count). */
  if (st == BB_OK && a->detail && (a->map_kind == BB_MAP_SSBUMP || a->map_kind == BB_MAP_WEIGHTS))
    st = check_hl2(path, &m->file, &m->info, err);
  if (st != BB_OK || a->map_kind != BB_MAP_NORMAL)
    return st;
  /* Not renormalised: a texel the operators copy must keep its code. */
  bb_error e = {{0}};
  st = bb_normal_map_decode(&m->file, m->info.is_float, a->maps_normal_y_up, 0, &m->values, &e);
  return st == BB_OK ? BB_OK : bb__fail_at(err, st, path, &e);
}

static const bb_image *values_of(const map_input *m) {
  return m->values.pixels ? &m->values : &m->file;
}

static bb_status load_mask(const char *path, bb_image *mask, bb_error *err) {
  map_input m = {{0}, {0}, {0}};
  bb_status st = read_map(path, &m.file, &m.info, err);
  if (st == BB_OK) {
    bb_error e = {{0}};
    st = bb_height_from_image(&m.file, m.info.alpha_channel, BB_CHANNEL_AUTO, mask, &e);
    if (st != BB_OK)
      bb__fail_at(err, st, path, &e);
  }
  map_input_free(&m);
  return st;
}

/* combine's operator on the values of A and B (normals decoded, +Y down;
 * B is the brightness map with --brightness): mask the T field of --mask
 * (NULL: --mix), flat B's flat texel with --detail (NULL: the exact one).
 * A normal map comes out in --normal-y's convention. */
static bb_status combine_values(const bb_command_options *a, const bb_image *va,
                                const bb_image *vb, const bb_image *mask, const float *flat,
                                bb_image *out, bb_error *err) {
  bb_status st;
  if (a->brightness)
    st = bb__combine_brightness(va, vb, a->map_kind, out, err);
  else if (a->detail)
    st = bb__combine_detail(va, vb, a->map_kind, flat, out, err);
  else
    st = bb__combine_blend(va, vb, mask, (float)a->mix, a->map_kind, out, err);
  if (st == BB_OK && a->map_kind == BB_MAP_NORMAL && a->maps_normal_y_up)
    bb__image_flip_green(out); /* back to the inputs' convention */
  return st;
}

/* Runs the library; errors about two images name the first input. */
static bb_status combine_maps(const bb_command_options *a, const char *first,
                              const map_input *m, const bb_image *mask, bb_image *out,
                              bb_error *err) {
  bb_error e = {{0}};
  float flat[3]; /* B's own flat: as its file holds it */
  if (a->detail)
    bb__map_flat_texel(a->map_kind, m[1].info.bits_per_sample, m[1].info.is_float, flat);
  bb_status st = combine_values(a, values_of(&m[0]), values_of(&m[1]),
                                mask->pixels ? mask : NULL, flat, out, &e);
  return st == BB_OK ? BB_OK : bb__fail_at(err, st, first, &e);
}

bb_status bb__run_combine(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                          bb_error *err) {
  (void)hooks;
  const bb_command_options *a = &c->options;
  const char *in[2] = {c->inputs[0], a->brightness ? a->brightness : c->inputs[1]};
  map_input m[2] = {{{0}, {0}, {0}}, {{0}, {0}, {0}}};
  bb_image mask = {0}, out = {0};
  bb_status st = load_map(a, in[0], &m[0], err);
  if (st == BB_OK && a->brightness) /* a grey to multiply by, whatever the kind */
    st = read_map(in[1], &m[1].file, &m[1].info, err);
  else if (st == BB_OK)
    st = load_map(a, in[1], &m[1], err);
  if (st == BB_OK && a->mask)
    st = load_mask(a->mask, &mask, err);
  if (st == BB_OK)
    st = combine_maps(a, in[0], m, &mask, &out, err);
  if (st == BB_OK) {
    const int normal = a->map_kind == BB_MAP_NORMAL;
    st = write_map(c, in[0], NULL, &m[0].file, &m[0].info, bb__map_kind_name(a->map_kind), &out,
                   normal ? BB_RANGE_SIGNED : BB_RANGE_UNIT, r, err);
  }
  bb_image_free(&out);
  bb_image_free(&mask);
  map_input_free(&m[0]);
  map_input_free(&m[1]);
  return st;
}

/* ------------------------------------------------------------ in memory */

/* *use: in, or (up, and in has a green) a copy of it with its green
 * negated: OpenGL's +Y up read as the library's +Y down, as decoding a
 * file with --normal-y up reads it. */
static bb_status green_down(const bb_image *in, int up, bb_image *copy, const bb_image **use,
                            bb_error *err) {
  *use = in;
  if (!up || !in || !in->pixels || in->channels < 2)
    return BB_OK;
  bb_status st = bb_image_alloc(copy, in->width, in->height, in->channels, err);
  if (st != BB_OK)
    return st;
  memcpy(copy->pixels, in->pixels,
         (size_t)in->width * (size_t)in->height * (size_t)in->channels * sizeof(float));
  bb__image_flip_green(copy);
  *use = copy;
  return BB_OK;
}

/* The texel a flat detail holds as a file of depth d stores it (8 and 16
 * bits: a code; half: 11 significant bits; float: as float); NULL for
 * BB_DEPTH_DEFAULT, the exact flat. */
static const float *flat_of_depth(bb_map_kind kind, bb_depth d, float flat[3]) {
  if (d == BB_DEPTH_DEFAULT)
    return NULL;
  const int bits = d == BB_DEPTH_8 ? 8 : d == BB_DEPTH_FLOAT ? 32 : 16;
  bb__map_flat_texel(kind, bits, d == BB_DEPTH_HALF || d == BB_DEPTH_FLOAT, flat);
  return flat;
}

static bb_status map(bb_command *c, const bb_image *a, const bb_image *b, const bb_image *mask,
                     bb_depth b_depth, const bb_basis *basis, bb_image *out, bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_command_map: NULL argument");
  memset(out, 0, sizeof *out);
  if (!c || !c->checked || !c->in_memory)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: the command is not checked for images in memory",
                    c ? c->def->info.name : "bb_command_map");
  const bb_command_options *o = &c->options;
  const char *name = c->def->info.name;
  if (!a)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: no map given", name);
  const int up = o->maps_normal_y_up;
  bb_image copies[2] = {{0}, {0}};
  const bb_image *va = a, *vb = b;
  bb_status st;
  if (c->def->run == bb__run_normal2ssbump) {
    st = green_down(a, up, &copies[0], &va, err);
    if (st == BB_OK)
      st = bb__derive_weights_all_cores(va, basis, out, err);
  } else if (c->def->run == bb__run_ssbump2normal) {
    st = ssbump_normal(o, a, out, err);
  } else if (c->def->run == bb__run_combine) {
    const int normal = o->map_kind == BB_MAP_NORMAL;
    float flat[3];
    if (!b)
      st = bb__fail(err, BB_ERR_ARGUMENT, "combine: %s",
                    o->brightness ? "the brightness map is needed" : "B, the second map, is needed");
    else if (o->mask && !mask)
      st = bb__fail(err, BB_ERR_ARGUMENT, "combine: the mask is needed");
    else if (b_depth < BB_DEPTH_DEFAULT || b_depth > BB_DEPTH_FLOAT)
      st = bb__fail(err, BB_ERR_ARGUMENT, "combine: no depth %d", (int)b_depth);
    else
      st = green_down(a, normal && up, &copies[0], &va, err);
    if (st == BB_OK)
      st = green_down(b, normal && up, &copies[1], &vb, err);
    if (st == BB_OK) /* a mask only with --mask */
      st = combine_values(o, va, vb, o->mask ? mask : NULL,
                          flat_of_depth(o->map_kind, b_depth, flat), out, err);
  } else {
    st = bb__fail(err, BB_ERR_ARGUMENT, "%s makes no map of images in memory", name);
  }
  bb_image_free(&copies[0]);
  bb_image_free(&copies[1]);
  return st;
}

bb_status bb_command_map(bb_command *c, const bb_image *a, const bb_image *b,
                         const bb_image *mask, bb_depth b_depth, const bb_basis *basis,
                         bb_image *out, bb_error *err) {
  return bb__spelled(c, map(c, a, b, mask, b_depth, basis, out, err), err);
}

/* -------------------------------------------------------------- program */

/* The program's image: its text (the command's input) parsed and run
 * from --base. */
static bb_status program_image(const bb_command *c, bb_image *out, int *is_normal,
                               bb_error *err) {
  const bb_command_options *o = &c->options;
  bb__program *program = NULL;
  bb_status st = bb__program_parse(c->inputs[0], &program, err);
  if (st != BB_OK)
    return st;
  bb__program_options po;
  bb__program_options_init(&po);
  po.base_dir = o->base_dir;
  po.allow_outside_base = o->allow_outside_base;
  /* the message names the image file or the function at fault */
  st = bb__program_run(program, &po, out, is_normal, err);
  bb__program_free(program);
  return st;
}

bb_status bb__run_program(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                          bb_error *err) {
  (void)hooks;
  const char *text = c->inputs[0];
  bb_image out = {0};
  int is_normal = 0;
  bb_status st = program_image(c, &out, &is_normal, err);
  if (st == BB_OK)
    st = write_map(c, NULL, text, NULL, NULL, is_normal ? "normal" : "colour", &out,
                   is_normal ? BB_RANGE_SIGNED : BB_RANGE_UNIT, r, err);
  bb_image_free(&out);
  return st;
}

bb_status bb_command_program(bb_command *c, bb_image *out, int *is_normal_map, bb_error *err) {
  if (!out || !is_normal_map)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_command_program: NULL argument");
  if (!c || strcmp(c->def->info.name, "program") != 0 || !c->checked || c->input_count < 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_command_program: not a checked program command");
  return bb__spelled(c, program_image(c, out, is_normal_map, err), err);
}
