/* render_compare.c: the paper's four-panel comparison: one set of maps
 * rendered four ways (bb__render) and laid out as labelled panels. */
#include "core/internal.h"
#include "render/render_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bb_status bb__render_compare(const bb_render_maps *maps, const bb_render_options *o,
                            const bb_panel_layout *l, bb_image *out, int *labels_drawn,
                            bb_error *err) {
  if (labels_drawn)
    *labels_drawn = 0;
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "compare: out is NULL");
  memset(out, 0, sizeof *out);
  if (!o || !l)
    return bb__fail(err, BB_ERR_ARGUMENT, "compare: options are NULL");
  static const struct {
    bb_render_mode mode;
    int specular;
    const char *label;
  } kinds[] = {
      {BB_RENDER_NORMAL, 0, "normal-mapped"},
      {BB_RENDER_SSBUMP, 0, "ssbump"},
      {BB_RENDER_SSBUMP, 1, "ssbump + specular"},
      {BB_RENDER_NORMAL_AO, 0, "ao"},
  };
  enum { KINDS = sizeof kinds / sizeof kinds[0] };
  bb_image renders[KINDS];
  bb_panel panels[KINDS];
  memset(renders, 0, sizeof renders);
  bb_status st = BB_OK;
  for (int i = 0; i < KINDS && st == BB_OK; i++) {
    bb_render_options po = *o;
    po.mode = kinds[i].mode;
    po.specular_exponent = !kinds[i].specular           ? 0.0
                           : o->specular_exponent > 0.0 ? o->specular_exponent
                                                        : BB_COMPARE_SPECULAR_EXPONENT;
    st = bb__render(maps, &po, &renders[i], err);
    panels[i] = (bb_panel){&renders[i], kinds[i].label};
  }
  if (st == BB_OK)
    st = bb__panels_compose(panels, KINDS, l, out, labels_drawn, err);
  for (int i = 0; i < KINDS; i++)
    bb_image_free(&renders[i]);
  return st;
}
