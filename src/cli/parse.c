/* parse.c: the command line of any command, read against the library's
 * description of it: getopt_long's tables built from the options, "did you
 * mean" and usage errors from the descriptions, every value handed to the
 * library's parser (bb_command_set), then the library's checks
 * (bb_command_check) and the run. It also keeps the words as typed, less
 * those of options that do not change the output, as the command line the
 * outputs record. */
#include "cli.h"
#include "common.h"

#include <getopt.h>
#include <stdlib.h>
#include <string.h>

typedef struct runner {
  const char *name;
  int (*run)(const cli_run *r);
} runner;

static const runner runners[] = {
    {"normal", cli_run_job},          {"bake", cli_run_job},
    {"height2ssbump", cli_run_job},   {"compare", cli_run_compare},
    {"check", cli_run_check},
    {"info", cli_run_info},           {"renderbumpflat", cli_run_renderbumpflat},
    {"render", cli_run_render},       {"sheet", cli_run_sheet},
    {"normal2ssbump", cli_run_normal2ssbump}, {"ssbump2normal", cli_run_ssbump2normal},
    {"combine", cli_run_combine},     {"program", cli_run_program},
};

/* What one parse makes: the command, and which typed words it records. */
typedef struct parse {
  const bb_command_info *info;
  bb_command *command;
  int argc;
  char **argv;   /* as typed */
  char **word;   /* the word as recorded (a short cluster less a letter) */
  char *dropped; /* 1: the word is left out of the record */
  char *is_option; /* 1: the word belongs to an option (not a positional) */
  const bb_option_info **file_of; /* the file option the word belongs to */
  const char **file_value;        /* ... and the file it names */
  int usage;     /* the command's usage exit code */
} parse;

/* The option of command whose short name is c ('o' for -o), or NULL. */
static const bb_option_info *option_short(const bb_command_info *command, char c) {
  const bb_option_info *o;
  for (int k = 0; c && (o = bb_command_option(command, k)) != NULL; k++)
    if (o->short_name == c)
      return o;
  return NULL;
}

static int usage_error(const parse *p, const char *fmt, const char *a, const char *b) {
  char line[1024];
  snprintf(line, sizeof line, fmt, a, b);
  cli_usage_error(p->info->name, "%s", line);
  return p->usage;
}

/* A library refusal: a usage error (BB_ERR_ARGUMENT) or a file's (a basis
 * file that is there but wrong: exit 1). */
static int refused(const parse *p, bb_status st, const bb_error *err) {
  if (st == BB_ERR_ARGUMENT) {
    cli_usage_error(p->info->name, "%s", err->message);
    return p->usage;
  }
  cli_error_line(err->message[0] ? err->message : bb_status_name(st));
  /* compare's 1 is a verdict (a warning, as idiff's): every refusal of
   * compare is its usage exit, 4, as a file it cannot read is. */
  return p->usage == BB_EXIT_USAGE ? BB_EXIT_FAILURE : p->usage;
}

static void leave_out(parse *p, int from, int to) {
  for (int w = from; w < to && w < p->argc; w++)
    p->dropped[w] = 1;
}

/* ------------------------------------------------- options of many words */

/* renderbumpflat's -size W H and --rect L B R T take several words, which
 * getopt cannot: they are read here, out of the words getopt sees. */
static int take_many(parse *p, int *map, int *count, char **kept) {
  int n = 0;
  for (int i = 1; i < p->argc; i++) {
    const char *s = p->argv[i];
    if (!strcmp(s, "--")) {
      for (; i < p->argc; i++)
        map[n] = i, kept[n++] = p->argv[i];
      break;
    }
    const bb_option_info *o = NULL;
    if (s[0] == '-' && s[1])
      o = bb_option_find(p->info, s + (s[1] == '-' ? 2 : 1), 0);
    if (!o || o->values < 2 || (s[1] != '-' && !(o->flags & BB_OPTION_SINGLE_DASH))) {
      map[n] = i, kept[n++] = p->argv[i];
      continue;
    }
    if (i + o->values >= p->argc) {
      char example[96];
      snprintf(example, sizeof example, "%s %s", s, o->value_name);
      char need[160];
      snprintf(need, sizeof need, "%d values: %s", o->values, example);
      return usage_error(p, "%s needs %s", s, need);
    }
    char text[1024] = "";
    for (int k = 1; k <= o->values; k++)
      snprintf(text + strlen(text), sizeof text - strlen(text), "%s%s", k > 1 ? " " : "",
               p->argv[i + k]);
    bb_error err = {{0}};
    bb_status st = bb_command_set(p->command, o->name, text, &err);
    if (st != BB_OK)
      return refused(p, st, &err);
    for (int k = 0; k <= o->values; k++)
      p->is_option[i + k] = 1;
    if (!(o->flags & BB_OPTION_RECORDED))
      leave_out(p, i, i + o->values + 1);
    i += o->values;
  }
  *count = n;
  return 0;
}

/* ------------------------------------------------------ whole long names */

/* Every long option word must name an option in full: getopt_long would
 * take "--ray" for --rays silently. An unknown word gets the nearest name;
 * a prefix of several names lists them. The words after "--" and the
 * values of options that take one are not options. */
static int check_long_words(const parse *p, int argc, char **argv, int long_only) {
  for (int i = 1; i < argc; i++) {
    const char *w = argv[i];
    if (!strcmp(w, "--"))
      return 0;
    const int dashes = w[0] == '-' && w[1] == '-' ? 2 : (long_only && w[0] == '-' && w[1] && w[2]) ? 1 : 0;
    if (!dashes)
      continue;
    const char *name = w + dashes;
    const size_t n = strcspn(name, "=");
    const bb_option_info *exact = bb_option_find(p->info, name, n);
    if (exact && n) {
      if (exact->type != BB_OPTION_FLAG && !name[n])
        i++; /* its value */
      continue;
    }
    if (dashes == 1) /* a cluster of short options ("-nA") is getopt's */
      continue;
    char candidates[256] = "";
    int prefix_of = 0;
    for (int k = 0; k < p->info->option_count; k++) {
      const bb_option_info *o = bb_command_option(p->info, k);
      if (strncmp(o->name, name, n) == 0) {
        prefix_of++;
        snprintf(candidates + strlen(candidates), sizeof candidates - strlen(candidates),
                 "%s--%s", candidates[0] ? ", " : "", o->name);
      }
    }
    char typed[128];
    snprintf(typed, sizeof typed, "--%.*s", (int)(n < 100 ? n : 100), name);
    if (prefix_of > 1)
      return usage_error(p, "option '%s' is ambiguous: %s", typed, candidates);
    if (prefix_of == 1)
      return usage_error(p, "unknown option '%s' (did you mean %s?)", typed, candidates);
    const bb_option_info *near = bb_option_nearest(p->info, name, n);
    if (near) {
      char suggestion[80];
      snprintf(suggestion, sizeof suggestion, "--%s", near->name);
      return usage_error(p, "unknown option '%s' (did you mean %s?)", typed, suggestion);
    }
    return usage_error(p, "unknown option '%s' (see --help)%s", typed, "");
  }
  return 0;
}

/* ------------------------------------------------------------- getopt */

/* Which typed word an option returned by getopt came from, and what it
 * records: a long option's words go whole; a short option in a cluster
 * ("-qn") loses only its letter. */
static void record_option(parse *p, const bb_option_info *o, int c, int first, int after,
                          const int *map) {
  for (int w = first; w < after; w++) {
    p->is_option[map[w]] = 1;
    if (o->type == BB_OPTION_PATH) {
      p->file_of[map[w]] = o;
      p->file_value[map[w]] = optarg;
    }
  }
  if (o->flags & BB_OPTION_RECORDED)
    return;
  const int at = map[first];
  const char *typed = p->argv[at];
  if (typed[0] == '-' && typed[1] != '-' && c < 256) {
    /* a short option: its letter out of the word as recorded */
    char *word = p->word[at];
    char *letter = strchr(word + 1, c);
    if (letter)
      memmove(letter, letter + 1, strlen(letter));
    if (!strcmp(word, "-"))
      p->dropped[at] = 1;
    for (int w = first + 1; w < after; w++)
      p->dropped[map[w]] = 1; /* its value */
    return;
  }
  for (int w = first; w < after; w++)
    p->dropped[map[w]] = 1;
}

enum { MAX_OPTIONS = 64 };

static int run_getopt(parse *p, int argc, char **argv, const int *map) {
  struct option longopts[MAX_OPTIONS + 1];
  char shortopts[2 * MAX_OPTIONS + 3];
  int nl = 0, ns = 0, long_only = 0;
  /* '-': every positional comes back in order (nothing permuted), so each
   * word's option is known; ':' reports a missing value. */
  shortopts[ns++] = '-';
  shortopts[ns++] = ':';
  const int count = p->info->option_count < MAX_OPTIONS ? p->info->option_count : MAX_OPTIONS;
  for (int i = 0; i < count; i++) {
    const bb_option_info *o = bb_command_option(p->info, i);
    if (o->values > 1)
      continue; /* read by take_many */
    long_only |= (o->flags & BB_OPTION_SINGLE_DASH) != 0;
    const int has_arg = o->type == BB_OPTION_FLAG ? no_argument : required_argument;
    longopts[nl++] = (struct option){o->name, has_arg, NULL, 256 + i};
    if (o->short_name) {
      shortopts[ns++] = o->short_name;
      if (has_arg)
        shortopts[ns++] = ':';
    }
  }
  longopts[nl] = (struct option){NULL, 0, NULL, 0};
  shortopts[ns] = '\0';
  int rc = check_long_words(p, argc, argv, long_only);
  if (rc)
    return rc;
  opterr = 0; /* our messages, in our format */
  /* 0, not 1: glibc then forgets all its state, including its pointer into
   * the previous argv when that parse stopped inside a cluster such as
   * "-nx" (a later parse read freed memory through it: found by fuzz_cli). */
  optind = 0;
  for (;;) {
    const int first = optind ? optind : 1;
    const int c = long_only ? getopt_long_only(argc, argv, shortopts, longopts, NULL)
                            : getopt_long(argc, argv, shortopts, longopts, NULL);
    if (c == -1)
      break;
    bb_error err = {{0}};
    if (c == 1) { /* a positional */
      bb_status st = bb_command_add_input(p->command, optarg, &err);
      if (st != BB_OK)
        return refused(p, st, &err);
      continue;
    }
    if (c == '?' || c == ':') {
      const bb_option_info *known =
          optopt >= 256 ? bb_command_option(p->info, optopt - 256)
                        : optopt > 0 ? option_short(p->info, (char)optopt) : NULL;
      char name[80] = "";
      if (known && optopt < 256)
        snprintf(name, sizeof name, "-%c", known->short_name);
      else if (known)
        snprintf(name, sizeof name, "--%s", known->name);
      if (c == ':')
        return usage_error(p, "%s needs a value%s", known ? name : argv[optind - 1], "");
      if (optopt > 0 && optopt < 256 && !known) {
        const char letter[3] = {'-', (char)optopt, 0};
        return usage_error(p, "unknown option '%s' (see --help)%s", letter, "");
      }
      if (known) /* glibc reports "--flag=value" for a flag this way */
        return usage_error(p, "%s takes no value%s", name, "");
      return usage_error(p, "unknown or ambiguous option '%s' (see --help)%s",
                         argv[optind - 1], "");
    }
    const bb_option_info *o =
        c >= 256 ? bb_command_option(p->info, c - 256) : option_short(p->info, (char)c);
    if (!o)
      return usage_error(p, "internal: unhandled option %s%s", "", "");
    if (!strcmp(o->name, "help")) {
      cli_print_help(p->info);
      return -1;
    }
    bb_status st = bb_command_set(p->command, o->name, o->type == BB_OPTION_FLAG ? NULL : optarg,
                                  &err);
    if (st != BB_OK)
      return refused(p, st, &err);
    record_option(p, o, c, first, optind > first ? optind : first + 1, map);
  }
  for (int i = optind; i < argc; i++) { /* after "--" */
    bb_error err = {{0}};
    bb_status st = bb_command_add_input(p->command, argv[i], &err);
    if (st != BB_OK)
      return refused(p, st, &err);
  }
  return 0;
}

/* "bumpbake NAME WORDS..." of the recorded words, each quoted for a POSIX
 * shell by the library (bb_text_shell_quoted); options only (a batch's
 * provenance: "bumpbake bake INPUT OPTIONS") when options_only. With
 * file_of, the words of file_of's other files (those not naming file) are
 * left out too. NULL when out of memory. */
static char *recorded_of(const parse *p, int options_only, const bb_option_info *file_of,
                         const char *file) {
  size_t len = strlen("bumpbake ") + strlen(p->argv[0]) + 1, used = 0;
  char *text = malloc(len);
  if (!text)
    return NULL;
  text[0] = '\0';
  if (!options_only)
    used = (size_t)snprintf(text, len, "bumpbake %s", p->argv[0]);
  for (int w = 1; w < p->argc; w++) {
    if (p->dropped[w] || (options_only && (!p->is_option[w] || !strcmp(p->argv[w], "--"))))
      continue;
    if (file_of && p->file_of[w] == file_of && strcmp(p->file_value[w], file))
      continue;
    char *word = bb_text_shell_quoted(p->word[w]);
    char *grown = word ? realloc(text, used + strlen(word) + 2) : NULL;
    if (!grown) {
      free(word);
      free(text);
      return NULL;
    }
    text = grown;
    used += (size_t)sprintf(text + used, "%s%s", used ? " " : "", word);
    free(word);
  }
  return text;
}

static char *recorded(const parse *p, int options_only) {
  return recorded_of(p, options_only, NULL, NULL);
}

/* A map the library writes to several files (--ssbump s.png --ssbump
 * s.vtf, one bake): each file records the words as typed less those of
 * the map's other files, what a bake of that file alone records. */
static bb_status record_files(const parse *p, bb_error *err) {
  for (int w = 1; w < p->argc; w++) {
    const bb_option_info *o = p->file_of[w];
    if (!o || p->dropped[w])
      continue;
    int seen = 0, others = 0;
    for (int v = 1; v < p->argc; v++) {
      if (p->file_of[v] != o)
        continue;
      if (v < w && !strcmp(p->file_value[v], p->file_value[w]))
        seen = 1;
      others |= strcmp(p->file_value[v], p->file_value[w]) != 0;
    }
    if (seen || !others)
      continue;
    char *line = recorded_of(p, 0, o, p->file_value[w]);
    if (!line)
      return BB_ERR_MEMORY;
    bb_status st = bb_command_set_record(p->command, p->file_value[w], line, NULL, err);
    free(line);
    if (st != BB_OK)
      return st;
  }
  return BB_OK;
}

/* -------------------------------------------------------------- the run */

static int parse_and_run(parse *p, int (*run)(const cli_run *r)) {
  int *map = malloc((size_t)p->argc * sizeof *map);
  char **kept = malloc(((size_t)p->argc + 1) * sizeof *kept);
  int n = 0, rc = map && kept ? 0 : BB_EXIT_FAILURE;
  if (rc)
    cli_error_line("out of memory");
  if (!rc) {
    map[0] = 0;
    kept[0] = p->argv[0];
  }
  if (!rc)
    rc = take_many(p, map + 1, &n, kept + 1);
  if (!rc) {
    kept[n + 1] = NULL;
    rc = run_getopt(p, n + 1, kept, map);
  }
  free(map);
  free(kept);
  if (rc)
    return rc < 0 ? BB_EXIT_OK : rc; /* --help, or a usage error */
  bb_error err = {{0}};
  bb_status st = bb_command_check(p->command, &err);
  if (st != BB_OK)
    return refused(p, st, &err);
  char *line = recorded(p, 0), *options = recorded(p, 1);
  st = line && options ? bb_command_set_record(p->command, NULL, line, options, &err)
                       : BB_ERR_MEMORY;
  if (st == BB_OK)
    st = record_files(p, &err);
  if (st != BB_OK) {
    free(line);
    free(options);
    if (st == BB_ERR_MEMORY)
      cli_error_line("out of memory");
    return st == BB_ERR_MEMORY ? BB_EXIT_FAILURE : refused(p, st, &err);
  }
  cli_run r = {p->command, 0, 0, line};
  r.quiet = cli_flag(&r, "quiet");
  r.json = cli_flag(&r, "json");
  rc = BB_EXIT_FAILURE;
  for (size_t i = 0; !run && i < sizeof runners / sizeof runners[0]; i++)
    if (!strcmp(runners[i].name, p->info->name))
      run = runners[i].run;
  if (run)
    rc = run(&r);
  free(line);
  free(options);
  return rc;
}

int bb_cli_command(int argc, char **argv) {
  return bb_cli_command_with(argc, argv, NULL);
}

int bb_cli_command_with(int argc, char **argv, int (*run)(const cli_run *r)) {
  bb_command *command = NULL;
  bb_error err = {{0}};
  if (bb_command_new(argv[0], &command, &err) != BB_OK) {
    cli_error_line(err.message);
    return BB_EXIT_USAGE;
  }
  parse p = {.info = bb_command_describe(command),
             .command = command,
             .argc = argc,
             .usage = bb_command_describe(command)->usage_exit};
  /* getopt writes into argv (it may permute): the words as typed are kept */
  p.argv = malloc(((size_t)argc + 1) * sizeof *p.argv);
  p.word = calloc((size_t)argc + 1, sizeof *p.word);
  p.is_option = calloc((size_t)argc + 1, 1);
  p.dropped = calloc((size_t)argc + 1, 1);
  p.file_of = calloc((size_t)argc + 1, sizeof *p.file_of);
  p.file_value = calloc((size_t)argc + 1, sizeof *p.file_value);
  int rc = p.argv && p.word && p.is_option && p.dropped && p.file_of && p.file_value
               ? 0
               : BB_EXIT_FAILURE;
  for (int i = 0; !rc && i < argc; i++) {
    p.argv[i] = argv[i];
    if (!(p.word[i] = strdup(argv[i])))
      rc = BB_EXIT_FAILURE;
  }
  if (rc)
    cli_error_line("out of memory");
  else
    rc = parse_and_run(&p, run);
  for (int i = 0; p.word && i < argc; i++)
    free(p.word[i]);
  free(p.word);
  free(p.argv);
  free(p.is_option);
  free(p.dropped);
  free(p.file_of);
  free(p.file_value);
  bb_command_free(command);
  return rc;
}
