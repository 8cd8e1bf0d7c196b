/* renderbump_notes.c: what a flat render bump tells its caller: that its
 * texels are not square, and the size or rectangle that would make them so. */
#include "mesh/renderbump_notes.h"

#include <math.h>
#include <stdio.h>

void bb__renderbump_notes(const bb_renderbump_options *o, const bb_renderbump_result *r) {
  if (!o->note || fabs(r->texel_aspect - 1.0) <= 0.01)
    return;
  /* Square texels: the size whose texels match the rectangle's shape, or
   * the rectangle grown along its short side to match the size. */
  const double w = r->rect[2] - r->rect[0], h = r->rect[3] - r->rect[1];
  long width = o->width, height = o->height;
  double rect[4] = {r->rect[0], r->rect[1], r->rect[2], r->rect[3]};
  if (r->texel_aspect > 1.0) {
    width = lround((double)o->height * w / h);
    rect[3] = r->rect[1] + w * o->height / o->width;
  } else {
    height = lround((double)o->width * h / w);
    rect[2] = r->rect[0] + h * o->width / o->height;
  }
  char text[512];
  snprintf(text, sizeof text,
           "texels are %.4g times as wide as high (a %g x %g rectangle on %d x %d texels), "
           "so round features come out stretched; size %ld %ld, or rect %g %g %g %g, keeps "
           "them square",
           r->texel_aspect, w, h, o->width, o->height, width < 1 ? 1 : width,
           height < 1 ? 1 : height, rect[0], rect[1], rect[2], rect[3]);
  o->note(o->note_user, NULL, text);
}
