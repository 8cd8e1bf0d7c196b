/* test_shell_word.c: bb_text_shell_quoted, the one quoting of a word for a
 * POSIX shell that every command line the library spells goes through
 * (the provenance's command, serve's line, the command line's record): a
 * word of plain characters stays as it is, any other is single-quoted, and
 * whatever its bytes, sh reads back the word itself. */
#define _DEFAULT_SOURCE /* popen */

#include "bumpbake.h"

#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void expect_quoted(const char *word, const char *want) {
  char *got = bb_text_shell_quoted(word);
  cr_assert_not_null(got);
  cr_expect_str_eq(got, want, "%s", word);
  free(got);
}

Test(shell_word, plain_words_stay_and_the_rest_is_quoted) {
  /* what paths and values have always been: today's bytes */
  expect_quoted("rock06_height.png", "rock06_height.png");
  expect_quoted("/tmp/out/h_normal.png", "/tmp/out/h_normal.png");
  expect_quoted("dirs:6", "dirs:6");
  expect_quoted("-0.55", "-0.55");
  expect_quoted("135,45", "135,45");
  expect_quoted("a+b=c@d%e", "a+b=c@d%e");
  expect_quoted("h\xc3\xb6he.png", "h\xc3\xb6he.png"); /* UTF-8 is not special to sh */
  /* what a shell would take apart or expand */
  expect_quoted("my rock.png", "'my rock.png'");
  expect_quoted("x;touch PWNED;y.png", "'x;touch PWNED;y.png'");
  expect_quoted("$HOME/h.png", "'$HOME/h.png'");
  expect_quoted("*.png", "'*.png'");
  expect_quoted("~/h.png", "'~/h.png'");
  expect_quoted("{stem}_{kind}.png", "'{stem}_{kind}.png'");
  expect_quoted("it's", "'it'\\''s'");
  expect_quoted("", "''");
  expect_quoted("a\nb", "'a\nb'");
}

/* Every word, its bytes 1..255 at random, printed by sh from its quoted
 * form, is itself. */
Test(shell_word, sh_reads_back_the_word) {
  srand(39);
  for (int trial = 0; trial < 200; trial++) {
    char word[24];
    const int n = trial % 23;
    for (int i = 0; i < n; i++)
      word[i] = (char)(1 + rand() % 255);
    word[n] = '\0';
    char *quoted = bb_text_shell_quoted(word);
    cr_assert_not_null(quoted);
    char *script = malloc(strlen(quoted) + 32);
    cr_assert_not_null(script);
    sprintf(script, "printf '%%s' %s", quoted);
    FILE *sh = popen(script, "r");
    cr_assert_not_null(sh);
    char got[64] = "";
    const size_t len = fread(got, 1, sizeof got - 1, sh);
    got[len] = '\0';
    cr_assert_eq(pclose(sh), 0, "%s", script);
    cr_expect_eq(len, (size_t)n, "trial %d: %s", trial, quoted);
    cr_expect_eq(memcmp(got, word, (size_t)n), 0, "trial %d: %s", trial, quoted);
    free(script);
    free(quoted);
  }
}
