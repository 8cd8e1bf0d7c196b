/* bake_rows.c: the bake's options as rows (bake_rows.h): each option's
 * name, field and spelling written once, here, for the commands that read
 * and spell them (cmd/options_bake.c points at them). The special cases
 * are the rows' own printers: --basis (a file as named, else its name),
 * --maps (comma-separated), --vtf-version (7.N), --vtf-flags (hex). */
#include "job/bake_rows.h"
#include "job/job_internal.h"

#include <stdio.h>
#include <string.h>

#define AT(member) offsetof(bb_job_options, member)

/* ------------------------------------------------------------ special printers */

/* --basis: a file as named, else the basis's name. */
static void print_basis(const bb_job_options *o, bb__text *t) {
  bb__text_add(t, o->basis_file ? o->basis_file : o->bake.basis.name);
}

/* --maps: the batch's maps (0: the default ones), comma-separated. */
static unsigned maps_of(const bb_job_options *o) {
  return o->maps ? o->maps : BB_JOB_DEFAULT_MAPS;
}

static void print_maps(const bb_job_options *o, bb__text *t) {
  const unsigned maps = maps_of(o);
  int first = 1;
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    if (maps & BB_MAP_BIT(k)) {
      bb__text_printf(t, "%s%s", first ? "" : ",", bb__name_output_kind(k));
      first = 0;
    }
}

static void print_vtf_version(const bb_job_options *o, bb__text *t) {
  bb__text_printf(t, "7.%d", o->texture.vtf_version);
}

static void print_vtf_flags(const bb_job_options *o, bb__text *t) {
  bb__text_printf(t, "0x%x", (unsigned)o->texture.vtf_flags);
}

/* ------------------------------------------------------------------ rows */

#define ROW(name_, field_, member)                                                       \
  .name = name_, .field = BB__FIELD_##field_, .offset = AT(member)
#define MAP_FILE(name_, kind_)                                                           \
  { ROW(name_, STRING, paths[kind_]) }

_Static_assert(sizeof(((bb_job_options *)0)->texture.vtf_flags) == sizeof(int),
               "--vtf-flags is read as an int");

const bb__bake_row bb__row_scale = {ROW("scale", FLOAT, bake.height_scale)};
const bb__bake_row bb__row_rays = {ROW("rays", INT, bake.rays)};
const bb__bake_row bb__row_slices = {ROW("slices", INT, bake.slices)};
const bb__bake_row bb__row_filter_radius = {
    ROW("filter-radius", INT, bake.smooth.radius_texels)};
const bb__bake_row bb__row_filter_threshold = {
    ROW("filter-threshold", FLOAT, bake.smooth.threshold)};
const bb__bake_row bb__row_bias = {ROW("bias", DOUBLE, bake.trace.bias_texels)};
const bb__bake_row bb__row_power = {ROW("power", DOUBLE, bake.power)};
const bb__bake_row bb__row_basis = {
    .name = "basis", .print = print_basis};
const bb__bake_row bb__row_normal_filter = {
    ROW("normal-filter", ENUM, bake.normal_filter), .names = bb__name_normal_filter};
const bb__bake_row bb__row_normal_y = {ROW("normal-y", INT, bake.normal_y_up),
                                       .names = bb__name_normal_y};
const bb__bake_row bb__row_clamp = {
    .name = "clamp",
    .flag = 1,
    .sets = {BB__FIELD_ENUM, AT(bake.smooth.addressing), BB_ADDRESS_CLAMP, NULL}};
const bb__bake_row bb__row_channel = {ROW("channel", ENUM, channel),
                                      .names = bb__name_channel};
const bb__bake_row bb__row_depth = {ROW("depth", ENUM, depth), .names = bb__name_depth};
const bb__bake_row bb__row_mips = {ROW("mips", INT, mips), .flag = 1};
const bb__bake_row bb__row_bounce = {ROW("bounce", DOUBLE, bake.bounce_albedo)};
const bb__bake_row bb__row_bounces = {ROW("bounces", INT, bake.bounces)};
const bb__bake_row bb__row_bounce_albedo = {
    ROW("bounce-albedo", STRING, bounce_albedo_file)};
const bb__bake_row bb__row_brightness = {ROW("brightness", STRING, brightness_file)};
const bb__bake_row bb__row_normal = MAP_FILE("normal", BB_MAP_NORMAL);
const bb__bake_row bb__row_weights = MAP_FILE("weights", BB_MAP_WEIGHTS);
const bb__bake_row bb__row_ssbump = MAP_FILE("ssbump", BB_MAP_SSBUMP);
const bb__bake_row bb__row_ao = MAP_FILE("ao", BB_MAP_AO);
const bb__bake_row bb__row_bent = MAP_FILE("bent", BB_MAP_BENT);
const bb__bake_row bb__row_filtered = MAP_FILE("filtered", BB_MAP_FILTERED);
const bb__bake_row bb__row_slope = {ROW("slope", STRING, slope_path)};
const bb__bake_row bb__row_lit = {ROW("lit", ANGLES, slope_lit_azimuth),
                                  .sets = {BB__FIELD_INT, AT(slope_lit), 1, NULL}};
/* --out-dir is what makes a batch: any bake may give it. */
const bb__bake_row bb__row_out_dir = {ROW("out-dir", STRING, out_dir)};
const bb__bake_row bb__row_maps = {.name = "maps",
                                   .names = bb__name_output_kind,
                                   .print = print_maps};
const bb__bake_row bb__row_name = {ROW("name", STRING, name_template)};
const bb__bake_row bb__row_texture_format = {ROW("texture-format", ENUM, texture.format),
                                             .names = bb__name_texture_format};
const bb__bake_row bb__row_vtf_version = {ROW("vtf-version", INT, texture.vtf_version),
                                          .print = print_vtf_version};
const bb__bake_row bb__row_vtf_flags = {ROW("vtf-flags", INT, texture.vtf_flags),
                                        .print = print_vtf_flags};
const bb__bake_row bb__row_nomip = {
    .name = "nomip", .flag = 1, .sets = {BB__FIELD_INT, AT(texture.mips), 0, NULL}};
const bb__bake_row bb__row_fast_compression = {
    .name = "fast-compression",
    .flag = 1,
    .sets = {BB__FIELD_INT, AT(texture.fast), 1, NULL}};
/* One material for one bake: a batch refuses them (plan.c). */
const bb__bake_row bb__row_vmt = {ROW("vmt", STRING, vmt)};
const bb__bake_row bb__row_materials = {ROW("materials", STRING, vmt_materials)};
const bb__bake_row bb__row_basetexture = {ROW("basetexture", STRING, vmt_basetexture)};

/* --------------------------------------------------------------- reading */

static const void *at(const bb_job_options *o, size_t offset) {
  return (const char *)o + offset;
}

void bb__field_text(bb__field field, int flag, bb__name_fn names, const void *value,
                    bb__text *t) {
  char buf[48], el[48];
  switch (field) {
  case BB__FIELD_INT:
  case BB__FIELD_ENUM:
    if (names)
      bb__text_add(t, names(*(const int *)value));
    else if (!flag)
      bb__text_printf(t, "%d", *(const int *)value);
    return;
  case BB__FIELD_FLOAT:
    bb__float_text(*(const float *)value, buf, sizeof buf);
    bb__text_add(t, buf);
    return;
  case BB__FIELD_DOUBLE:
    bb__double_text(*(const double *)value, buf, sizeof buf);
    bb__text_add(t, buf);
    return;
  case BB__FIELD_STRING:
    bb__text_add(t, *(const char *const *)value);
    return;
  case BB__FIELD_ANGLES:
    bb__double_text(((const double *)value)[0], buf, sizeof buf);
    bb__double_text(((const double *)value)[1], el, sizeof el);
    bb__text_printf(t, "%s,%s", buf, el);
    return;
  case BB__FIELD_NONE:
  case BB__FIELD_KEPT:
    return;
  }
}

void bb__bake_row_value(const bb__bake_row *r, const bb_job_options *o, bb__text *t) {
  if (r->flag)
    return;
  if (r->print)
    r->print(o, t);
  else
    bb__field_text(r->field, r->flag, r->names, at(o, r->offset), t);
}
