/* command.c: the "command" a job's outputs record in their provenance: the
 * caller's command line when it gave one, else the bake's options written
 * out as `bumpbake bake` spells them, so the same job writes the same bytes
 * from the command line and from Python. Every word is quoted for a POSIX
 * shell (bb__text_add_word): typed in one, the line is that job. */
#include "core/internal.h"
#include "job/job_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void add_option(bb__text *t, const char *name, const char *value) {
  bb__text_add(t, " ");
  bb__text_add(t, name);
  if (value) {
    bb__text_add(t, " ");
    bb__text_add_word(t, value);
  }
}

/* The shortest decimal that reads back as the same float (36.8083, not
 * 36.8082962), as a user would type it. */
static void float_text(float v, char *buf, size_t cap) {
  for (int digits = 1; digits <= 9; digits++) {
    snprintf(buf, cap, "%.*g", digits, (double)v);
    if (strtof(buf, NULL) == v)
      return;
  }
}

static void double_text(double v, char *buf, size_t cap) {
  for (int digits = 1; digits <= 17; digits++) {
    snprintf(buf, cap, "%.*g", digits, v);
    if (strtod(buf, NULL) == v)
      return;
  }
}

static void add_float(bb__text *t, const char *name, float v) {
  char buf[32];
  float_text(v, buf, sizeof buf);
  add_option(t, name, buf);
}

static void add_double(bb__text *t, const char *name, double v) {
  char buf[40];
  double_text(v, buf, sizeof buf);
  add_option(t, name, buf);
}

static void add_int(bb__text *t, const char *name, long v) {
  char buf[24];
  snprintf(buf, sizeof buf, "%ld", v);
  add_option(t, name, buf);
}

/* The bake's settings that differ from bb_job_options_init's, in the order
 * of `bumpbake bake --help`. */
static void add_settings(bb__text *t, const bb_job_options *o) {
  bb_job_options d;
  bb_job_options_init(&d);
  const bb_bake_options *b = &o->bake, *db = &d.bake;
  add_float(t, "--scale", b->height_scale);
  if (b->slices)
    add_int(t, "--slices", b->slices);
  else if (b->rays != db->rays)
    add_int(t, "--rays", b->rays);
  if (b->smooth.radius_texels != db->smooth.radius_texels)
    add_int(t, "--filter-radius", b->smooth.radius_texels);
  if (b->smooth.threshold != db->smooth.threshold)
    add_float(t, "--filter-threshold", b->smooth.threshold);
  if (b->trace.bias_texels != db->trace.bias_texels)
    add_double(t, "--bias", b->trace.bias_texels);
  if (b->power != db->power)
    add_double(t, "--power", b->power);
  if (o->basis_file)
    add_option(t, "--basis", o->basis_file);
  else if (strcmp(b->basis.name, db->basis.name) != 0)
    add_option(t, "--basis", b->basis.name);
  if (b->normal_filter != db->normal_filter)
    add_option(t, "--normal-filter", bb_normal_filter_name(b->normal_filter));
  if (b->normal_y_up)
    add_option(t, "--normal-y", "up");
  if (b->smooth.addressing == BB_ADDRESS_CLAMP)
    add_option(t, "--clamp", NULL);
  if (o->channel != d.channel)
    add_option(t, "--channel", bb_channel_name(o->channel));
  if (o->depth != BB_DEPTH_DEFAULT)
    add_option(t, "--depth", bb_depth_name(o->depth));
  if (o->mips)
    add_option(t, "--mips", NULL);
  if (b->bounce_albedo != db->bounce_albedo &&
      !(o->bounce_albedo_file && b->bounce_albedo == 1.0))
    add_double(t, "--bounce", b->bounce_albedo);
  if (b->bounces != db->bounces)
    add_int(t, "--bounces", b->bounces);
  if (o->bounce_albedo_file)
    add_option(t, "--bounce-albedo", o->bounce_albedo_file);
  if (o->brightness_file)
    add_option(t, "--brightness", o->brightness_file);
}

/* The outputs: one by one, or a batch's directory, maps and names. */
static void add_outputs(bb__text *t, const bb_job_options *o) {
  if (!o->out_dir) {
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
      if (o->paths[k]) {
        char name[32];
        snprintf(name, sizeof name, "--%s", bb_map_kind_get((bb_map_kind)k)->name);
        add_option(t, name, o->paths[k]);
      }
    if (o->slope_path)
      add_option(t, "--slope", o->slope_path);
    if (o->slope_path && o->slope_lit) {
      char az[40], el[40], both[96];
      double_text(o->slope_lit_azimuth, az, sizeof az);
      double_text(o->slope_lit_elevation, el, sizeof el);
      snprintf(both, sizeof both, "%s,%s", az, el);
      add_option(t, "--lit", both);
    }
    return;
  }
  add_option(t, "--out-dir", o->out_dir);
  const unsigned maps = o->maps ? o->maps : BB_JOB_DEFAULT_MAPS;
  if (maps != BB_JOB_DEFAULT_MAPS) {
    char list[128] = "";
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
      if (maps & BB_MAP_BIT(k))
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", list[0] ? "," : "",
                 bb_map_kind_get((bb_map_kind)k)->name);
    add_option(t, "--maps", list);
  }
  if (o->name_template)
    add_option(t, "--name", o->name_template);
}

/* The engine textures' settings and the Source material, last in --help.
 * threads is left out: the bytes are the same for any count. */
static void add_texture(bb__text *t, const bb_job_options *o) {
  bb_texture_options d;
  bb_texture_options_init(&d);
  const bb_texture_options *x = &o->texture;
  if (x->format != d.format)
    add_option(t, "--texture-format", bb_texture_format_name(x->format));
  if (x->vtf_version != d.vtf_version) {
    char version[24];
    snprintf(version, sizeof version, "7.%d", x->vtf_version);
    add_option(t, "--vtf-version", version);
  }
  if (x->vtf_flags != d.vtf_flags) {
    char flags[24];
    snprintf(flags, sizeof flags, "0x%x", (unsigned)x->vtf_flags);
    add_option(t, "--vtf-flags", flags);
  }
  if (!x->mips)
    add_option(t, "--nomip", NULL);
  if (x->fast)
    add_option(t, "--fast-compression", NULL);
  if (o->vmt)
    add_option(t, "--vmt", o->vmt);
  if (o->vmt_materials)
    add_option(t, "--materials", o->vmt_materials);
  if (o->vmt_basetexture)
    add_option(t, "--basetexture", o->vmt_basetexture);
}

char *bb_job_command_text(const bb_job_options *o, const char *input) {
  if (!o || !input)
    return NULL;
  bb__text t = {0};
  bb__text_add(&t, "bumpbake bake ");
  bb__text_add_word(&t, input);
  add_settings(&t, o);
  add_outputs(&t, o);
  add_texture(&t, o);
  if (t.failed) {
    free(t.data);
    return NULL;
  }
  return t.data;
}

char *bb__job_command_of(const bb_job *job, const bb__job_item *item) {
  if (job->command)
    return strdup(job->command);
  if (!job->command_options) {
    bb_job_options as_given = job->options; /* rays spelled as asked, not resolved */
    as_given.bake.slices = job->asked_slices;
    return bb_job_command_text(&as_given, item->input);
  }
  /* "bumpbake bake INPUT OPTIONS", as a batch run by hand records it (the
   * options as the caller's record quoted them, or as bb__add_options
   * does). */
  bb__text t = {0};
  bb__text_add(&t, "bumpbake bake ");
  bb__text_add_word(&t, item->input);
  if (job->command_options[0]) {
    bb__text_add(&t, " ");
    bb__text_add(&t, job->command_options);
  }
  if (t.failed) {
    free(t.data);
    return NULL;
  }
  return t.data;
}
