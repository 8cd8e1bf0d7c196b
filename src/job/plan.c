/* plan.c: a bake job decided before any bake: its options checked, its
 * inputs gathered (directories expanded), each input's output paths named
 * (one by one, or from out_dir and a template) and checked against each
 * other, against every input and against the depfile, so a clash or a bad
 * name costs no baking time. */
#include "bake/bake_internal.h"
#include "core/internal.h"
#include "files/safe_file.h"
#include "image/formats.h"
#include "job/job_internal.h"
#include "job/bake_rows.h"
#include "render/render_internal.h"
#include "files/provenance.h"
#include "image/height_channel.h"
#include "image/oiio.h"
#include "texture/texture.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *kind_name(int kind) {
  return bb_map_kind_get((bb_map_kind)kind)->name;
}

static char *copy(const char *s) {
  return s ? strdup(s) : NULL;
}

void bb__job_options_init(bb_job_options *o) {
  memset(o, 0, sizeof *o);
  bb__bake_options_init(&o->bake);
  o->channel = BB_CHANNEL_AUTO;
  o->depth = BB_DEPTH_DEFAULT;
  bb_texture_options_init(&o->texture);
}

double bb__bounce_rho(double asked, int albedo_map) {
  return asked == 0.0 && albedo_map ? 1.0 : asked;
}

/* ----------------------------------------------------------------- inputs */

/* 1 when a and b are one existing file (an input named twice, an output
 * over an input). */
static int same_existing_file(const bb__file_identity *a, const bb__file_identity *b) {
  return a->exists && b->exists && bb__same_file_identity(a, b);
}

/* The inputs gathered so far, with the identity of each, so a file named
 * twice is kept once. */
typedef struct input_list {
  bb_job *job;
  int capacity;
  bb__file_identity *ids;
} input_list;

static bb_status add_input(input_list *l, const char *path, bb_error *err) {
  const bb__file_identity id = bb__file_identify(path);
  for (int i = 0; i < l->job->count; i++)
    if (same_existing_file(&l->ids[i], &id))
      return BB_OK;
  if (l->job->count == l->capacity) {
    int cap = l->capacity ? 2 * l->capacity : 16;
    bb__job_item *items = realloc(l->job->items, (size_t)cap * sizeof *items);
    if (items)
      l->job->items = items;
    bb__file_identity *ids = realloc(l->ids, (size_t)cap * sizeof *ids);
    if (ids)
      l->ids = ids;
    if (!items || !ids)
      return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
    l->capacity = cap;
  }
  bb__job_item *item = &l->job->items[l->job->count];
  memset(item, 0, sizeof *item);
  if (!(item->input = strdup(path)))
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  l->ids[l->job->count++] = id;
  return BB_OK;
}

/* 1 when the file's provenance says bumpbake wrote it as one of the maps:
 * reading it back as a height would bake a map of a map. */
static int is_baked_map(const char *path) {
  bb_image_info info;
  if (bb_image_read_info(path, NULL, NULL, NULL, &info, NULL) != BB_OK)
    return 0; /* not ours to judge: its bake will say what is wrong */
  char kind[64];
  int baked = 0;
  if (bb__provenance_classify(info.description) != BB_PROVENANCE_NONE &&
      bb__provenance_value(info.description, "output", kind, sizeof kind))
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
      baked |= strcmp(kind, kind_name(k)) == 0;
  bb_image_info_free(&info);
  return baked;
}

static int by_name(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

static char *join_path(const char *dir, const char *name) {
  size_t n = strlen(dir);
  while (n > 1 && dir[n - 1] == '/')
    n--;
  size_t len = n + 1 + strlen(name) + 1;
  char *path = malloc(len);
  if (path)
    snprintf(path, len, "%.*s/%s", (int)n, dir, name);
  return path;
}

static void free_names(char **names, int count) {
  for (int i = 0; i < count; i++)
    free(names[i]);
  free(names);
}

/* The names in dir that may be heights, sorted (malloc'd array of malloc'd
 * names in *names); the count. */
static bb_status read_directory(const char *dir, char ***names, int *count, bb_error *err) {
  *names = NULL;
  *count = 0;
  DIR *d = opendir(dir);
  if (!d)
    return bb__fail(err, BB_ERR_IO, "%s: %s", dir, strerror(errno));
  int capacity = 0, failed = 0;
  for (struct dirent *e; !failed && (e = readdir(d));) {
    if (e->d_name[0] == '.' || !bb__path_is_readable_format(e->d_name))
      continue;
    if (*count == capacity) {
      capacity = capacity ? 2 * capacity : 32;
      char **grown = realloc(*names, (size_t)capacity * sizeof *grown);
      failed = !grown;
      if (grown)
        *names = grown;
    }
    if (!failed && !((*names)[*count] = strdup(e->d_name)))
      failed = 1;
    *count += !failed;
  }
  closedir(d);
  if (failed) {
    free_names(*names, *count);
    *names = NULL;
    *count = 0;
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", dir);
  }
  if (*count)
    qsort(*names, (size_t)*count, sizeof **names, by_name);
  return BB_OK;
}

/* Adds the image files of dir that are not maps bumpbake baked; a
 * subdirectory is left out (not below). Anything else under an image's
 * name (a dangling link, a FIFO) is an input that fails at its bake with
 * its reason, as a corrupt image does, rather than left out unsaid. */
static bb_status add_directory(input_list *l, const char *dir, bb_error *err) {
  char **names;
  int count;
  bb_status st = read_directory(dir, &names, &count, err);
  for (int i = 0; i < count && st == BB_OK; i++) {
    char *path = join_path(dir, names[i]);
    struct stat s;
    if (!path)
      st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", dir);
    else if (stat(path, &s) != 0 || !S_ISREG(s.st_mode))
      st = stat(path, &s) == 0 && S_ISDIR(s.st_mode) ? BB_OK : add_input(l, path, err);
    else if (!is_baked_map(path))
      st = add_input(l, path, err);
    free(path);
  }
  free_names(names, count);
  return st;
}

static bb_status gather_inputs(bb_job *job, const char *const *inputs, int input_count,
                               bb_error *err) {
  input_list l = {job, 0, NULL};
  bb_status st = BB_OK;
  for (int i = 0; i < input_count && st == BB_OK; i++) {
    struct stat s;
    if (!inputs[i] || !*inputs[i])
      st = bb__fail(err, BB_ERR_ARGUMENT, "an input name is empty");
    else if (job->batch && stat(inputs[i], &s) == 0 && S_ISDIR(s.st_mode))
      st = add_directory(&l, inputs[i], err);
    else /* a missing file fails at its bake */
      st = add_input(&l, inputs[i], err);
  }
  free(l.ids);
  if (st == BB_OK && job->count == 0)
    st = bb__fail(err, BB_ERR_ARGUMENT, "nothing to bake: %s%s holds no image file", inputs[0],
                  input_count > 1 ? " (and the others)" : "");
  return st;
}

/* ------------------------------------------------------------------ names */

/* The file name of input (no directory) split into stem and extension
 * (after the last dot; "" when none). */
static void split_name(const char *input, char *stem, size_t stem_cap, char *ext,
                       size_t ext_cap) {
  const char *base = bb__file_name(input), *dot = bb__file_extension(input);
  size_t n = dot ? (size_t)(dot - base) : strlen(base);
  snprintf(stem, stem_cap, "%.*s", (int)n, base);
  snprintf(ext, ext_cap, "%s", dot ? dot + 1 : "");
}

/* BB_OK when name, made from a template, stays inside the output
 * directory: relative, and no part of it empty, "." or "..". */
static bb_status check_inside(const char *tmpl, const char *input, const char *name,
                              bb_error *err) {
  if (name[0] == '/')
    return bb__fail(err, BB_ERR_ARGUMENT, "name template %s: '%s' is an absolute path", tmpl,
                    name);
  for (const char *part = name; *part;) {
    size_t n = strcspn(part, "/");
    if (n == 0 || (n == 1 && part[0] == '.') || (n == 2 && part[0] == '.' && part[1] == '.'))
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "name template %s: %s of %s would leave the output directory "
                      "(a part of the name is empty, '.' or '..')",
                      tmpl, name, input);
    part += n + (part[n] == '/');
  }
  return BB_OK;
}

bb_status bb__job_expand_name(const char *tmpl, const char *const fields[3], char *out,
                              size_t cap, bb_error *err) {
  static const char *const names[3] = {"stem", "kind", "ext"};
  size_t used = 0;
  for (const char *s = tmpl; *s;) {
    const char *piece = s;
    size_t n = 1;
    if ((s[0] == '{' && s[1] == '{') || (s[0] == '}' && s[1] == '}')) {
      s += 2;
    } else if (*s == '{') {
      size_t len = strcspn(s + 1, "}");
      if (s[1 + len] != '}')
        return bb__fail(err, BB_ERR_ARGUMENT, "--name %s: '{' without '}'", tmpl);
      int f = 0;
      while (f < 3 && !(strlen(names[f]) == len && strncmp(names[f], s + 1, len) == 0))
        f++;
      if (f == 3)
        return bb__fail(err, BB_ERR_ARGUMENT,
                        "--name %s: unknown field {%.*s} (use {stem}, {kind}, {ext})", tmpl,
                        (int)len, s + 1);
      piece = fields[f];
      n = strlen(piece);
      s += len + 2;
    } else if (*s == '}') {
      return bb__fail(err, BB_ERR_ARGUMENT, "--name %s: '}' without '{' (write }} for a brace)",
                      tmpl);
    } else {
      s++;
    }
    if (used + n >= cap)
      return bb__fail(err, BB_ERR_ARGUMENT, "--name %s: the name is too long", tmpl);
    memcpy(out + used, piece, n);
    used += n;
  }
  out[used] = '\0';
  if (used == 0 || out[used - 1] == '/')
    return bb__fail(err, BB_ERR_ARGUMENT, "--name %s: gives no file name", tmpl);
  return BB_OK;
}

static bb_status name_outputs(bb_job *job, bb__job_item *item, bb_error *err) {
  char stem[1024], ext[64], name[4096];
  split_name(item->input, stem, sizeof stem, ext, sizeof ext);
  const char *tmpl = job->name_template ? job->name_template : BB_JOB_DEFAULT_NAME;
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    if (!(job->options.bake.outputs & BB_MAP_BIT(k)))
      continue;
    const char *fields[3] = {stem, kind_name(k), ext};
    bb_status st = bb__job_expand_name(tmpl, fields, name, sizeof name, err);
    if (st == BB_OK)
      st = check_inside(tmpl, item->input, name, err);
    if (st != BB_OK)
      return st;
    if (!(item->paths[k] = join_path(job->out_dir, name)))
      return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", item->input);
  }
  return BB_OK;
}

/* A literal "../" (or an absolute path) in the template leaves out_dir for
 * every input alike: refused once, before any input is named. */
static bb_status check_template(const char *tmpl, bb_error *err) {
  if (!tmpl)
    return BB_OK;
  if (tmpl[0] == '/')
    return bb__fail(err, BB_ERR_ARGUMENT, "--name %s: names are relative to the output directory",
                    tmpl);
  for (const char *part = tmpl; *part;) {
    size_t n = strcspn(part, "/");
    if ((n == 1 && part[0] == '.') || (n == 2 && part[0] == '.' && part[1] == '.'))
      return bb__fail(err, BB_ERR_ARGUMENT, "--name %s: '%.*s' would leave the output directory",
                      tmpl, (int)n, part);
    part += n + (part[n] == '/');
  }
  return BB_OK;
}

/* ---------------------------------------------------------------- clashes */

typedef struct planned_output {
  const char *path;
  int item, kind;
} planned_output;

static int by_path(const void *a, const void *b) {
  const planned_output *x = a, *y = b;
  int c = strcmp(x->path, y->path);
  return c ? c : (x->item > y->item) - (x->item < y->item);
}

/* Two outputs of a batch on one path, found by sorting the paths (all are
 * made the same way under one directory, so equal files have equal
 * spellings), and outputs that are one of the inputs. */
static bb_status check_batch_paths(const bb_job *job, bb_error *err) {
  planned_output *outs = malloc((size_t)job->count * BB_MAP_BAKED_COUNT * sizeof *outs);
  bb__file_identity *in = malloc((size_t)job->count * sizeof *in);
  bb_status st = BB_OK;
  if (!outs || !in)
    st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
  int n = 0;
  for (int i = 0; i < job->count && st == BB_OK; i++) {
    in[i] = bb__file_identify(job->items[i].input);
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
      if (job->items[i].paths[k])
        outs[n++] = (planned_output){job->items[i].paths[k], i, k};
  }
  for (int i = 0; i < n && st == BB_OK; i++) {
    const bb__file_identity out = bb__file_identify(outs[i].path);
    for (int j = 0; j < job->count && out.exists && st == BB_OK; j++)
      if (same_existing_file(&in[j], &out))
        st = bb__refuse_output_over_input(err, outs[i].path, job->items[j].input);
  }
  if (st == BB_OK && n > 1) {
    qsort(outs, (size_t)n, sizeof *outs, by_path);
    for (int i = 1; i < n && st == BB_OK; i++) {
      if (strcmp(outs[i - 1].path, outs[i].path) != 0)
        continue;
      const planned_output *a = &outs[i - 1], *o = &outs[i];
      if (a->item == o->item)
        st = bb__fail(err, BB_ERR_ARGUMENT, "%s: %s and %s would both be written to %s",
                      job->items[a->item].input, kind_name(a->kind), kind_name(o->kind),
                      o->path);
      else
        st = bb__fail(err, BB_ERR_ARGUMENT, "%s and %s would both be written to %s",
                      job->items[a->item].input, job->items[o->item].input, o->path);
    }
  }
  free(outs);
  free(in);
  return st;
}

/* ---------------------------------------------------------- output checks */

/* A map with a channel per basis direction needs room for them: PNG and TGA
 * hold 4, so "hl2+z" still fits RGBA. */
static bb_status check_channels(const bb_job *job, const char *path, int kind, bb_error *err) {
  const bb_basis *basis = &job->options.bake.basis;
  const int room = bb__path_max_channels(path);
  if (bb_map_kind_get((bb_map_kind)kind)->channels != 0 || basis->count <= room)
    return BB_OK;
  char ext[17];
  bb__extension_of(path, ext, sizeof ext);
  return bb__fail(err, BB_ERR_ARGUMENT,
                  "%s: --basis %s gives %s %d channels and %s files hold at most %d (write it "
                  "as .exr or .tif)",
                  path, job->basis_file ? job->basis_file : basis->name, kind_name(kind),
                  basis->count, ext, room);
}

/* The channels a map of kind has (one per basis direction for weights
 * and ssbump). */
static int kind_channels(const bb_job *job, int kind) {
  const int c = bb_map_kind_get((bb_map_kind)kind)->channels;
  return c ? c : job->options.bake.basis.count;
}

/* The input's size from its header, when an output is a .vtf or .dds
 * (whose sizes are checked before the bake); 0 x 0 when there is none or
 * the header cannot be read (the bake then says why). */
static void texture_input_size(const bb__job_item *item, int *width, int *height) {
  *width = *height = 0;
  int textures = 0;
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    textures |= item->paths[k] && bb__path_is_texture_format(item->paths[k]);
  if (textures && bb_image_read_info(item->input, width, height, NULL, NULL, NULL) != BB_OK)
    *width = *height = 0;
}

/* One input's outputs as a single bake checks them. */
static bb_status check_item_outputs(const bb_job *job, const bb__job_item *item,
                                    bb_error *err) {
  bb_output_spec specs[BB_JOB_MAX_OUTPUTS];
  int kinds[BB_JOB_MAX_OUTPUTS];
  int n = 0, width, height;
  texture_input_size(item, &width, &height);
  int map_kinds[BB_JOB_MAX_OUTPUTS];
  const char *map_paths[BB_JOB_MAX_OUTPUTS], *map_commands[BB_JOB_MAX_OUTPUTS];
  const int maps = bb__job_map_files(item, map_kinds, map_paths, map_commands);
  for (int f = 0; f < maps; f++) {
    const int k = map_kinds[f];
    kinds[n] = k;
    specs[n++] = (bb_output_spec){
        map_paths[f], kind_name(k),
        /* the basis message below is the clearer one
           for other formats */
        bb__path_is_texture_format(map_paths[f]) ? kind_channels(job, k) : 0,
        job->options.depth, job->options.mips, 0, width, height,
        bb_map_kind_get((bb_map_kind)k)->range, &job->options.texture};
  }
  if (job->valve_path) {
    if (!width && bb__path_is_texture_format(job->valve_path) &&
        bb_image_read_info(item->input, &width, &height, NULL, NULL, NULL) != BB_OK)
      width = height = 0;
    kinds[n] = -1;
    specs[n++] = (bb_output_spec){job->valve_path, bb__job_valve_kind(&job->options), 4,
                                  job->options.depth, 0, 0, width, height, BB_RANGE_UNIT,
                                  &job->options.texture};
  }
  if (job->slope_path) {
    /* The slope map is its bytes: 8-bit, no mips; its preview a picture. */
    if (!bb__path_supports_depth(job->slope_path, BB_DEPTH_8))
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s: the slope map is one byte per texel: use .png, .tga or .tif",
                      job->slope_path);
    kinds[n] = -1;
    specs[n++] = (bb_output_spec){job->slope_path, "slope", 1, BB_DEPTH_8, 0, 0, 0, 0,
                                  BB_RANGE_UNIT, NULL};
    if (item->slope_lit_path) {
      kinds[n] = -1;
      specs[n++] = (bb_output_spec){item->slope_lit_path, "slope_lit", 1, job->options.depth,
                                    0, 0, 0, 0, BB_RANGE_UNIT, NULL};
    }
  }
  if (job->vmt) {
    kinds[n] = -1;
    specs[n++] = (bb_output_spec){job->vmt, "material", 0, BB_DEPTH_DEFAULT, 0, 1, 0, 0,
                                  BB_RANGE_UNIT, NULL};
  }
  const char *reads[BB__JOB_MAX_READS];
  bb_status st =
      bb__outputs_check(specs, n, reads, bb__job_reads(job, item, reads), !job->read_only, err);
  for (int i = 0; i < maps && st == BB_OK; i++)
    st = check_channels(job, specs[i].path, kinds[i], err);
  return st;
}

/* ---------------------------------------------------------------- depfile */

/* The depfile against every input and output of the plan: not a file the
 * bake reads, not one it writes, every name one a depfile can hold, its
 * directory writable. */
static bb_status check_depfile(const bb_job *job, bb_error *err) {
  const char *path = job->depfile;
  for (int i = 0; i < job->count; i++) {
    const bb__job_item *item = &job->items[i];
    const char *prereq[BB__JOB_MAX_READS];
    const int n_prereq = bb__job_reads(job, item, prereq);
    const char *targets[BB_JOB_MAX_OUTPUTS];
    int t = 0;
    if (job->valve_path)
      targets[t++] = job->valve_path;
    int kinds[BB_JOB_MAX_OUTPUTS];
    const char *commands[BB_JOB_MAX_OUTPUTS];
    t += bb__job_map_files(item, kinds, targets + t, commands);
    if (job->slope_path)
      targets[t++] = job->slope_path;
    if (item->slope_lit_path)
      targets[t++] = item->slope_lit_path;
    if (job->vmt)
      targets[t++] = job->vmt;
    bb__dep_rule rule = {targets, t, prereq, n_prereq};
    bb_status st = bb__depfile_check_names(path, &rule, 1, err);
    if (st != BB_OK)
      return st;
    for (int p = 0; p < rule.prerequisite_count; p++)
      if (bb__same_file(prereq[p], path))
        return bb__refuse_output_over_input(err, path, prereq[p]);
    for (int k = 0; k < t; k++)
      if (bb__same_file(targets[k], path))
        return bb__fail(err, BB_ERR_ARGUMENT, "--depfile %s is also an output of the bake",
                        path);
  }
  bb__dep_rule none = {NULL, 0, NULL, 0};
  const char *self[1] = {path};
  none.targets = self;
  none.target_count = 1;
  bb_status st = bb__depfile_check_names(path, &none, 1, err);
  if (st == BB_OK && bb__safe_is_stream(path)) {
    /* /dev/stdout on a pipe or terminal, a FIFO, /dev/null: written
     * through (run.c), not replaced. */
    if (access(path, W_OK) != 0)
      st = bb__fail(err, BB_ERR_IO, "%s: cannot write the depfile: %s", path, strerror(errno));
    return st;
  }
  if (st == BB_OK)
    st = bb__check_output_directory(path, err);
  if (st == BB_OK) {
    char dir[PATH_MAX];
    bb__directory_part(path, dir, sizeof dir);
    if (access(dir, W_OK) != 0)
      st = bb__fail(err, BB_ERR_IO, "%s: cannot write the depfile: directory %s: %s", path,
                    dir, strerror(errno));
  }
  return st;
}

/* ------------------------------------------------------------------- plan */

unsigned bb__job_maps_asked(const bb_job_options *o) {
  if (o->out_dir)
    return o->maps ? o->maps : BB_JOB_DEFAULT_MAPS;
  unsigned mask = o->prefix ? BB_JOB_DEFAULT_MAPS : 0u;
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    if (o->paths[k])
      mask |= BB_MAP_BIT(k);
  if (o->slope_path)
    mask |= BB_MAP_BIT(BB_MAP_FILTERED);
  if (o->valve_path)
    mask |= BB_MAP_BIT(o->valve.normal_map ? BB_MAP_NORMAL : BB_MAP_SSBUMP) |
            BB_MAP_BIT(o->valve.ao_in_alpha ? BB_MAP_AO : BB_MAP_FILTERED);
  return mask;
}

const char *bb__job_valve_kind(const bb_job_options *o) {
  if (o->valve.normal_map)
    return o->valve.ao_in_alpha ? "normal+ao" : "normal+height";
  if (o->valve_detail)
    return o->valve.ao_in_alpha ? "detail-ssbump+ao" : "detail-ssbump+height";
  return o->valve.ao_in_alpha ? "ssbump+ao" : "ssbump+height";
}

/* The rules of a single bake's options, and of the options only a batch
 * uses (refused without out_dir), for every client: the commands' option
 * rows say which use an option belongs to (bb_option_info.mode), and a test
 * walks them against these checks. force is not a batch's only: a single
 * input may skip its bake when its outputs are current (the bake command
 * always bakes one, and refuses --force without --out-dir). */
static bb_status check_single(const bb_job_options *o, const char *const *inputs,
                              int input_count, bb_error *err) {
  if (input_count > 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "several HEIGHT files need --out-dir DIR");
  /* A directory is a batch's input: its maps need a folder, not names. */
  struct stat s;
  if (inputs[0] && stat(inputs[0], &s) == 0 && S_ISDIR(s.st_mode))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s is a directory: a batch of its heights needs --out-dir DIR", inputs[0]);
  const char *batch_only = o->name_template ? "--name"
                           : o->maps        ? "--maps"
                           : o->keep_going  ? "--keep-going"
                                            : NULL;
  if (batch_only)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s is for batches: give --out-dir DIR", batch_only);
  if (o->slope_lit && !o->slope_path)
    return bb__fail(err, BB_ERR_ARGUMENT, "--lit previews the slope map: give --slope FILE too");
  /* bb__light_direction takes any angle; above 90 degrees the light would
   * come from under the surface. */
  if (o->slope_lit && !isfinite(o->slope_lit_azimuth))
    return bb__fail(err, BB_ERR_ARGUMENT, "--lit azimuth must be finite (got %g)",
                    o->slope_lit_azimuth);
  bb_status st = o->slope_lit ? bb__range_check(&bb__range_light_elevation,
                                                o->slope_lit_elevation, "--lit elevation", err)
                              : BB_OK;
  if (st == BB_OK && o->valve_path && o->valve_detail && o->valve.normal_map)
    st = bb__fail(err, BB_ERR_ARGUMENT, "-d makes a detail ssbump; it cannot be used with -n");
  if (st == BB_OK && !bb__job_maps_asked(o))
    st = bb__fail(err, BB_ERR_ARGUMENT,
                  "nothing to write: give -o PREFIX or at least one of --normal, "
                  "--weights, --ssbump, --ao, --bent, --filtered, --slope (or --out-dir DIR "
                  "for a batch)");
  return st;
}

static bb_status check_options(const bb_job_options *o, const char *const *inputs,
                               int input_count, bb_error *err) {
  if (input_count < 1)
    return bb__fail(err, BB_ERR_ARGUMENT, "no input given");
  if (o->out_dir) {
    int named = o->slope_path != NULL || o->prefix != NULL || o->valve_path != NULL;
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
      named |= o->paths[k] != NULL;
    if (named)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "--out-dir names the outputs: choose the maps with --maps, not -o, "
                      "--MAP FILE or --slope");
    if (o->maps & ~BB_MAPS_BAKED)
      return bb__fail(err, BB_ERR_ARGUMENT, "maps: unknown map bits 0x%x", o->maps);
    if (o->vmt)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "--vmt writes one material: bake one input with --ssbump FILE.vtf");
    if (o->slope_lit)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "--lit previews one slope map: bake one input with --slope FILE");
  } else {
    bb_status st = check_single(o, inputs, input_count, err);
    if (st != BB_OK)
      return st;
  }
  if ((o->vmt_materials || o->vmt_basetexture) && !o->vmt)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--materials and --basetexture name a material's paths: give --vmt FILE");
  if (strcmp(bb__channel_name(o->channel), "unknown") == 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "unknown height channel %d", (int)o->channel);
  if ((int)o->depth < BB_DEPTH_DEFAULT || o->depth > BB_DEPTH_FLOAT)
    return bb__fail(err, BB_ERR_ARGUMENT, "unknown depth %d", (int)o->depth);
  return BB_OK;
}

/* The options' strings, copied: a job outlives its caller's buffers. */
static bb_status copy_options(bb_job *job, const bb_job_options *o, bb_error *err) {
  job->options = *o;
  job->options.bake.outputs = bb__job_maps_asked(o);
  job->batch = o->out_dir != NULL;
  job->basis_file = copy(o->basis_file);
  job->out_dir = copy(o->out_dir);
  job->name_template = copy(o->name_template);
  job->depfile = copy(o->depfile);
  job->command = copy(o->command);
  job->command_options = copy(o->command_options);
  job->slope_path = copy(o->slope_path);
  job->bounce_albedo_file = copy(o->bounce_albedo_file);
  job->brightness_file = copy(o->brightness_file);
  job->vmt = copy(o->vmt);
  job->vmt_materials = copy(o->vmt_materials);
  job->vmt_basetexture = copy(o->vmt_basetexture);
  job->valve_path = copy(o->valve_path);
  job->options.valve_path = job->valve_path;
  if ((o->valve_path && !job->valve_path) || (o->vmt && !job->vmt) || (o->vmt_materials && !job->vmt_materials) ||
      (o->vmt_basetexture && !job->vmt_basetexture))
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  job->options.vmt = job->vmt;
  job->options.vmt_materials = job->vmt_materials;
  job->options.vmt_basetexture = job->vmt_basetexture;
  job->options.texture.description = NULL; /* each file's own provenance */
  if (job->options.texture.threads == 0)
    job->options.texture.threads = o->bake.trace.threads;
  if ((o->bounce_albedo_file && !job->bounce_albedo_file) ||
      (o->brightness_file && !job->brightness_file))
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  if ((o->basis_file && !job->basis_file) || (o->out_dir && !job->out_dir) ||
      (o->name_template && !job->name_template) || (o->depfile && !job->depfile) ||
      (o->command && !job->command) || (o->command_options && !job->command_options) ||
      (o->slope_path && !job->slope_path))
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  /* The options keep no pointer of the caller's. */
  memset(job->options.paths, 0, sizeof job->options.paths);
  job->options.basis_file = job->basis_file;
  job->options.out_dir = job->out_dir;
  job->options.name_template = job->name_template;
  job->options.depfile = job->depfile;
  job->options.command = job->command;
  job->options.command_options = job->command_options;
  job->options.slope_path = job->slope_path;
  job->options.prefix = NULL; /* expanded into the item's paths */
  job->options.bounce_albedo_file = job->bounce_albedo_file;
  job->options.brightness_file = job->brightness_file;
  /* A basis file is a prerequisite only when it made the basis. */
  job->prerequisite_basis =
      job->basis_file && strncmp(o->bake.basis.name, "vectors:", 8) == 0;
  return BB_OK;
}

/* The maps the bake multiplies by, read once for every input (the bake
 * checks their size against each). */
static bb_status read_bake_maps(bb_job *job, bb_error *err) {
  bb_status st = BB_OK;
  if (job->bounce_albedo_file) {
    st = bb_image_read(job->bounce_albedo_file, &job->bounce_albedo_map, NULL, err);
    job->options.bake.bounce_albedo_map = st == BB_OK ? &job->bounce_albedo_map : NULL;
  }
  if (st == BB_OK && job->brightness_file) {
    st = bb_image_read(job->brightness_file, &job->brightness_map, NULL, err);
    job->options.bake.brightness = st == BB_OK ? &job->brightness_map : NULL;
  }
  return st;
}

int bb__job_map_files(const bb__job_item *item, int *kinds, const char **paths,
                      const char **commands) {
  int n = 0;
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    if (!item->paths[k])
      continue;
    kinds[n] = k, paths[n] = item->paths[k], commands[n++] = item->commands[k];
    for (int i = 0; i < item->more_count; i++)
      if (item->more_kinds[i] == k)
        kinds[n] = k, paths[n] = item->more_paths[i],
        commands[n++] = item->more_commands[i];
  }
  return n;
}

/* The further files of a single input's maps, and the command each file of
 * such a map records: a map given more than once is still one bake. */
static bb_status name_more(bb_job *job, const bb_job_options *o, const bb__job_more *more,
                           bb_error *err) {
  bb__job_item *item = &job->items[0];
  int outputs = 0;
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    outputs += item->paths[k] != NULL;
  outputs += (o->valve_path != NULL) + (o->slope_path != NULL) + (o->slope_lit != 0) +
             (o->vmt != NULL);
  if (outputs + more->count > BB_JOB_MAX_OUTPUTS)
    return bb__fail(err, BB_ERR_ARGUMENT, "a bake writes at most %d files (%d asked)",
                    BB_JOB_MAX_OUTPUTS, outputs + more->count);
  for (int i = 0; i < more->count; i++) {
    const int k = more->kinds[i];
    if (k < 0 || k >= BB_MAP_BAKED_COUNT || !o->paths[k] || !more->paths[i])
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "job plan: a further file of a map not asked");
    item->more_kinds[i] = k;
    if (!(item->more_paths[i] = strdup(more->paths[i])) ||
        (more->commands[i] && !(item->more_commands[i] = strdup(more->commands[i]))))
      return bb__fail(err, BB_ERR_MEMORY, "out of memory");
    item->more_count = i + 1;
  }
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    if (more->first_commands[k] && item->paths[k] &&
        !(item->commands[k] = strdup(more->first_commands[k])))
      return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  return BB_OK;
}

/* A single input's outputs, as named, and PREFIX_KIND.png for Valve's trio
 * where a prefix is given. */
static bb_status name_single(bb_job *job, const bb_job_options *o, bb_error *err) {
  bb__job_item *item = &job->items[0];
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    bb_status st = bb__job_map_file(o, (bb_map_kind)k, &item->paths[k], err);
    if (st != BB_OK)
      return st;
  }
  if (o->slope_path && o->slope_lit) {
    /* The preview is the map's name with "_lit" before its extension. */
    const char *dot = bb__file_extension(o->slope_path);
    const size_t stem = dot ? (size_t)(dot - o->slope_path) : strlen(o->slope_path);
    const size_t len = strlen(o->slope_path) + sizeof "_lit";
    if (!(item->slope_lit_path = malloc(len)))
      return bb__fail(err, BB_ERR_MEMORY, "out of memory");
    snprintf(item->slope_lit_path, len, "%.*s_lit%s", (int)stem, o->slope_path, dot ? dot : "");
  }
  return BB_OK;
}

static int is_vtf(const char *path) {
  return bb__path_has_extension(path, "vtf");
}

/* The material of a single input: its bump map is the ssbump .vtf, else
 * the normal map's .vtf; its text is made now, so a path it cannot name
 * costs no baking time. */
static bb_status plan_material(bb_job *job, bb_error *err) {
  if (!job->vmt)
    return BB_OK;
  const bb__job_item *item = &job->items[0];
  /* the .vtf among each map's files */
  const char *ssbump = NULL, *normal = NULL;
  int kinds[BB_JOB_MAX_OUTPUTS];
  const char *paths[BB_JOB_MAX_OUTPUTS], *commands[BB_JOB_MAX_OUTPUTS];
  const int files = bb__job_map_files(item, kinds, paths, commands);
  for (int f = files - 1; f >= 0; f--) {
    if (kinds[f] == BB_MAP_SSBUMP && is_vtf(paths[f]))
      ssbump = paths[f];
    if (kinds[f] == BB_MAP_NORMAL && is_vtf(paths[f]))
      normal = paths[f];
  }
  int is_ssbump = ssbump != NULL;
  const char *bump = is_ssbump ? ssbump : normal;
  if (job->valve_path) { /* Valve's file is the bump map, whatever it is named */
    bump = job->valve_path;
    is_ssbump = !job->options.valve.normal_map;
  }
  if (!bump)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--vmt %s: a material needs a .vtf bump map: write --ssbump (or --normal) "
                    "as a .vtf file",
                    job->vmt);
  /* bb__vmt_text checks the material's own name (.vmt, no texture's). */
  const bb_vmt_options v = {job->vmt_materials, bump, job->vmt_basetexture, is_ssbump};
  return bb__vmt_text(job->vmt, &v, &job->vmt_text, &job->vmt_size, err);
}

/* Creates path's directory and its parents when missing (mkdir -p). A name
 * taken by a file is left to the outputs' check, which says which output it
 * stops; a failure names the output too. */
static bb_status create_directory_of(const char *path, bb_error *err) {
  if (!path)
    return BB_OK;
  char dir[PATH_MAX];
  bb__directory_part(path, dir, sizeof dir);
  struct stat s;
  if (stat(dir, &s) == 0)
    return BB_OK;
  bb_error e = {{0}};
  bb_status st = bb__directory_create(dir, &e);
  return st == BB_OK ? BB_OK : bb__fail(err, st, "%s: cannot write: %s", path, e.message);
}

/* Creates out_dir and every directory the outputs' names need: a batch's
 * template subfolders, a single input's named files' folders (as a batch
 * creates its out_dir; the depfile's folder is the build system's). */
static bb_status create_directories(const bb_job *job, bb_error *err) {
  bb_status st = job->out_dir ? bb__directory_create(job->out_dir, err) : BB_OK;
  for (int i = 0; i < job->count && st == BB_OK; i++) {
    int kinds[BB_JOB_MAX_OUTPUTS];
    const char *paths[BB_JOB_MAX_OUTPUTS], *commands[BB_JOB_MAX_OUTPUTS];
    const int files = bb__job_map_files(&job->items[i], kinds, paths, commands);
    for (int f = 0; f < files && st == BB_OK; f++)
      st = create_directory_of(paths[f], err);
    if (st == BB_OK)
      st = create_directory_of(job->items[i].slope_lit_path, err);
  }
  const char *single[] = {job->valve_path, job->slope_path, job->vmt};
  for (size_t i = 0; i < sizeof single / sizeof *single && st == BB_OK && !job->batch; i++)
    st = create_directory_of(single[i], err);
  return st;
}

static void init_reports(bb_job *job) {
  for (int i = 0; i < job->count; i++) {
    bb__job_item *item = &job->items[i];
    bb_job_report *r = &item->report;
    memset(r, 0, sizeof *r);
    r->input = item->input;
    if (job->valve_path)
      r->outputs[r->output_count++] =
          (bb_job_file){bb__job_valve_kind(&job->options), job->valve_path};
    int kinds[BB_JOB_MAX_OUTPUTS];
    const char *paths[BB_JOB_MAX_OUTPUTS], *commands[BB_JOB_MAX_OUTPUTS];
    const int files = bb__job_map_files(item, kinds, paths, commands);
    for (int f = 0; f < files; f++)
      r->outputs[r->output_count++] = (bb_job_file){kind_name(kinds[f]), paths[f]};
    if (job->slope_path)
      r->outputs[r->output_count++] = (bb_job_file){"slope", job->slope_path};
    if (item->slope_lit_path)
      r->outputs[r->output_count++] = (bb_job_file){"slope_lit", item->slope_lit_path};
    if (job->vmt)
      r->outputs[r->output_count++] = (bb_job_file){"material", job->vmt};
  }
}

bb_status bb__job_plan(const char *const *inputs, int input_count, const bb_job_options *o,
                       unsigned flags, const bb__job_more *more, bb_job **out,
                       bb_error *err) {
  if (!out || !o || (input_count > 0 && !inputs))
    return bb__fail(err, BB_ERR_ARGUMENT, "job plan: bad arguments");
  *out = NULL;
  /* Its outputs record the command line that made them: the command's
   * (bb__command_plan), spelled by the one speller, bb_command_text. */
  if (!o->command && !o->command_options)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "job plan: no command line to record (plan it through its command)");
  bb_status st = check_options(o, inputs, input_count, err);
  if (st != BB_OK)
    return st;
  bb_job *job = calloc(1, sizeof *job);
  if (!job)
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  st = copy_options(job, o, err);
  job->read_only = (flags & BB__PLAN_READ_ONLY) != 0;
  if (st == BB_OK && (flags & BB__PLAN_CHECKED))
    bb__bake_resolve(&job->options.bake);
  else if (st == BB_OK)
    st = bb__bake_prepare(&job->options.bake, &job->options.bake, err);
  if (st == BB_OK)
    st = read_bake_maps(job, err);
  if (st == BB_OK)
    job->options.bake.bounce_albedo = bb__bounce_rho(job->options.bake.bounce_albedo,
                                                     job->options.bake.bounce_albedo_map != NULL);
  if (st == BB_OK && job->batch)
    st = check_template(job->name_template, err);
  if (st == BB_OK)
    st = gather_inputs(job, inputs, input_count, err);
  if (st == BB_OK && !job->batch)
    st = name_single(job, o, err);
  if (st == BB_OK && !job->batch && more)
    st = name_more(job, o, more, err);
  for (int k = 0; k < BB_MAP_BAKED_COUNT && st == BB_OK && !job->batch; k++)
    job->options.paths[k] = job->items[0].paths[k]; /* the job's copies */
  if (st == BB_OK && !job->batch)
    st = plan_material(job, err);
  for (int i = 0; i < job->count && st == BB_OK && job->batch; i++)
    st = name_outputs(job, &job->items[i], err);
  if (st == BB_OK && job->batch)
    st = check_batch_paths(job, err);
  if (st == BB_OK && !job->read_only)
    st = create_directories(job, err);
  for (int i = 0; i < job->count && st == BB_OK; i++)
    st = check_item_outputs(job, &job->items[i], err);
  if (st == BB_OK && job->depfile)
    st = check_depfile(job, err);
  if (st != BB_OK) {
    bb_job_free(job);
    return st;
  }
  init_reports(job);
  *out = job;
  return BB_OK;
}

bb_status bb__job_plan_options(const char *const *inputs, int input_count, const bb_job_options *o,
                      bb_job **out, bb_error *err) {
  return bb__job_plan(inputs, input_count, o, 0, NULL, out, err);
}

void bb_job_free(bb_job *job) {
  if (!job)
    return;
  for (int i = 0; i < job->count; i++) {
    free(job->items[i].input);
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
      free(job->items[i].paths[k]);
      free(job->items[i].commands[k]);
    }
    for (int m = 0; m < job->items[i].more_count; m++) {
      free(job->items[i].more_paths[m]);
      free(job->items[i].more_commands[m]);
    }
    free(job->items[i].slope_lit_path);
  }
  free(job->items);
  free(job->basis_file);
  free(job->out_dir);
  free(job->name_template);
  free(job->depfile);
  free(job->command);
  free(job->command_options);
  free(job->slope_path);
  free(job->bounce_albedo_file);
  free(job->brightness_file);
  free(job->vmt);
  free(job->vmt_materials);
  free(job->vmt_basetexture);
  free(job->vmt_text);
  free(job->valve_path);
  bb_image_free(&job->bounce_albedo_map);
  bb_image_free(&job->brightness_map);
  free(job);
}

int bb__job_reads(const bb_job *job, const bb__job_item *item, const char **out) {
  int n = 0;
  out[n++] = item->input;
  if (job->prerequisite_basis)
    out[n++] = job->basis_file;
  if (job->bounce_albedo_file)
    out[n++] = job->bounce_albedo_file;
  if (job->brightness_file)
    out[n++] = job->brightness_file;
  return n;
}

int bb_job_count(const bb_job *job) {
  return job ? job->count : 0;
}

const bb_job_report *bb_job_report_get(const bb_job *job, int i) {
  return job && i >= 0 && i < job->count ? &job->items[i].report : NULL;
}
