/* ranges.c: the one check of a value against its range, and the one way
 * a number is spelled in messages and help, so every parameter of the
 * library is refused with the same words by every caller. */
#include "core/internal.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

void bb__number_text(double v, char *out, size_t cap) {
  if (!cap)
    return;
  if (isnan(v)) {
    snprintf(out, cap, "nan");
    return;
  }
  snprintf(out, cap, "%g", v);
  /* "1e+06" reads as "1e6", as a user types it */
  char *e = strchr(out, 'e');
  if (!e)
    return;
  char *digits = e + 1;
  const int negative = *digits == '-';
  if (*digits == '+' || *digits == '-')
    digits++;
  while (*digits == '0' && digits[1])
    digits++;
  char tail[16];
  snprintf(tail, sizeof tail, "%s%s", negative ? "-" : "", digits);
  snprintf(e + 1, cap - (size_t)(e + 1 - out), "%s", tail);
}

void bb__range_text(const bb__range *r, char *out, size_t cap) {
  char lo[32], hi[32];
  bb__number_text(r->min, lo, sizeof lo);
  bb__number_text(r->max, hi, sizeof hi);
  if (r->max >= HUGE_VAL || (r->max >= FLT_MAX && !r->integer))
    snprintf(out, cap, "%s %s", r->min_exclusive ? ">" : ">=", lo);
  else if (r->min <= -HUGE_VAL)
    snprintf(out, cap, "<= %s", hi);
  else if (r->min_exclusive)
    snprintf(out, cap, "> %s, <= %s", lo, hi);
  else
    snprintf(out, cap, "%s..%s", lo, hi);
}

int bb__range_holds(const bb__range *r, double v) {
  if (isnan(v) || (r->integer && v != floor(v)))
    return 0;
  if (r->min_exclusive ? !(v > r->min) : !(v >= r->min))
    return 0;
  return v <= r->max;
}

bb_status bb__range_check(const bb__range *r, double v, const char *who, bb_error *err) {
  if (bb__range_holds(r, v))
    return BB_OK;
  char range[80], got[32];
  bb__range_text(r, range, sizeof range);
  if (r->integer && v == floor(v) && fabs(v) < 1e18)
    snprintf(got, sizeof got, "%.0f", v);
  else
    bb__number_text(v, got, sizeof got);
  /* A range whose top is a float's largest shows none ("colour must be >=
   * 0"): above it, say so rather than repeat the bottom. */
  if (v > r->max && !strstr(range, "..") && !strstr(range, "<="))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s is too large: at most %s, a float's largest (got %s)",
                    who ? who : r->what, (bb__number_text(r->max, range, sizeof range), range),
                    got);
  const int interval = strstr(range, "..") != NULL;
  return bb__fail(err, BB_ERR_ARGUMENT, "%s must be %s%s (got %s)", who ? who : r->what,
                  interval ? "in " : "", range, got);
}
