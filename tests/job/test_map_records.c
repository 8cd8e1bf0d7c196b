/* test_map_records.c: what a map's provenance records (bb__map_kind_records)
 * held to the pixels: every kind baked with each parameter changed, a key
 * recorded exactly when the kind's pixels change; and the rule followed by
 * the writer, the up-to-date check and the diff, also against a text
 * written before the rule (every key recorded). */
#include "bake/bake_internal.h"
#include "job/job_internal.h"
#include "bumpbake.h"
#include "core/internal.h"
#include "files/provenance.h"
#include "image/image_write.h"
#include "maps/maps_internal.h"
#include "trace/basis.h"

#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum { W = 40, H = 36 };

/* A rough height field: sums of sines, no symmetry for a parameter to hide
 * behind, and a grain under the smoothing's threshold for it to take out. */
static void make_height(bb_image *h) {
  cr_assert_eq(bb_image_alloc(h, W, H, 1, NULL), BB_OK);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++)
      h->pixels[y * W + x] =
          (float)(0.5 + 0.25 * sin(0.7 * x + 0.3 * y) +
                  0.2 * cos(1.3 * y - 0.4 * x) * sin(0.21 * x * y) +
                  1.5 / 255.0 * ((double)((x * 7919 + y * 104729) % 17) / 8.0 - 1.0));
}

static void make_grey(bb_image *g, float base) {
  cr_assert_eq(bb_image_alloc(g, W, H, 1, NULL), BB_OK);
  for (int i = 0; i < W * H; i++)
    g->pixels[i] = base + 0.4f * (float)((i * 7919) % 13) / 13.0f;
}

static bb_bake_options base_options(void) {
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 12.0f;
  o.rays = 64;
  o.trace.threads = 2;
  o.outputs = BB_MAPS_BAKED;
  return o;
}

/* The maps of a bake, and the slope map of its filtered height (as the job
 * makes it), by kind. */
typedef struct maps {
  bb_bake_result r;
  bb_image slope;
} maps;

static void bake(const bb_image *h, const bb_bake_options *o, maps *m) {
  bb_error err = {{0}};
  cr_assert_eq(bb__bake_checked(h, o, &m->r, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb__slope_map(&m->r.filtered, o->height_scale, o->smooth.addressing,
                            &m->slope, &err),
               BB_OK, "%s", err.message);
}

static const bb_image *image_of(const maps *m, bb_map_kind k) {
  return k == BB_MAP_SLOPE ? &m->slope : bb__bake_result_image(&m->r, k);
}

static void maps_free(maps *m) {
  bb_bake_result_free(&m->r);
  bb_image_free(&m->slope);
}

static int same_pixels(const bb_image *a, const bb_image *b) {
  if (a->width != b->width || a->height != b->height || a->channels != b->channels)
    return 0;
  const size_t n = (size_t)a->width * (size_t)a->height * (size_t)a->channels;
  return memcmp(a->pixels, b->pixels, n * sizeof(float)) == 0;
}

/* One parameter changed, and the provenance key that records it. */
typedef struct change {
  const char *key;
  void (*apply)(bb_bake_options *o);
} change;

static bb_image albedo_map, brightness_map;

static void more_scale(bb_bake_options *o) {
  o->height_scale = 13.0f;
}
static void more_rays(bb_bake_options *o) {
  o->rays = 81;
}
static void less_radius(bb_bake_options *o) {
  o->smooth.radius_texels = 0;
}
static void more_threshold(bb_bake_options *o) {
  o->smooth.threshold = 0.05f;
}
static void more_bias(bb_bake_options *o) {
  o->trace.bias_texels = 1.5;
}
static void more_power(bb_bake_options *o) {
  o->power = 2.0;
}
static void other_basis(bb_bake_options *o) {
  cr_assert_eq(bb__basis_parse("dirs:4", &o->basis, NULL), BB_OK);
}
static void other_filter(bb_bake_options *o) {
  o->normal_filter = BB_NORMAL_SOBEL;
}
static void green_up(bb_bake_options *o) {
  o->normal_y_up = 1;
}
static void clamped(bb_bake_options *o) {
  o->smooth.addressing = BB_ADDRESS_CLAMP;
}
static void bounced(bb_bake_options *o) {
  o->bounce_albedo = 0.6;
}
static void two_bounces(bb_bake_options *o) {
  o->bounces = 2;
}
static void albedo(bb_bake_options *o) {
  o->bounce_albedo_map = &albedo_map;
}
static void brighter(bb_bake_options *o) {
  o->brightness = &brightness_map;
}

static const change changes[] = {
    {"scale", more_scale},
    {"rays", more_rays},
    {"filter_radius", less_radius},
    {"filter_threshold", more_threshold},
    {"bias", more_bias},
    {"power", more_power},
    {"basis", other_basis},
    {"normal_filter", other_filter},
    {"normal_y", green_up},
    {"addressing", clamped},
    {"bounce", bounced},
    {"brightness", brighter},
};

static const bb_map_kind kinds[] = {BB_MAP_NORMAL, BB_MAP_WEIGHTS, BB_MAP_SSBUMP,
                                    BB_MAP_AO,     BB_MAP_BENT,    BB_MAP_FILTERED,
                                    BB_MAP_SLOPE};

/* Every kind against every change from base (bounce: the base bounces),
 * the key recorded exactly when the pixels change. */
static void hold_rule(const bb_bake_options *base, int bounce, const change *c,
                      size_t count) {
  bb_image h;
  make_height(&h);
  maps before;
  bake(&h, base, &before);
  for (size_t i = 0; i < count; i++) {
    bb_bake_options o = *base;
    c[i].apply(&o);
    maps after;
    bake(&h, &o, &after);
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
      const char *kind = bb__map_kind_name(kinds[k]);
      const int changed =
          !same_pixels(image_of(&before, kinds[k]), image_of(&after, kinds[k]));
      const int recorded =
          bb__map_kind_records(kind, c[i].key, bounce || o.bounce_albedo > 0);
      cr_expect_eq(changed, recorded, "%s%s: %s %s the pixels but the rule says %s",
                   bounce ? "with inter-reflection, " : "", kind, c[i].key,
                   changed ? "changes" : "leaves",
                   recorded ? "recorded" : "not recorded");
    }
    maps_free(&after);
  }
  maps_free(&before);
  bb_image_free(&h);
}

Test(map_records, a_key_is_recorded_exactly_when_it_changes_the_pixels) {
  make_grey(&albedo_map, 0.3f);
  make_grey(&brightness_map, 0.5f);
  bb_bake_options o = base_options();
  hold_rule(&o, 0, changes, sizeof changes / sizeof changes[0]);
  bb_image_free(&albedo_map);
  bb_image_free(&brightness_map);
}

/* With inter-reflection the lobes weigh the light ao gathers: its power
 * and basis count then, and the bounce's own settings. */
Test(map_records, with_inter_reflection_ao_depends_on_the_lobes) {
  make_grey(&albedo_map, 0.3f);
  const change bounce_changes[] = {
      {"power", more_power},           {"basis", other_basis},
      {"normal_filter", other_filter}, {"bounces", two_bounces},
      {"bounce_albedo_map", albedo},   {"bias", more_bias}};
  bb_bake_options o = base_options();
  o.bounce_albedo = 0.6;
  hold_rule(&o, 1, bounce_changes, sizeof bounce_changes / sizeof bounce_changes[0]);
  bb_image_free(&albedo_map);
}

Test(map_records, kinds_of_parts_and_unknown_kinds) {
  /* Valve's packed files record what any part records */
  cr_assert(bb__map_kind_records("ssbump+height", "normal_filter", 0));
  cr_assert(!bb__map_kind_records("ssbump+height", "normal_y", 0));
  cr_assert(bb__map_kind_records("normal+height", "normal_y", 0));
  cr_assert(!bb__map_kind_records("normal+height", "rays", 0));
  cr_assert(bb__map_kind_records("normal+ao", "rays", 0));
  cr_assert(!bb__map_kind_records("detail-ssbump+height", "normal_y", 0));
  /* what is not a bake's parameter, and what is not a bake's map, is kept */
  cr_assert(bb__map_kind_records("normal", "bumpbake_version", 0));
  cr_assert(bb__map_kind_records("normal", "input_file_hash", 0));
  cr_assert(bb__map_kind_records("normal", "texture_format", 0));
  cr_assert(bb__map_kind_records("render", "rays", 0));
  cr_assert(bb__map_kind_records("normal+coverage", "rayset", 0));
  cr_assert(bb__map_kind_records(NULL, "rays", 0));
  cr_assert(!bb__map_kind_records("normal", NULL, 0));
}

/* ------------------------------------------------- the rule in use */

static char *describe(const char *kind, const bb_bake_options *o, const char *rayset) {
  const bb_provenance p = {"bumpbake bake h.png", "h.png", 0x1234, kind, o,
                           BB_CHANNEL_AUTO,       rayset,  0xfeed, NULL};
  char *text = bb__provenance_format(&p);
  cr_assert_not_null(text);
  return text;
}

Test(map_records, a_normal_map_records_no_trace_and_ao_its_slices) {
  bb_bake_options o = base_options();
  char *normal = describe("normal", &o, "bb-horizon-v1:a8:p1:hl2");
  for (const char *const *k = (const char *const[]){"\nrays=", "\nrayset=", "\nbias=",
                                                    "\npower=", "\nbasis=", NULL};
       *k; k++)
    cr_expect_null(strstr(normal, *k), "%s in\n%s", *k, normal);
  cr_expect_not_null(strstr(normal, "\nnormal_y=down\n"), "%s", normal);
  char *ao = describe("ao", &o, "bb-horizon-v1:a8:p1:hl2");
  cr_expect_not_null(strstr(ao, "\nrayset=bb-horizon-v1:a8\n"), "%s", ao);
  cr_expect_null(strstr(ao, "\nnormal_filter="), "%s", ao);
  o.bounce_albedo = 0.5;
  char *bounced_ao = describe("ao", &o, "bb-horizon-v1:a8:p1:hl2");
  cr_expect_not_null(strstr(bounced_ao, "\nrayset=bb-horizon-v1:a8:p1:hl2\n"), "%s",
                     bounced_ao);
  cr_expect_not_null(strstr(bounced_ao, "\npower=1\n"), "%s", bounced_ao);
  /* a map of another command, without bake options, as it always was */
  const bb_provenance other = {"bumpbake ssbump2normal s.png",
                               "s.png",
                               1,
                               "normal",
                               NULL,
                               BB_CHANNEL_AUTO,
                               NULL,
                               0,
                               NULL};
  char *text = bb__provenance_format(&other);
  cr_expect_not_null(strstr(text, "\nrayset=none\n"), "%s", text);
  free(text);
  free(normal);
  free(ao);
  free(bounced_ao);
}

/* A golden written before the rule recorded every key: its diff against
 * a map made now lists only what the map depends on. */
/* A text as bumpbake 0.4 wrote it, every key recorded whatever the kind. */
static void old_text(char *out, size_t cap, const char *kind) {
  snprintf(out, cap,
           "bumpbake_version=0.4.0\ncommand=bumpbake bake h.png\ninput=h.png\n"
           "input_hash=0000000000001234\ninput_file_hash=000000000000feed\n"
           "output=%s\nscale=12\nrays=256\nrayset=bb-horizon-v1:a16:p1:hl2\n"
           "filter_radius=10\nfilter_threshold=0.00784313772\nbias=0.55\n"
           "power=1\nbasis=hl2\nnormal_filter=vertex\nnormal_y=down\n"
           "addressing=periodic\nchannel=auto\n",
           kind);
}

/* A golden written before the rule recorded every key: its diff against
 * a map made now lists only what the map depends on. */
Test(map_records, a_diff_against_a_text_with_every_key_lists_what_counts) {
  const int same_version = strcmp(BB_VERSION_STRING, "0.4.0") == 0;
  char old_normal[1024], old_ao[1024], out[512];
  old_text(old_normal, sizeof old_normal, "normal");
  old_text(old_ao, sizeof old_ao, "ao");
  bb_bake_options o = base_options(); /* rays 64: another ray set */
  char *now = describe("normal", &o, NULL);
  int n = bb__provenance_diff(old_normal, now, out, sizeof out);
  cr_expect(same_version ? n == 0 : n == 1 && strstr(out, "bumpbake_version:"), "%s",
            out);
  /* as an ao: rays and the ray set's slices count, the lobes of its id do
   * not, nor the normals' keys */
  char *ao = describe("ao", &o, "bb-horizon-v1:a8:p2:dirs:5");
  n = bb__provenance_diff(old_ao, ao, out, sizeof out);
  cr_expect(strstr(out, "rays: 256 -> 64\n") &&
                strstr(out, "rayset: bb-horizon-v1:a16 -> "
                            "bb-horizon-v1:a8\n"),
            "%s", out);
  cr_expect_eq(n, same_version ? 2 : 3, "%s", out);
  o.rays = 256;
  char *ao_256 = describe("ao", &o, "bb-horizon-v1:a16:p2:dirs:5");
  n = bb__provenance_diff(old_ao, ao_256, out, sizeof out);
  cr_expect_eq(n, same_version ? 0 : 1, "%s", out);
  free(now);
  free(ao);
  free(ao_256);
}

/* The up-to-date check of a file written before the rule: current when
 * only keys its kind does not record differ. */
Test(map_records, a_file_with_every_key_is_current_when_only_those_differ) {
  char dir[] = "/tmp/bb-records-XXXXXX";
  cr_assert_not_null(mkdtemp(dir));
  char path[64], text[1024], reason[200];
  snprintf(path, sizeof path, "%s/n.exr", dir);
  old_text(text, sizeof text, "normal");
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 4, 4, 3, NULL), BB_OK);
  const bb_write_options wo = {BB_DEPTH_DEFAULT, BB_RANGE_SIGNED, text, NULL};
  cr_assert_eq(bb__image_write(path, &img, &wo, NULL), BB_OK);
  bb_bake_options o = base_options();
  o.rays = 9;
  o.power = 3;
  const bb_provenance want = {
      "x",    "h.png", 0x1234, "normal", &o, BB_CHANNEL_AUTO, "bb-horizon-v1:a3:p3:hl2",
      0xfeed, NULL};
  bb_output_state state;
  cr_assert_eq(bb__output_check(path, &want, BB_DEPTH_DEFAULT, 0, &state, reason,
                               sizeof reason, NULL),
               BB_OK);
  if (strcmp(BB_VERSION_STRING, "0.4.0") == 0)
    cr_expect_eq(state, BB_OUTPUT_CURRENT, "%s", reason);
  else
    cr_expect(state == BB_OUTPUT_STALE && strstr(reason, "bumpbake_version"), "%s",
              reason);
  o.normal_filter = BB_NORMAL_VALVE;
  cr_assert_eq(bb__output_check(path, &want, BB_DEPTH_DEFAULT, 0, &state, reason,
                               sizeof reason, NULL),
               BB_OK);
  cr_expect_eq(state, BB_OUTPUT_STALE);
  bb_image_free(&img);
  unlink(path);
  rmdir(dir);
}
