/* test_handover.c: a checked command handed to another process
 * (bb_command_handover, what `bake --scheduler` gives bumpbake.dask) is set
 * up there again from the texts its options were set from: the same
 * command, words with blanks included; a chunk's inputs replace the
 * batch's; what is not a hand-over of this version is refused. */
#include "cmd/cmd_internal.h"
#include "bumpbake.h"
#include "bumpbake_cluster.h"

#include <criterion/criterion.h>
#include <stdlib.h>
#include <string.h>

static bb_command *bake(const char *const *inputs, const char *const (*options)[2]) {
  bb_command *c = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_command_new("bake", &c, &err), BB_OK, "%s", err.message);
  for (int i = 0; inputs[i]; i++)
    cr_assert_eq(bb_command_add_input(c, inputs[i], &err), BB_OK, "%s", err.message);
  for (int i = 0; options[i][0]; i++)
    cr_assert_eq(bb_command_set(c, options[i][0], options[i][1], &err), BB_OK, "%s: %s",
                 options[i][0], err.message);
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  return c;
}

static char *spelled(const bb_command *c) {
  char *text = bb_command_text(c, NULL, 0);
  cr_assert_not_null(text);
  return text;
}

Test(handover, gives_the_same_command) {
  const char *inputs[] = {"my heights", "b.png", NULL};
  const char *const options[][2] = {
      {"scale", "36.8083"}, {"rays", "100"},        {"bias", "0.3"},
      {"filter-threshold", "0.00784"}, {"normal-y", "up"}, {"clamp", NULL},
      {"bounce", "0.25"},   {"out-dir", "out dir"}, {"name", "{kind}/{stem} x.png"},
      {"maps", "normal,ao"}, {"force", NULL},       {"json", NULL},
      {"quiet", NULL},      {"threads", "3"},       {"scheduler", "tcp://h:8786"},
      {NULL, NULL}};
  bb_command *c = bake(inputs, options);
  bb_error err = {{0}};
  cr_assert_eq(bb_command_set_record(c, NULL, "bumpbake bake my heights ...", "--scale 36.8083", &err),
               BB_OK);
  size_t size = 0;
  char *data = bb_command_handover(c, &size);
  cr_assert(data && size > 0);

  bb_command *back = NULL;
  cr_assert_eq(bb_command_from_handover(data, size, NULL, 0, &back, &err), BB_OK, "%s",
               err.message);
  char *a = spelled(c), *b = spelled(back);
  cr_expect_str_eq(b, a);
  cr_expect_eq(bb__command_input_count(back), 2);
  cr_expect_str_eq(bb_command_input(back, 0), "my heights");
  const bb_command_options *o = bb__command_options_of(back);
  cr_expect(o->json && o->quiet, "the client's own options travel too");
  cr_expect_str_eq(o->scheduler, "tcp://h:8786");
  cr_expect_str_eq(o->job.out_dir, "out dir");
  cr_expect_eq(o->job.bake.smooth.threshold, bb__command_options_of(c)->job.bake.smooth.threshold);
  free(b);
  bb_command_free(back);

  /* a chunk of the batch: its inputs in place of the batch's */
  const char *chunk[] = {"b.png"};
  cr_assert_eq(bb_command_from_handover(data, size, chunk, 1, &back, &err), BB_OK);
  cr_expect_eq(bb__command_input_count(back), 1);
  cr_expect_str_eq(bb_command_input(back, 0), "b.png");
  bb_command_free(back);
  free(a);
  free(data);
  bb_command_free(c);
}

Test(handover, refuses_what_is_not_one) {
  const char *inputs[] = {"h.png", NULL};
  const char *const options[][2] = {{"scale", "8"}, {"normal", "n.png"}, {NULL, NULL}};
  bb_command *c = bake(inputs, options);
  size_t size = 0;
  char *data = bb_command_handover(c, &size);
  bb_command *back = (bb_command *)data; /* set to NULL on failure */
  bb_error err = {{0}};
  cr_expect_eq(bb_command_from_handover("", 0, NULL, 0, &back, &err), BB_ERR_ARGUMENT);
  cr_expect_null(back);
  cr_expect(strstr(err.message, "not a command of this bumpbake version"), "%s", err.message);
  cr_expect_eq(bb_command_from_handover(data, size - 4, NULL, 0, &back, &err), BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "cut short"), "%s", err.message);
  /* a value its parser refuses, as the command line's would be */
  const char bad[] = "bumpbake-command 1\0bake\0input\0h.png\0option\0rays\0many\0end";
  cr_expect_eq(bb_command_from_handover(bad, sizeof bad, NULL, 0, &back, &err),
               BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "--rays"), "%s", err.message);
  /* and one that bb_command_check refuses: a scale out of its range */
  const char none[] = "bumpbake-command 1\0bake\0input\0h.png\0option\0normal\0n.png\0"
                      "option\0scale\0-1\0end";
  cr_expect_eq(bb_command_from_handover(none, sizeof none, NULL, 0, &back, &err),
               BB_ERR_ARGUMENT);
  cr_expect_null(back);
  const char odd[] = "bumpbake-command 1\0bake\0inputs\0h.png\0end";
  cr_expect_eq(bb_command_from_handover(odd, sizeof odd, NULL, 0, &back, &err),
               BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "unknown field"), "%s", err.message);
  free(data);
  bb_command_free(c);
}

/* A map written to several files travels with its further files and the
 * command line each file records, and plans as the same files. */
Test(handover, carries_a_map_written_to_several_files) {
  const char *inputs[] = {"h.png", NULL};
  const char *const options[][2] = {{"scale", "8"},
                                    {"ssbump", "s.png"},
                                    {"normal", "n.png"},
                                    {"ssbump", "s.tga"},
                                    {NULL, NULL}};
  bb_command *c = bake(inputs, options);
  bb_error err = {{0}};
  cr_assert_eq(
      bb_command_set_record(c, NULL, "bumpbake bake h.png --scale 8 ...", "--scale 8", &err),
      BB_OK);
  cr_assert_eq(
      bb_command_set_record(c, "s.tga", "bumpbake bake h.png --scale 8 s.tga", NULL, &err),
      BB_OK);
  /* a file records a line, and nothing else */
  cr_expect_eq(bb_command_set_record(c, "s.tga", "bumpbake bake h.png", "--scale 8", &err),
               BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "command: a file records a line alone");
  cr_expect_eq(bb_command_set_record(c, "s.tga", NULL, NULL, &err), BB_ERR_ARGUMENT);
  size_t size = 0;
  char *data = bb_command_handover(c, &size);
  cr_assert(data && size > 0);
  bb_command *back = NULL;
  cr_assert_eq(bb_command_from_handover(data, size, NULL, 0, &back, &err), BB_OK, "%s",
               err.message);
  char *a = spelled(c), *b = spelled(back);
  cr_expect_str_eq(b, a);
  cr_expect(strstr(a, "--ssbump s.png --ssbump s.tga"), "%s", a);
  size_t again = 0;
  char *data_back = bb_command_handover(back, &again);
  cr_expect(again == size && !memcmp(data, data_back, size),
            "the record of s.tga is lost");
  free(data_back);
  free(a);
  free(b);
  free(data);
  bb_command_free(back);
  bb_command_free(c);
}
