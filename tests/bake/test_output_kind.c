/* test_output_kind.c: the library's table of the maps a bake makes. */
#include <criterion/criterion.h>

#include <string.h>

#include "bumpbake.h"

Test(output_kind, table_lists_every_kind_in_enum_order) {
  static const char *names[] = {"normal", "weights", "ssbump", "ao", "bent", "filtered"};
  static const int channels[] = {3, 0, 0, 1, 3, 1};
  static const bb_range ranges[] = {BB_RANGE_SIGNED, BB_RANGE_UNIT, BB_RANGE_UNIT,
                                    BB_RANGE_UNIT,   BB_RANGE_SIGNED, BB_RANGE_UNIT};
  cr_assert_eq(BB_OUTPUT_KIND_COUNT, 6);
  unsigned traced = 0;
  for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++) {
    const bb_output_kind_info *info = bb_output_kind_get((bb_output_kind)k);
    cr_assert_not_null(info);
    cr_assert_str_eq(info->name, names[k]);
    cr_assert(info->description && info->description[0]);
    cr_assert_eq(info->channels, channels[k], "%s", names[k]);
    cr_assert_eq(info->range, ranges[k], "%s", names[k]);
    if (info->needs_trace)
      traced |= BB_OUTPUT_BIT(k);
    bb_output_kind parsed = BB_OUTPUT_KIND_COUNT;
    cr_assert_eq(bb_output_kind_parse(names[k], &parsed, NULL), 0);
    cr_assert_eq((int)parsed, k);
  }
  cr_assert_eq(traced, BB_OUTPUTS_TRACED);
  cr_assert_eq(BB_OUTPUTS_ALL, 0x3fu);
}

Test(output_kind, unknown_kinds_are_refused) {
  cr_assert_null(bb_output_kind_get(BB_OUTPUT_KIND_COUNT));
  cr_assert_null(bb_output_kind_get((bb_output_kind)-1));
  bb_output_kind k = BB_OUTPUT_AO;
  cr_assert_eq(bb_output_kind_parse("shadow", &k, NULL), BB_ERR_ARGUMENT);
  cr_assert_eq(bb_output_kind_parse("Normal", &k, NULL), BB_ERR_ARGUMENT);
  cr_assert_eq(bb_output_kind_parse(NULL, &k, NULL), BB_ERR_ARGUMENT);
  cr_assert_eq(k, BB_OUTPUT_AO, "untouched on failure");
}

/* Each kind's image in a result is the field of its name, and it has the
 * channels the table says (the basis' count for 0). */
Test(output_kind, result_images_match_the_table) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 9, 7, 1, NULL), BB_OK);
  for (int i = 0; i < 63; i++)
    h.pixels[i] = (float)(i % 5) / 5.0f;
  bb_bake_options o;
  bb_bake_options_init(&o);
  o.height_scale = 3.0f;
  o.slices = 4;
  cr_assert_eq(bb_basis_parse("dirs:5", &o.basis, NULL), BB_OK);
  bb_bake_result r;
  bb_error err;
  cr_assert_eq(bb_bake(&h, &o, &r, &err), BB_OK, "%s", err.message);
  const bb_image *fields[] = {&r.normal, &r.weights, &r.ssbump, &r.ao, &r.bent, &r.filtered};
  for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++) {
    const bb_image *img = bb_bake_result_image(&r, (bb_output_kind)k);
    cr_assert_eq(img, fields[k], "kind %d", k);
    const int want = bb_output_kind_get((bb_output_kind)k)->channels;
    cr_assert_eq(img->channels, want ? want : 5, "kind %d", k);
  }
  cr_assert_null(bb_bake_result_image(&r, BB_OUTPUT_KIND_COUNT));
  cr_assert_null(bb_bake_result_image(NULL, BB_OUTPUT_NORMAL));
  bb_bake_result_free(&r);
  bb_image_free(&h);
}
