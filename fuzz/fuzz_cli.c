/* fuzz_cli.c: every command's option parser and output checks, through
 * the real entry point (bb_cli_command, the generic driver). The first byte picks the
 * command; the rest is its arguments, separated by NUL bytes.
 *
 * Safety: the process works in an empty scratch directory and inputs
 * holding a '/' are skipped, so no argument can name a file outside it
 * ("--base .." lets program read, never write, one level up); no image
 * exists there, so nearly every run stops at loading its input, before
 * anything is written (program's _flat needs none; it writes into the
 * scratch directory). What is fuzzed is everything before that: getopt
 * tables, number parsing and ranges, prefix expansion, output-name checks,
 * compare's own parser, program's expression parser. Properties: no crash,
 * leak or undefined behaviour, and only the documented exit codes. */
#include "cli/cli.h"
#include "fuzz_common.h"

static const struct {
  const char *name;
  int max_exit; /* compare follows idiff: up to 4 */
} COMMANDS[] = {
    {"normal", 2},         {"bake", 2},   {"height2ssbump", 2}, {"compare", 4},
    {"info", 2},           {"renderbumpflat", 2}, {"render", 2}, {"sheet", 2},
    {"normal2ssbump", 2},  {"ssbump2normal", 2},  {"combine", 2}, {"program", 2},
};

enum { MAX_ARGS = 48 };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1 || size > 4096 || memchr(data, '/', size))
    return 0;
  static int in_scratch;
  if (!in_scratch) {
    if (chdir(fuzz_scratch_dir()) != 0)
      abort();
    in_scratch = 1;
  }
  const int which = data[0] % (int)(sizeof COMMANDS / sizeof COMMANDS[0]);
  /* The arguments live in one writable buffer (getopt permutes argv). */
  char *text = malloc(size);
  if (!text)
    abort();
  memcpy(text, data + 1, size - 1);
  text[size - 1] = '\0';
  char *argv[MAX_ARGS + 2];
  int argc = 0;
  argv[argc++] = (char *)COMMANDS[which].name;
  for (char *p = text; p < text + size - 1 && argc <= MAX_ARGS; p += strlen(p) + 1)
    argv[argc++] = p;
  argv[argc] = NULL;

  int code = bb_cli_command(argc, argv);
  FUZZ_CHECK(code >= 0 && code <= COMMANDS[which].max_exit);
  free(text);
  return 0;
}
