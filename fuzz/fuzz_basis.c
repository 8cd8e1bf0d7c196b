/* fuzz_basis.c: basis files (bb__basis_read_text) on any text. Properties: no
 * crash or overflow; a basis read is 3..16 unit vectors with z >= 0 named
 * "vectors:" and its hash, the same text reads to the same bits twice, and
 * a refusal says which line ("SOURCE:LINE: ..."). */
#include "bumpbake.h"
#include "fuzz_common.h"
#include "trace/basis.h"

#include <math.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size > 1 << 16)
    return 0;
  char *text = malloc(size + 1);
  if (!text)
    abort();
  memcpy(text, data, size);
  text[size] = '\0';
  bb_basis a, b;
  bb_error err = {{0}};
  bb_status st = bb__basis_read_text(text, "fuzz", &a, &err);
  if (st == BB_OK) {
    FUZZ_CHECK(a.count >= 3 && a.count <= BB_MAX_BASIS);
    FUZZ_CHECK(strncmp(a.name, "vectors:", 8) == 0);
    for (int c = 0; c < a.count; c++) {
      const double *v = a.vector[c];
      FUZZ_CHECK(fabs(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] - 1.0) < 1e-9);
      FUZZ_CHECK(v[2] >= 0.0);
    }
    FUZZ_CHECK(bb__basis_read_text(text, "fuzz", &b, NULL) == BB_OK);
    FUZZ_CHECK(memcmp(a.vector, b.vector, sizeof a.vector) == 0);
    FUZZ_CHECK(strcmp(a.name, b.name) == 0);
  } else {
    FUZZ_CHECK(st == BB_ERR_ARGUMENT || st == BB_ERR_FORMAT);
    FUZZ_CHECK(strncmp(err.message, "fuzz", 4) == 0);
  }
  free(text);
  return 0;
}
