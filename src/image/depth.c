/* depth.c: the names of sample depths, as the command line's --depth, the
 * provenance's command and Python spell them, and as messages say them. */
#include "core/internal.h"
#include "image/oiio.h"

#include <stddef.h>

/* By bb_depth; BB_DEPTH_DEFAULT is no word a user types. */
static const char *const DEPTH_NAMES[] = {NULL, "8", "16", "half", "float"};
#define DEPTH_COUNT ((int)(sizeof DEPTH_NAMES / sizeof DEPTH_NAMES[0]))

bb_status bb__depth_parse(const char *name, bb_depth *out, bb_error *err) {
  int i;
  bb_status st = bb__parse_name("depth", name, DEPTH_NAMES, DEPTH_COUNT, 0, &i, err);
  if (st == BB_OK)
    *out = (bb_depth)i;
  return st;
}

const char *bb__depth_words(int depth) {
  switch (depth) {
  case BB_DEPTH_DEFAULT: return "default";
  case BB_DEPTH_8: return "8-bit";
  case BB_DEPTH_16: return "16-bit";
  case BB_DEPTH_HALF: return "half float";
  case BB_DEPTH_FLOAT: return "float";
  }
  return "unknown";
}

const char *bb__depth_name(bb_depth depth) {
  if (depth == BB_DEPTH_DEFAULT)
    return "default";
  if ((int)depth < 0 || (int)depth >= DEPTH_COUNT)
    return "unknown";
  return DEPTH_NAMES[depth];
}
