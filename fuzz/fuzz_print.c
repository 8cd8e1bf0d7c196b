/* fuzz_print.c: what info and compare print about files they did not make:
 * the input is a description stored in a small PNG (as a provenance text,
 * or another tool's) and a fragment of its file name. info, info --json and
 * compare run in-process with stdout and stderr in a scratch file.
 * Properties: no crash or overflow; the text printed for a human holds no
 * control character but newlines (nothing can drive a terminal); --json is
 * valid UTF-8 with one object per line. */
#include "bumpbake.h"
#include "cli/cli.h"
#include "fuzz_common.h"
#include "printed_text.h"
#include "image/image_write.h"

#include <fcntl.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Runs fn(argc, argv) with stdout and stderr in a scratch file; returns
 * what it printed (malloc'd). */
static char *captured(int (*fn)(int, char **), int argc, char **argv) {
  char path[128];
  snprintf(path, sizeof path, "%s/printed.txt", fuzz_scratch_dir());
  fflush(stdout);
  fflush(stderr);
  int out = dup(1), err = dup(2), fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
  if (out < 0 || err < 0 || fd < 0)
    abort();
  dup2(fd, 1);
  dup2(fd, 2);
  close(fd);
  fn(argc, argv);
  fflush(stdout);
  fflush(stderr);
  dup2(out, 1);
  dup2(err, 2);
  close(out);
  close(err);
  FILE *f = fopen(path, "rb");
  if (!f)
    abort();
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  rewind(f);
  char *text = malloc((size_t)n + 1);
  if (!text || fread(text, 1, (size_t)n, f) != (size_t)n)
    abort();
  text[n] = '\0';
  fclose(f);
  return text;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1 || size > 8192)
    return 0;
  /* The first byte: how many of the last bytes are the file name's. */
  size_t name_len = data[0] % 24;
  if (name_len + 1 > size)
    name_len = size - 1;
  const size_t text_len = size - 1 - name_len;
  char *text = malloc(text_len + 1);
  if (!text)
    abort();
  memcpy(text, data + 1, text_len);
  text[text_len] = '\0';
  char name[64] = "p";
  for (size_t i = 0; i < name_len; i++) {
    unsigned char c = data[1 + text_len + i];
    name[1 + i] = (char)(c == '/' || c == 0 ? '_' : c);
  }
  strcpy(name + 1 + name_len, ".png");
  char path[256];
  snprintf(path, sizeof path, "%s/%s", fuzz_scratch_dir(), name);
  bb_image img;
  if (bb_image_alloc(&img, 2, 2, 1, NULL) != BB_OK)
    abort();
  const bb_write_options wo = {BB_DEPTH_8, BB_RANGE_UNIT, text, NULL};
  if (bb__image_write(path, &img, &wo, NULL) == BB_OK) {
    char *info[] = {"info", path, NULL};
    char *printed = captured(bb_cli_command, 2, info);
    FUZZ_CHECK(!has_control(printed));
    free(printed);
    char *json[] = {"info", "--json", path, NULL};
    printed = captured(bb_cli_command, 3, json);
    FUZZ_CHECK(valid_utf8(printed));
    free(printed);
    char *compare[] = {"compare", path, path, NULL};
    printed = captured(bb_cli_command, 3, compare);
    FUZZ_CHECK(!has_control(printed));
    free(printed);
    unlink(path);
  }
  bb_image_free(&img);
  free(text);
  return 0;
}
