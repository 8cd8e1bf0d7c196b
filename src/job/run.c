/* run.c: a planned bake job run input by input: inputs whose outputs are
 * up to date skipped, the others read, baked once and written all or
 * nothing with their provenance, and the depfile of what was made. */
#include "bake/bake_internal.h"
#include "core/input_file.h"
#include "core/internal.h"
#include "files/safe_file.h"
#include "job/job_internal.h"
#include "texture/blocks.h"
#include "maps/maps_internal.h"
#include "image/oiio_module.h"
#include "render/render_internal.h"
#include "texture/texture.h"

#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static const bb_map_kind_info *kind_info(int kind) {
  return bb_map_kind_get((bb_map_kind)kind);
}

/* The depth kind is written with: the job's, but the filtered height keeps
 * the input's depth where the format holds it unless a depth was asked. */
static bb_depth output_depth(const bb_job *job, int kind, const char *path, int bits,
                             int is_float) {
  if (kind == BB_MAP_FILTERED)
    return bb__job_depth(job->options.depth, bits, is_float, path);
  return job->options.depth;
}

/* ----------------------------------------------------------- up to date */

static bb_status fail_item(bb_job_report *r, bb_status st, const bb_error *e) {
  r->outcome = BB_JOB_FAILED;
  r->status = st;
  if (e && e != &r->error)
    r->error = *e;
  return st;
}

/* 1 when the material file holds the bytes the plan made for it. */
static int material_is_current(const bb_job *job) {
  int fd;
  if (bb__input_open(job->vmt, &fd, NULL) != BB_OK) /* a FIFO is not waited on */
    return 0;
  FILE *f = fdopen(fd, "rb");
  if (!f) {
    close(fd);
    return 0;
  }
  char *have = malloc(job->vmt_size + 1);
  const size_t n = have ? fread(have, 1, job->vmt_size + 1, f) : 0;
  const int same = have && n == job->vmt_size && memcmp(have, job->vmt_text, n) == 0;
  free(have);
  fclose(f);
  return same;
}

/* 1 when every map of item is what baking it now would write, judged from
 * the files' headers; reason says why not. */
static int item_is_current(const bb_job *job, bb__job_item *item, char *reason, size_t cap) {
  if (job->slope_path) { /* the slope files are not judged: baked every time */
    snprintf(reason, cap, "a slope map is asked");
    return 0;
  }
  if (item->more_count) { /* nor a map's further files: baked every time */
    snprintf(reason, cap, "a map is written to several files");
    return 0;
  }
  bb_bake_options o = job->options.bake;
  char rayset[64];
  bb__bake_rayset_id(&o, rayset, sizeof rayset);
  bb_image_info info;
  int bits = 8, is_float = 0;
  if (bb_image_read_info(item->input, NULL, NULL, NULL, &info, NULL) == BB_OK) {
    bits = info.bits_per_sample;
    is_float = info.is_float;
    bb_image_info_free(&info);
  }
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    if (!item->paths[k])
      continue;
    /* A texture's settings are part of its provenance (bb__image_write adds them). */
    char *texture = bb__texture_provenance(item->paths[k], &job->options.texture);
    const bb__job_source s = {.input_file_hash = item->file_hash,
                              .bake = &o,
                              .channel = job->options.channel,
                              .rayset_id = rayset[0] ? rayset : NULL,
                              .extra = texture};
    const bb_provenance want = bb__job_provenance(&s, kind_info(k)->name);
    bb_output_state state;
    const bb_depth depth = output_depth(job, k, item->paths[k], bits, is_float);
    char why[200] = "";
    const bb_status checked = bb__output_check(item->paths[k], &want, depth, job->options.mips,
                                              &state, why, sizeof why, NULL);
    free(texture);
    if (checked != BB_OK) {
      snprintf(reason, cap, "%s: cannot be checked", item->paths[k]);
      return 0;
    }
    if (state != BB_OUTPUT_CURRENT) {
      snprintf(reason, cap, "%s: %s", item->paths[k], why);
      return 0;
    }
  }
  if (job->vmt && !material_is_current(job)) {
    snprintf(reason, cap, "%s: not the material this bake writes", job->vmt);
    return 0;
  }
  reason[0] = '\0';
  return 1;
}

/* An input found up to date whose outputs are older than a file it reads
 * (a touched input, a basis file rewritten with the same directions):
 * make compares times, not contents, so it would run the bake again on
 * every make. The outputs' times are set to now (or to the newest read's,
 * should its clock run ahead), so the target is newer than its
 * prerequisites; outputs already newer are left alone. Best effort: an
 * output whose time cannot be set is left as it is. */
static void keep_outputs_newer(const bb_job *job, const bb__job_item *item) {
  const char *reads[BB__JOB_MAX_READS];
  const int n = bb__job_reads(job, item, reads);
  struct timespec newest = {0, 0};
  struct stat st;
  for (int r = 0; r < n; r++)
    if (reads[r] && stat(reads[r], &st) == 0 &&
        (st.st_mtim.tv_sec > newest.tv_sec ||
         (st.st_mtim.tv_sec == newest.tv_sec && st.st_mtim.tv_nsec > newest.tv_nsec)))
      newest = st.st_mtim;
  struct timespec now;
  clock_gettime(CLOCK_REALTIME, &now);
  const int ahead = newest.tv_sec > now.tv_sec ||
                    (newest.tv_sec == now.tv_sec && newest.tv_nsec > now.tv_nsec);
  const struct timespec when[2] = {ahead ? newest : now, ahead ? newest : now};
  const bb_job_report *r = &item->report;
  for (int k = 0; k < r->output_count; k++) {
    const char *path = r->outputs[k].path;
    if (lstat(path, &st) != 0 || !S_ISREG(st.st_mode))
      continue;
    if (st.st_mtim.tv_sec > newest.tv_sec ||
        (st.st_mtim.tv_sec == newest.tv_sec && st.st_mtim.tv_nsec > newest.tv_nsec))
      continue;
    (void)utimensat(AT_FDCWD, path, when, AT_SYMLINK_NOFOLLOW);
  }
}

bb_status bb_job_check_current(bb_job *job, int i, int *current, bb_error *err) {
  if (!job || i < 0 || i >= job->count || !current)
    return bb__fail(err, BB_ERR_ARGUMENT, "job check: bad arguments");
  bb__job_item *item = &job->items[i];
  *current = 0;
  /* An input that is no image is not current, judged by its header before
   * all its bytes are hashed: its bake refuses it in the same words. */
  bb_error refused = {{0}};
  bb_status st = bb_image_read_info(item->input, NULL, NULL, NULL, NULL, &refused);
  if (st != BB_OK && st != BB_ERR_IO) {
    snprintf(item->report.reason, sizeof item->report.reason, "%.*s",
             (int)sizeof item->report.reason - 1, refused.message);
    return BB_OK;
  }
  if (st != BB_OK) {
    if (err)
      *err = refused;
    return st;
  }
  st = bb_file_hash(item->input, &item->file_hash, err);
  if (st != BB_OK)
    return st;
  *current = item_is_current(job, item, item->report.reason, sizeof item->report.reason);
  return BB_OK;
}

/* ------------------------------------------------------------------ bake */

/* Everything one input's bake makes, and the provenance texts of its files. */
typedef struct baked {
  unsigned only;     /* the maps to write: BB_MAP_BIT(kind)s; 0: every file */
  bb_image height;
  bb_bake_result result;
  bb_image valve;    /* Valve's packed file (job->valve_path) */
  bb_image slope, slope_lit;
  char *descriptions[BB_JOB_MAX_OUTPUTS];
  char *depfile_text;
} baked;

static void baked_free(baked *b) {
  bb_image_free(&b->height);
  bb_bake_result_free(&b->result);
  bb_image_free(&b->valve);
  bb_image_free(&b->slope);
  bb_image_free(&b->slope_lit);
  for (int i = 0; i < BB_JOB_MAX_OUTPUTS; i++)
    free(b->descriptions[i]);
  free(b->depfile_text);
}

/* flipcode's slope map of the filtered height and its lit preview. */
static bb_status make_slope(const bb_job *job, const bb__job_item *item, baked *b,
                            bb_error *err) {
  const bb_bake_options *o = &job->options.bake;
  bb_status st = bb__slope_map(&b->result.filtered, o->height_scale, o->smooth.addressing,
                              &b->slope, err);
  if (st == BB_OK && item->slope_lit_path) {
    double light[3];
    float table[256];
    bb__light_direction(job->options.slope_lit_azimuth, job->options.slope_lit_elevation, light);
    bb__slope_table(light, table);
    st = bb__slope_light(&b->slope, table, &b->slope_lit, err);
  }
  return st;
}

/* The message of a failure about item's input, naming it once. */
static bb_status fail_input(const bb__job_item *item, bb_status st, const bb_error *e,
                            bb_error *err) {
  const size_t n = strlen(item->input);
  if (strncmp(e->message, item->input, n) == 0 && e->message[n] == ':')
    return bb__fail(err, st, "%s", e->message);
  return bb__fail(err, st, "%s: %s", item->input, e->message);
}

/* Valve's RGBA file of the bake (bb__valve_pack), and for its detail
 * variant the input's colour read again (the height reader kept only the
 * height) to scale it by (bb__valve_detail). */
static bb_status make_valve(const bb_job *job, const bb__job_item *item, baked *b,
                            bb_error *err) {
  bb_error e = {{0}};
  bb_status st = bb__valve_pack(&b->result, &job->options.valve, &b->valve, &e);
  if (st == BB_OK && job->options.valve_detail) {
    bb_image colour = {0};
    st = bb_image_read(item->input, &colour, NULL, &e);
    if (st == BB_OK)
      st = bb__valve_detail(&b->valve, &colour, &b->height, &job->options.bake.smooth, &e);
    bb_image_free(&colour);
  }
  return st == BB_OK ? BB_OK : fail_input(item, st, &e, err);
}

/* The provenance text of an output of kind of the input r reports, its
 * bake's ray set rayset_id (NULL: none traced). */
static char *provenance(const bb_job *job, const char *command, const char *rayset_id,
                        const bb_job_report *r, const char *kind) {
  /* Valve's file names the channel its rule took (alpha, or the grey) */
  const bb_channel channel = job->valve_path ? r->source.channel : job->options.channel;
  const bb__job_source s = {.command = command,
                            .input = r->input,
                            .input_hash = r->source.height_hash,
                            .input_file_hash = r->source.file_hash,
                            .bake = &job->options.bake,
                            .channel = channel,
                            .rayset_id = rayset_id};
  return bb__job_describe(&s, kind);
}

/* The provenance text of one output of item: the ray set when the job
 * writes a traced map. */
static char *describe(const bb_job *job, const char *command, const bb_bake_result *result,
                      const bb_job_report *r, const char *kind) {
  const int traced = (job->options.bake.outputs & BB_MAPS_TRACED) != 0;
  return provenance(job, command, traced ? result->rayset_id : NULL, r, kind);
}

char *bb_job_provenance(const bb_job *job, int i, const char *kind) {
  if (!job || i < 0 || i >= job->count || !kind)
    return NULL;
  const bb__job_item *item = &job->items[i];
  const bb_job_report *r = &item->report;
  if (r->width <= 0)
    return NULL; /* not baked */
  char *command = bb__job_command_of(job, item);
  if (!command && (job->command || job->command_options))
    return NULL;
  char *text = provenance(job, command, r->rayset_id[0] ? r->rayset_id : NULL, r, kind);
  free(command);
  return text;
}

/* The depfile rule of one input: its outputs depend on it (and on the basis
 * file that made the basis). */
static bb__dep_rule rule_of(const bb_job *job, const bb__job_item *item, const char **targets,
                            const char **prereq) {
  int t = 0;
  for (int k = 0; k < item->report.output_count; k++)
    targets[t++] = item->report.outputs[k].path;
  return (bb__dep_rule){targets, t, prereq, bb__job_reads(job, item, prereq)};
}

/* The depfile's text written: replacing a file whole, or through a stream
 * (bb__safe_is_stream: /dev/stdout, a FIFO) as it is; on failure the
 * message ends with what was written before. */
static bb_status write_depfile_text(const char *path, const char *text, size_t size,
                                    const char *written, bb_error *err) {
  bb_error local = {{0}};
  bb_status st = bb__safe_is_stream(path) ? bb__safe_write_through(path, text, size, &local)
                                          : bb__file_write(path, text, size, &local);
  if (st != BB_OK)
    bb__fail(err, st, "%s; %s", local.message, written);
  return st;
}

/* A single input's depfile on its own, after its maps. */
static bb_status write_depfile(const bb_job *job, const bb__job_item *item, const char *written,
                               bb_error *err) {
  const char *targets[BB_JOB_MAX_OUTPUTS], *prereq[BB__JOB_MAX_READS];
  bb__dep_rule rule = rule_of(job, item, targets, prereq);
  size_t size = 0;
  char *text = bb__depfile_text(&rule, 1, &size);
  bb_status st = text ? write_depfile_text(job->depfile, text, size, written, err)
                      : bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", job->depfile);
  free(text);
  return st;
}

/* The files of one input: its maps, the slope files, and a single input's
 * depfile, written together (a depfile written through a stream comes
 * after them). */
static bb_status write_item(bb_job *job, bb__job_item *item, baked *b,
                            bb_progress_fn progress, void *progress_user, bb_error *err) {
  bb_job_report *r = &item->report;
  char *command = bb__job_command_of(job, item);
  if (!command && (job->command || job->command_options))
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", item->input);
  bb_output_file files[BB_JOB_MAX_OUTPUTS + 1]; /* the maps, slope files, material, depfile */
  int n = 0;
  bb_status st = BB_OK;
  if (job->valve_path && !b->only) {
    const char *kind = bb__job_valve_kind(&job->options);
    b->descriptions[n] = describe(job, command, &b->result, r, kind);
    files[n] = (bb_output_file){job->valve_path, kind, &b->valve, BB_RANGE_UNIT,
                                job->options.depth, 0, b->descriptions[n], NULL, 0,
                                &job->options.texture};
    if (!b->descriptions[n++])
      st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", item->input);
  }
  /* every file of every map, a map written to several files from the one
   * bake, each recording its own command where it has one */
  int kinds[BB_JOB_MAX_OUTPUTS];
  const char *paths[BB_JOB_MAX_OUTPUTS], *commands[BB_JOB_MAX_OUTPUTS];
  const int map_files = bb__job_map_files(item, kinds, paths, commands);
  for (int f = 0; f < map_files && st == BB_OK; f++) {
    const int k = kinds[f];
    if (b->only && !(b->only & BB_MAP_BIT(k)))
      continue;
    b->descriptions[n] = describe(job, commands[f] ? commands[f] : command, &b->result, r,
                                  kind_info(k)->name);
    files[n] = (bb_output_file){
        paths[f],
        kind_info(k)->name,
        bb__bake_result_image(&b->result, (bb_map_kind)k),
        kind_info(k)->range,
        output_depth(job, k, paths[f], r->source.bits_per_sample, r->source.is_float),
        job->options.mips,
        b->descriptions[n],
        NULL,
        0,
        &job->options.texture};
    if (!b->descriptions[n++])
      st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", item->input);
  }
  /* The slope map is its bytes (8-bit, no mip levels: an average of slope
   * bytes means nothing); its preview is a picture at the job's depth. */
  if (st == BB_OK && b->slope.pixels) {
    b->descriptions[n] = describe(job, command, &b->result, r, "slope");
    files[n] = (bb_output_file){job->slope_path, "slope", &b->slope, BB_RANGE_UNIT,
                                BB_DEPTH_8, 0, b->descriptions[n], NULL, 0, NULL};
    if (!b->descriptions[n++])
      st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", item->input);
  }
  if (st == BB_OK && b->slope_lit.pixels) {
    b->descriptions[n] = describe(job, command, &b->result, r, "slope_lit");
    files[n] = (bb_output_file){item->slope_lit_path, "slope_lit", &b->slope_lit,
                                BB_RANGE_UNIT, job->options.depth, 0, b->descriptions[n],
                                NULL, 0, NULL};
    if (!b->descriptions[n++])
      st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", item->input);
  }
  free(command);
  if (st == BB_OK && job->vmt && !b->only)
    files[n++] = (bb_output_file){job->vmt, "material", NULL, BB_RANGE_UNIT, BB_DEPTH_DEFAULT,
                                  0, NULL, job->vmt_text, job->vmt_size, NULL};
  const int depfile_stream =
      job->depfile && !job->batch && !b->only && bb__safe_is_stream(job->depfile);
  if (st == BB_OK && job->depfile && !job->batch && !b->only && !depfile_stream) {
    /* One input's depfile goes in with its maps: all of them or none. */
    const char *targets[BB_JOB_MAX_OUTPUTS], *prereq[BB__JOB_MAX_READS];
    bb__dep_rule rule = rule_of(job, item, targets, prereq);
    size_t size = 0;
    if (!(b->depfile_text = bb__depfile_text(&rule, 1, &size)))
      st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", job->depfile);
    else
      files[n++] = (bb_output_file){job->depfile, "depfile", NULL, BB_RANGE_UNIT,
                                    BB_DEPTH_DEFAULT, 0, NULL, b->depfile_text, size, NULL};
  }
  const double t0 = bb__now_seconds();
  /* The engine textures' block compression is a stage of its own: its
   * progress (rows of blocks, stage "compress") and its seconds, a part
   * of the write's. */
  bb__blocks_watch watch;
  bb__blocks_watch_init(&watch, st == BB_OK ? bb__outputs_block_rows(files, n) : 0, progress,
                        progress_user);
  if (watch.total > 0)
    job->stage = "compress";
  if (st == BB_OK)
    st = bb__outputs_write(files, n, b->result.threads, &watch, err);
  job->stage = NULL;
  r->seconds_compress = watch.seconds;
  bb__blocks_watch_destroy(&watch);
  if (st == BB_OK && depfile_stream)
    st = write_depfile(job, item, "the maps were written", err);
  r->seconds_write = bb__now_seconds() - t0;
  return st;
}

/* Reads item's input and bakes it (the job's outputs and the kinds in also),
 * filling its report's figures; writes nothing. */
static bb_status read_and_bake(bb_job *job, bb__job_item *item, unsigned also,
                               bb_progress_fn progress, void *progress_user, baked *b,
                               bb_error *err) {
  bb_job_report *r = &item->report;
  const double t0 = bb__now_seconds();
  job->stage = "bake";
  bb_status st = bb__job_memory_check(job, item, err);
  if (st == BB_OK)
    st = bb__height_file_read(item->input, job->options.channel,
                             job->options.bake.height_scale, job->options.note,
                             job->options.note_user, &b->height, &r->source, err);
  r->seconds_load = bb__now_seconds() - t0;
  /* A material naming no colour map: said with the input's notes, so a
   * caller that takes notes as errors stops before anything is written. */
  if (st == BB_OK && job->vmt && !job->vmt_basetexture && job->options.note)
    job->options.note(job->options.note_user, job->vmt,
                      "the material has no $basetexture (no colour map): give --basetexture "
                      "FILE.vtf, or add the line to the .vmt");
  /* A colour map named but not there (a typo, or one made later): Source
   * draws its missing-texture checkerboard until it is. */
  struct stat base;
  if (st == BB_OK && job->vmt_basetexture && job->options.note &&
      (stat(job->vmt_basetexture, &base) != 0 || !S_ISREG(base.st_mode))) {
    char text[PATH_MAX + 160];
    snprintf(
        text, sizeof text,
        "--basetexture %s is not a file (yet): Source draws the material's colour as its "
        "missing-texture checkerboard until it is",
        job->vmt_basetexture);
    job->options.note(job->options.note_user, job->vmt, text);
  }
  /* The input's notes have been given: a caller that takes one as an
   * error cancels here, before anything is baked or written (progress
   * (0, 0): a checkpoint, no work done yet). */
  if (st == BB_OK && progress && progress(progress_user, 0, 0))
    st = bb__fail(err, BB_ERR_CANCELLED, "%s: cancelled by the progress callback", item->input);
  const int height_width = b->height.width, height_height = b->height.height;
  int slices = job->options.bake.slices;
  if (st == BB_OK) {
    bb_bake_options o = job->options.bake;
    o.outputs |= also;
    bb__bake_resolve(&o); /* the kinds added may trace */
    slices = o.slices;
    o.trace.progress = progress;
    o.trace.progress_user = progress_user;
    bb_error bake_err = {{0}};
    /* only the maps are kept: the bake lets the height and vis go as soon
     * as it is done with them (Valve's detail reads the height again) */
    const unsigned flags =
        BB__BAKE_DROP_VIS | (job->options.valve_detail ? 0u : BB__BAKE_TAKE_HEIGHT);
    st = bb__bake_through(job->context, &b->height, &o, flags, &b->result, &bake_err);
    if (st != BB_OK)
      bb__fail(err, st, "%s: %s", item->input, bake_err.message);
  }
  if (st == BB_OK && job->valve_path)
    st = make_valve(job, item, b, err);
  if (st == BB_OK && job->slope_path)
    st = make_slope(job, item, b, err);
  if (st == BB_OK) {
    const bb_bake_result *res = &b->result;
    r->width = height_width;
    r->height = height_height;
    r->threads = res->threads;
    r->slices = res->rayset_id[0] ? slices : 0; /* resolved by the plan */
    snprintf(r->rayset_id, sizeof r->rayset_id, "%s", res->rayset_id);
    r->horizons = res->horizons_found;
    r->seconds_smooth = res->seconds_smooth;
    r->seconds_pyramid = res->seconds_pyramid;
    r->seconds_trace = res->seconds_trace;
    r->seconds_derive = res->seconds_derive;
    r->bounces = res->bounces;
    r->seconds_bounce = res->seconds_bounce;
  }
  job->stage = NULL;
  return st;
}

static bb_status bake_item(bb_job *job, bb__job_item *item, bb_progress_fn progress,
                           void *progress_user, bb_error *err) {
  baked b;
  memset(&b, 0, sizeof b);
  bb_status st = read_and_bake(job, item, 0u, progress, progress_user, &b, err);
  if (st == BB_OK)
    st = write_item(job, item, &b, progress, progress_user, err);
  baked_free(&b);
  return st;
}

const char *bb_job_stage(const bb_job *job) {
  return job ? job->stage : NULL;
}

bb_status bb_job_bake_item(bb_job *job, int i, unsigned also, bb_progress_fn progress,
                           void *progress_user, bb_bake_result *result, bb_error *err) {
  if (result)
    memset(result, 0, sizeof *result);
  if (!job || i < 0 || i >= job->count || !result)
    return bb__fail(err, BB_ERR_ARGUMENT, "job bake: bad arguments");
  if (also & ~(unsigned)BB_MAPS_BAKED)
    return bb__fail(err, BB_ERR_ARGUMENT, "job bake: unknown map bits 0x%x", also);
  baked b;
  memset(&b, 0, sizeof b);
  bb_status st = read_and_bake(job, &job->items[i], also, progress, progress_user, &b, err);
  if (st == BB_OK) {
    *result = b.result; /* the maps change hands */
    memset(&b.result, 0, sizeof b.result);
  }
  baked_free(&b);
  return st;
}

void bb_job_use_context(bb_job *job, bb_bake_context *context) {
  if (job)
    job->context = context;
}

/* bb_job_write_item, or with only (BB_MAP_BIT(kind)s) just those maps. */
static bb_status write_maps(bb_job *job, int i, const bb_bake_result *result, unsigned only,
                            bb_error *err) {
  if (!job || i < 0 || i >= job->count || !result)
    return bb__fail(err, BB_ERR_ARGUMENT, "job write: bad arguments");
  bb__job_item *item = &job->items[i];
  bb_job_report *r = &item->report;
  if (r->width <= 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "job write: %s has not been baked by this job",
                    item->input);
  /* Valve's detail variant scales by the height as read, which the maps
   * do not hold: bb_job_run_item reads it again. */
  if (job->options.valve_detail)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "job write: %s: Valve's detail variant reads the input again "
                    "(bb_job_run_item writes it)",
                    item->input);
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    const bb_image *m = bb__bake_result_image(result, (bb_map_kind)k);
    const int needed = item->paths[k] || (k == BB_MAP_FILTERED && job->slope_path);
    if (needed && (!m || !m->pixels || m->width != r->width || m->height != r->height))
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "job write: %s: the maps given have no %s of %d x %d (another bake?)",
                      item->input, kind_info(k)->name, r->width, r->height);
  }
  baked b;
  memset(&b, 0, sizeof b);
  b.result = *result; /* borrowed: given back before baked_free */
  b.only = only;
  r->outcome = BB_JOB_PENDING;
  r->status = BB_OK;
  memset(&r->error, 0, sizeof r->error);
  bb_status st = BB_OK;
  if (job->valve_path && !only)
    st = make_valve(job, item, &b, &r->error);
  if (st == BB_OK && job->slope_path && !only)
    st = make_slope(job, item, &b, &r->error);
  if (st == BB_OK)
    st = write_item(job, item, &b, NULL, NULL, &r->error);
  memset(&b.result, 0, sizeof b.result);
  baked_free(&b);
  if (st != BB_OK) {
    if (err)
      *err = r->error;
    return fail_item(r, st, NULL);
  }
  r->outcome = BB_JOB_BAKED;
  return BB_OK;
}

bb_status bb_job_write_item(bb_job *job, int i, const bb_bake_result *result, bb_error *err) {
  return write_maps(job, i, result, 0u, err);
}

bb_status bb__job_write_maps(bb_job *job, int i, const bb_bake_result *result, unsigned maps,
                             bb_error *err) {
  return maps ? write_maps(job, i, result, maps, err) : BB_OK;
}

bb_depth bb__job_map_depth(const bb_job *job, int i, int kind) {
  const bb__job_item *item = &job->items[i];
  return output_depth(job, kind, item->paths[kind], item->report.source.bits_per_sample,
                      item->report.source.is_float);
}

char *bb__job_map_description(const bb_job *job, int i, const bb_bake_result *result,
                              int kind) {
  const bb__job_item *item = &job->items[i];
  char *command = bb__job_command_of(job, item);
  if (!command && (job->command || job->command_options))
    return NULL;
  char *text = describe(job, command, result, &item->report, kind_info(kind)->name);
  free(command);
  return text;
}

bb_status bb_job_run_item(bb_job *job, int i, bb_progress_fn progress, void *progress_user) {
  if (!job || i < 0 || i >= job->count)
    return BB_ERR_ARGUMENT;
  bb__job_item *item = &job->items[i];
  bb_job_report *r = &item->report;
  r->outcome = BB_JOB_PENDING;
  r->status = BB_OK;
  memset(&r->error, 0, sizeof r->error);
  if (!job->options.force) {
    int current = 0;
    bb_status st = bb_job_check_current(job, i, &current, &r->error);
    if (st != BB_OK)
      return fail_item(r, st, NULL);
    if (current) {
      keep_outputs_newer(job, item);
      r->outcome = BB_JOB_CURRENT;
      return BB_OK;
    }
  }
  bb_status st = bake_item(job, item, progress, progress_user, &r->error);
  if (st != BB_OK)
    return fail_item(r, st, NULL);
  r->outcome = BB_JOB_BAKED;
  return BB_OK;
}

/* --------------------------------------------------------------- depfile */

bb_status bb_job_write_depfile(bb_job *job, bb_error *err) {
  if (!job)
    return bb__fail(err, BB_ERR_ARGUMENT, "job depfile: no job");
  /* A single input's depfile was written with its maps. */
  if (!job->depfile || !job->batch)
    return BB_OK;
  const char *(*targets)[BB_JOB_MAX_OUTPUTS] = malloc((size_t)job->count * sizeof *targets);
  const char *(*prereq)[BB__JOB_MAX_READS] = malloc((size_t)job->count * sizeof *prereq);
  bb__dep_rule *rules = malloc((size_t)job->count * sizeof *rules);
  bb_status st = BB_OK;
  int n = 0, baked_inputs = 0;
  if (!targets || !prereq || !rules)
    st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", job->depfile);
  for (int i = 0; i < job->count && st == BB_OK; i++) {
    const bb_job_outcome o = job->items[i].report.outcome;
    baked_inputs += o == BB_JOB_BAKED;
    if (o == BB_JOB_BAKED || o == BB_JOB_CURRENT) {
      rules[n] = rule_of(job, &job->items[i], targets[n], prereq[n]);
      n++;
    }
  }
  size_t size = 0;
  char *text = st == BB_OK ? bb__depfile_text(rules, n, &size) : NULL;
  if (st == BB_OK && !text)
    st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", job->depfile);
  if (st == BB_OK) {
    char written[64];
    snprintf(written, sizeof written, "the maps of %d input%s baked were written", baked_inputs,
             baked_inputs == 1 ? "" : "s");
    st = write_depfile_text(job->depfile, text, size, written, err);
  }
  free(text);
  free(targets);
  free(prereq);
  free(rules);
  return st;
}

/* ------------------------------------------------------------------ runs */

bb_status bb_job_run(bb_job *job, bb_progress_fn progress, void *progress_user,
                     bb_job_report_fn each, void *user, bb_error *err) {
  if (!job)
    return bb__fail(err, BB_ERR_ARGUMENT, "job run: no job");
  /* The OpenImageIO module before any work, as bb_command_run loads it
   * (image/oiio_module.h): short of memory, the run fails here. */
  if (!bb__oiio_module())
    return bb__oiio_failed(err);
  bb_status first = BB_OK;
  int stopped = 0;
  for (int i = 0; i < job->count; i++) {
    bb_job_report *r = &job->items[i].report;
    if (stopped) {
      r->outcome = BB_JOB_NOT_RUN;
    } else {
      bb_status st = bb_job_run_item(job, i, progress, progress_user);
      if (st != BB_OK && first == BB_OK) {
        first = st;
        if (err)
          *err = r->error;
      }
      stopped = st != BB_OK && !job->options.keep_going;
    }
    if (each)
      each(user, r);
  }
  bb_status st = bb_job_write_depfile(job, first == BB_OK ? err : NULL);
  return first != BB_OK ? first : st;
}

const char *bb__job_outcome_name(bb_job_outcome outcome) {
  switch (outcome) {
  case BB_JOB_PENDING: return "pending";
  case BB_JOB_BAKED: return "baked";
  case BB_JOB_CURRENT: return "up to date";
  case BB_JOB_FAILED: return "failed";
  case BB_JOB_NOT_RUN: return "not run";
  }
  return "unknown";
}

const char *bb_report_word(const char *field, int value) {
  const char *w = NULL;
  if (field && !strcmp(field, "outcome"))
    w = bb__job_outcome_name((bb_job_outcome)value);
  else if (field && !strcmp(field, "result"))
    w = bb__check_status_name((bb_check_status)value);
  return w && strcmp(w, "unknown") != 0 ? w : NULL;
}
