/* test_fuzz.c: every input that once made a libFuzzer target fail
 * (fuzz/regressions/NAME/, see `make fuzz`) replayed through the target's
 * own code, compiled into this binary with LLVMFuzzerTestOneInput renamed
 * bb_fuzz_NAME. A target signals a failure by crashing (a failed property
 * aborts), which fails the test. Inputs of one target run in name order in
 * one process, since some failures need the state an earlier input left. */
#define _XOPEN_SOURCE 700 /* realpath */

#include "bumpbake.h"
#include "cli/cli.h"

#include <criterion/criterion.h>

#include <dirent.h>
#include <fcntl.h>
#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int bb_fuzz_cli(const uint8_t *data, size_t size);
int bb_fuzz_compare(const uint8_t *data, size_t size);
int bb_fuzz_load(const uint8_t *data, size_t size);
int bb_fuzz_mesh(const uint8_t *data, size_t size);
int bb_fuzz_provenance(const uint8_t *data, size_t size);

typedef int (*fuzz_target)(const uint8_t *data, size_t size);

typedef struct input {
  char name[256];
  uint8_t *data;
  size_t size;
} input;

static int by_name(const void *a, const void *b) {
  return strcmp(((const input *)a)->name, ((const input *)b)->name);
}

/* Reads every file of fuzz/regressions/NAME (before any target runs: the
 * CLI target changes directory) and returns how many, sorted by name. */
static int read_inputs(const char *name, input *inputs, int cap) {
  char dir[PATH_MAX];
  snprintf(dir, sizeof dir, "fuzz/regressions/%s", name);
  DIR *d = opendir(dir);
  cr_assert_not_null(d, "%s is missing (tests run from the project root)", dir);
  int n = 0;
  for (struct dirent *e; (e = readdir(d)) != NULL;) {
    if (e->d_name[0] == '.')
      continue;
    cr_assert_lt(n, cap);
    input *in = &inputs[n++];
    snprintf(in->name, sizeof in->name, "%s", e->d_name);
    char path[PATH_MAX + 256];
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    FILE *f = fopen(path, "rb");
    cr_assert_not_null(f, "%s", path);
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    rewind(f);
    in->data = malloc((size_t)size + 1);
    in->size = fread(in->data, 1, (size_t)size, f);
    fclose(f);
  }
  closedir(d);
  qsort(inputs, (size_t)n, sizeof inputs[0], by_name);
  return n;
}

/* The targets print what the CLI prints; the test output stays quiet. */
static void mute_output(void) {
  int null_fd = open("/dev/null", O_WRONLY);
  cr_assert(null_fd >= 0);
  fflush(NULL);
  dup2(null_fd, STDOUT_FILENO);
  dup2(null_fd, STDERR_FILENO);
  close(null_fd);
}

static void replay(const char *name, fuzz_target target, int expected_at_least) {
  input inputs[64];
  int n = read_inputs(name, inputs, 64);
  cr_assert_geq(n, expected_at_least, "fuzz/regressions/%s lost inputs", name);
  mute_output();
  for (int i = 0; i < n; i++) {
    target(inputs[i].data, inputs[i].size);
    free(inputs[i].data);
  }
}

TestSuite(fuzz, .timeout = 300);

/* getopt kept a pointer into the previous argv (freed by then) when a parse
 * stopped inside a cluster ("-xr5": unknown -x, "r5" pending); the next
 * parse read it: a heap use-after-free under ASan. */
Test(fuzz, cli_regressions) {
  replay("cli", bb_fuzz_cli, 2);
}

/* png-truncated-in-its-header: OpenImageIO 2.4 leaks an error string
 * while opening it (LeakSanitizer's report failed the target).
 * exr-attribute-with-no-type: OpenEXR's C++ reader allocated the 1.8 GB an
 * attribute of no type declared (over -malloc_limit_mb); OpenEXRCore,
 * which reads the header first now, reports it.
 * exr-attribute-name-with-a-newline: OpenEXRCore's report quoted the name,
 * newline and all: a two-line message (the target's check aborts).
 * exr-header-two-parsers-read-differently: OpenEXRCore's lenient parse
 * skipped what the C++ reader then took for a 1.6 GB attribute (the probe
 * parses strictly now).
 * gif-of-another-version-with-a-huge-screen: "GIF\x939a", which giflib
 * reads as a GIF and the probe once did not: a 1.7 GB canvas.
 * png-text-chunk-of-1.7-gb: libpng allocated and zeroed a tEXt chunk's
 * declared 1.7 GB (its 8 MB chunk limit is only a warning on read);
 * png_hooks.c bounds libpng's allocations on OpenImageIO's structs.
 * sgi-rle-row-length-of-4-gb: an RLE row length of 0xFFFFFFFF, allocated
 * at the first row read (AddressSanitizer: allocation size too big).
 * dpx-user-data-of-2.2-gb: the DPX reader allocated the declared user data
 * (past -malloc_limit_mb). softimage-unreadable-scanline-segv: the
 * Softimage reader, failing a scanline, used the FILE it had closed
 * (SIGSEGV). The PSD, IFF, FITS and JPEG 2000
 * inputs are an audit's files of the same kind (the header probe refuses
 * each: header_walk.h).
 * Replayed here without libFuzzer's memory limits: the messages and the
 * crashes are checked here, the allocations by `make fuzz`, which replays
 * them under its limits, and by tests/image/test_hostile_headers.c. */
Test(fuzz, load_regressions) {
  replay("load", bb_fuzz_load, 20);
}

/* Models that read outside their directory or crashed Assimp: an OBJ whose
 * mtllib is its own directory (Assimp lost the stream it opened on it:
 * LeakSanitizer), a glTF buffer up and out of it, Collada nodes nested
 * 3,000 deep. */
Test(fuzz, mesh_regressions) {
  replay("mesh", bb_fuzz_mesh, 3);
}

/* Nine differences near 1e27: their mean, sum / 9 in double, came out one
 * ulp above their maximum. Rounding, not a fault of compare; the target's
 * check now allows it, and this input keeps the check honest.
 * nan-on-both-sides: compare counts NaN against NaN as equal (a map that
 * is NaN where the golden is matches it); the target still expected
 * infinity there. */
Test(fuzz, compare_regressions) {
  replay("compare", bb_fuzz_compare, 2);
}

/* The same getopt fault without a sanitizer: the second, valid command line
 * took "-r 5" from the first one's leftovers and then found one argument
 * too many (exit 2) instead of reporting its missing file (exit 1). */
Test(fuzz, a_parse_forgets_the_previous_one) {
  char first[] = "-xr5", rays[] = "-r", count[] = "32", file[] = "absent.tga",
       scale[] = "2", name[] = "height2ssbump";
  char *stops_inside_a_cluster[] = {name, first, file, scale, NULL};
  char *valid[] = {name, rays, count, file, scale, NULL};
  mute_output();
  cr_assert_eq(bb_cli_command(4, stops_inside_a_cluster), 2);
  cr_assert_eq(bb_cli_command(5, valid), 1);
}
