/* test_output_kind.c: the library's table of map kinds (bb_map_kind_info),
 * the first BB_MAP_BAKED_COUNT of which a bake makes. */
#include <criterion/criterion.h>

#include <string.h>

#include "bake/bake_internal.h"
#include "bumpbake.h"
#include "core/internal.h"
#include "trace/basis.h"

Test(output_kind, table_lists_every_kind_in_enum_order) {
  static const char *names[] = {"normal", "weights",  "ssbump", "ao",
                                "bent",   "filtered", "slope",  "plain"};
  static const int channels[] = {3, 0, 0, 1, 3, 1, 1, 0};
  static const int file_channels[] = {3, 3, 3, 1, 3, 1, 1, 1};
  static const bb_range ranges[] = {BB_RANGE_SIGNED, BB_RANGE_UNIT, BB_RANGE_UNIT,
                                    BB_RANGE_UNIT,   BB_RANGE_SIGNED, BB_RANGE_UNIT,
                                    BB_RANGE_UNIT,   BB_RANGE_UNIT};
  static const uint32_t vtf_flags[] = {BB_VTF_FLAG_NORMAL, BB_VTF_FLAG_SSBUMP,
                                       BB_VTF_FLAG_SSBUMP, 0, BB_VTF_FLAG_NORMAL, 0, 0, 0};
  cr_assert_eq(BB_MAP_BAKED_COUNT, 6);
  cr_assert_eq(BB_MAP_KIND_COUNT, 8);
  unsigned traced = 0;
  for (int k = 0; k < BB_MAP_KIND_COUNT; k++) {
    const bb_map_kind_info *info = bb_map_kind_get((bb_map_kind)k);
    cr_assert_not_null(info);
    cr_assert_str_eq(info->name, names[k]);
    cr_assert_str_eq(bb__map_kind_name((bb_map_kind)k), names[k]);
    cr_assert(info->description && info->description[0]);
    cr_assert_eq(info->channels, channels[k], "%s", names[k]);
    cr_assert_eq(info->file_channels, file_channels[k], "%s", names[k]);
    cr_assert_eq(info->range, ranges[k], "%s", names[k]);
    cr_assert_eq(info->unit_vectors, info->range == BB_RANGE_SIGNED, "%s", names[k]);
    cr_assert_eq(info->vtf_flags, vtf_flags[k], "%s", names[k]);
    if (info->needs_trace)
      traced |= BB_MAP_BIT(k);
    bb_map_kind parsed = BB_MAP_KIND_COUNT;
    cr_assert_eq(bb__map_kind_parse(names[k], &parsed, NULL), 0);
    cr_assert_eq((int)parsed, k);
  }
  cr_assert_eq(traced, BB_MAPS_TRACED);
  cr_assert_eq(BB_MAPS_BAKED, 0x3fu);
}

Test(output_kind, unknown_kinds_are_refused) {
  cr_assert_null(bb_map_kind_get(BB_MAP_KIND_COUNT));
  cr_assert_null(bb_map_kind_get((bb_map_kind)-1));
  cr_assert_str_eq(bb__map_kind_name(BB_MAP_KIND_COUNT), "unknown");
  bb_map_kind k = BB_MAP_AO;
  cr_assert_eq(bb__map_kind_parse("shadow", &k, NULL), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__map_kind_parse(NULL, &k, NULL), BB_ERR_ARGUMENT);
  cr_assert_eq(k, BB_MAP_AO, "untouched on failure");
  cr_assert_eq(bb__map_kind_parse("Normal", &k, NULL), BB_OK, "any case");
  cr_assert_eq(k, BB_MAP_NORMAL);
}

/* Each kind's image in a result is the field of its name, and it has the
 * channels the table says (the basis' count for 0). */
Test(output_kind, result_images_match_the_table) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 9, 7, 1, NULL), BB_OK);
  for (int i = 0; i < 63; i++)
    h.pixels[i] = (float)(i % 5) / 5.0f;
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 3.0f;
  o.slices = 4;
  cr_assert_eq(bb__basis_parse("dirs:5", &o.basis, NULL), BB_OK);
  bb_bake_result r;
  bb_error err;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, &err), BB_OK, "%s", err.message);
  const bb_image *fields[] = {&r.normal, &r.weights, &r.ssbump, &r.ao, &r.bent, &r.filtered};
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    const bb_image *img = bb__bake_result_image(&r, (bb_map_kind)k);
    cr_assert_eq(img, fields[k], "kind %d", k);
    const int want = bb_map_kind_get((bb_map_kind)k)->channels;
    cr_assert_eq(img->channels, want ? want : 5, "kind %d", k);
  }
  cr_assert_null(bb__bake_result_image(&r, BB_MAP_BAKED_COUNT));
  cr_assert_null(bb__bake_result_image(NULL, BB_MAP_NORMAL));
  bb_bake_result_free(&r);
  bb_image_free(&h);
}
