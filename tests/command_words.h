/* command_words.h: a library command made from words as a test writes
 * them (the tests that run commands through bb_command_*). */
#ifndef BB_TESTS_COMMAND_WORDS_H
#define BB_TESTS_COMMAND_WORDS_H

#include <criterion/criterion.h>

#include "bumpbake.h"

/* The command name with words, NULL-terminated: inputs, and "--option",
 * "value" pairs (a flag's value "1"); not checked. */
static inline bb_command *command(const char *name, const char *const *words) {
  bb_command *c = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb_command_new(name, &c, &err), BB_OK, "%s", err.message);
  for (int i = 0; words[i]; i++) {
    if (words[i][0] != '-') {
      cr_assert_eq(bb_command_add_input(c, words[i], &err), BB_OK, "%s", err.message);
      continue;
    }
    cr_assert_eq(bb_command_set(c, words[i] + 2, words[i + 1], &err), BB_OK, "%s: %s",
                 words[i], err.message);
    i++;
  }
  return c;
}

#endif /* BB_TESTS_COMMAND_WORDS_H */
