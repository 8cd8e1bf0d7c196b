/* cli_batch_plan.c: a batch's inputs and output paths, decided and checked
 * before any bake, so a clash or a bad template costs no baking time. */
#include "batch_plan.h"

#include <dirent.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ---------------------------------------------------------------- --maps */

/* chosen[k] = 1 for each kind --maps names (comma-separated), or the
 * client's defaults. 0 or BB_EXIT_USAGE. */
static int choose_kinds(const cli_batch_client *c, const char *maps, int *chosen) {
  int any = 0;
  for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++)
    chosen[k] = maps ? 0 : (c->default_maps & BB_OUTPUT_BIT(k)) != 0;
  for (const char *s = maps; s && *s;) {
    size_t n = strcspn(s, ",");
    int found = -1;
    for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++)
      if (strlen(cli_batch_kind_name(k)) == n && strncmp(cli_batch_kind_name(k), s, n) == 0)
        found = k;
    if (found < 0) {
      char names[256] = "";
      for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++)
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", k ? ", " : "",
                 cli_batch_kind_name(k));
      return cli_usage_error(c->command, "--maps: unknown map '%.*s' (one of %s)", (int)n, s,
                             names);
    }
    chosen[found] = 1;
    s += n + (s[n] == ',');
  }
  for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++)
    any |= chosen[k];
  return any ? 0 : cli_usage_error(c->command, "--maps: no map named");
}

/* ---------------------------------------------------------------- inputs */

/* Which file a path names, when it exists. */
typedef struct file_id {
  int exists;
  dev_t dev;
  ino_t ino;
} file_id;

static file_id file_id_of(const char *path) {
  struct stat st;
  if (stat(path, &st) != 0)
    return (file_id){0, 0, 0};
  return (file_id){1, st.st_dev, st.st_ino};
}

static int same_file_id(file_id a, file_id b) {
  return a.exists && b.exists && a.dev == b.dev && a.ino == b.ino;
}

/* The inputs gathered so far, with the identity of each, so a file named
 * twice is kept once. */
typedef struct input_list {
  cli_batch_plan *plan;
  int capacity;
  file_id *ids;
} input_list;

static int grow(input_list *l) {
  int cap = l->capacity ? 2 * l->capacity : 16;
  cli_batch_item *items = realloc(l->plan->items, (size_t)cap * sizeof *items);
  if (items)
    l->plan->items = items;
  file_id *ids = realloc(l->ids, (size_t)cap * sizeof *ids);
  if (ids)
    l->ids = ids;
  if (!items || !ids)
    return -1;
  l->capacity = cap;
  return 0;
}

/* Adds path (copied) unless the same file is there already. 0 or -1 when
 * out of memory. */
static int add_input(input_list *l, const char *path) {
  file_id id = file_id_of(path);
  for (int i = 0; i < l->plan->count; i++)
    if (same_file_id(l->ids[i], id))
      return 0;
  if (l->plan->count == l->capacity && grow(l) != 0)
    return -1;
  cli_batch_item *item = &l->plan->items[l->plan->count];
  memset(item, 0, sizeof *item);
  item->input = strdup(path);
  if (!item->input)
    return -1;
  l->ids[l->plan->count++] = id;
  return 0;
}

/* 1 when the file's provenance says this command wrote it as one of its
 * maps: reading it back as a height would bake a map of a map. */
static int is_baked_map(const char *path) {
  bb_image_info info;
  int saved = cli_mute_stderr();
  bb_status st = bb_image_read_info(path, NULL, NULL, NULL, &info, NULL);
  cli_unmute_stderr(saved);
  if (st != BB_OK)
    return 0; /* not ours to judge: its bake will say what is wrong */
  char kind[64];
  int baked = 0;
  if (bb_provenance_classify(info.description) != BB_PROVENANCE_NONE &&
      bb_provenance_value(info.description, "output", kind, sizeof kind))
    for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++)
      baked |= strcmp(kind, cli_batch_kind_name(k)) == 0;
  bb_image_info_free(&info);
  return baked;
}

static int by_name(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

static char *join_path(const char *dir, const char *name) {
  size_t n = strlen(dir);
  while (n > 1 && dir[n - 1] == '/')
    n--;
  size_t len = n + 1 + strlen(name) + 1;
  char *path = malloc(len);
  if (path)
    snprintf(path, len, "%.*s/%s", (int)n, dir, name);
  return path;
}

/* The names in dir that may be heights, sorted (malloc'd array of malloc'd
 * names in *names). Returns the count, or -1 after printing why not. */
static int read_directory(const char *dir, char ***names) {
  *names = NULL;
  DIR *d = opendir(dir);
  if (!d) {
    cli_file_error(dir, strerror(errno));
    return -1;
  }
  int count = 0, capacity = 0, failed = 0;
  for (struct dirent *e; !failed && (e = readdir(d));) {
    if (e->d_name[0] == '.' || !bb_path_is_readable_format(e->d_name))
      continue;
    if (count == capacity) {
      capacity = capacity ? 2 * capacity : 32;
      char **grown = realloc(*names, (size_t)capacity * sizeof *grown);
      failed = !grown;
      if (grown)
        *names = grown;
    }
    if (!failed && !((*names)[count] = strdup(e->d_name)))
      failed = 1;
    count += !failed;
  }
  closedir(d);
  if (failed) {
    cli_file_error(dir, "out of memory");
    for (int i = 0; i < count; i++)
      free((*names)[i]);
    free(*names);
    *names = NULL;
    return -1;
  }
  if (count)
    qsort(*names, (size_t)count, sizeof **names, by_name);
  return count;
}

/* Adds dir/name when it is a regular file and not a baked map. */
static int add_directory_entry(input_list *l, const char *dir, const char *name) {
  char *path = join_path(dir, name);
  struct stat st;
  int failed = !path;
  if (path && stat(path, &st) == 0 && S_ISREG(st.st_mode) && !is_baked_map(path))
    failed = add_input(l, path) != 0;
  if (failed)
    cli_file_error(path ? path : dir, "out of memory");
  free(path);
  return failed ? BB_EXIT_FAILURE : 0;
}

static int add_directory(input_list *l, const char *dir) {
  char **names;
  int count = read_directory(dir, &names), rc = count < 0 ? BB_EXIT_FAILURE : 0;
  for (int i = 0; i < count; i++) {
    if (!rc)
      rc = add_directory_entry(l, dir, names[i]);
    free(names[i]);
  }
  free(names);
  return rc;
}

static int gather_inputs(const cli_batch_client *c, char *const *inputs, int input_count,
                         cli_batch_plan *plan) {
  input_list l = {plan, 0, NULL};
  int rc = 0;
  for (int i = 0; i < input_count && !rc; i++) {
    struct stat st;
    if (stat(inputs[i], &st) == 0 && S_ISDIR(st.st_mode)) {
      rc = add_directory(&l, inputs[i]);
    } else if (add_input(&l, inputs[i]) != 0) { /* a missing file fails at its bake */
      cli_file_error(inputs[i], "out of memory");
      rc = BB_EXIT_FAILURE;
    }
  }
  free(l.ids);
  if (!rc && plan->count == 0)
    rc = cli_usage_error(c->command, "nothing to bake: %s%s holds no image file", inputs[0],
                         input_count > 1 ? " (and the others)" : "");
  return rc;
}

/* ----------------------------------------------------------------- names */

/* The file name of input (no directory) split into stem and extension
 * (after the last dot; "" when none). */
static void split_name(const char *input, char *stem, size_t stem_cap, char *ext,
                       size_t ext_cap) {
  const char *slash = strrchr(input, '/');
  const char *base = slash ? slash + 1 : input;
  const char *dot = strrchr(base, '.');
  if (dot == base) /* ".hidden": all stem */
    dot = NULL;
  size_t n = dot ? (size_t)(dot - base) : strlen(base);
  snprintf(stem, stem_cap, "%.*s", (int)n, base);
  snprintf(ext, ext_cap, "%s", dot ? dot + 1 : "");
}

/* Expands the template's fields {stem}, {kind} and {ext} ("{{" and "}}"
 * are braces) into out (capacity cap). 0, or a usage error. */
static int expand_name(const char *command, const char *tmpl, const char *const fields[3],
                       char *out, size_t cap) {
  static const char *const names[3] = {"stem", "kind", "ext"};
  size_t used = 0;
  for (const char *s = tmpl; *s;) {
    const char *piece = s;
    size_t n = 1;
    if ((s[0] == '{' && s[1] == '{') || (s[0] == '}' && s[1] == '}')) {
      s += 2;
    } else if (*s == '{') {
      size_t len = strcspn(s + 1, "}");
      if (s[1 + len] != '}')
        return cli_usage_error(command, "--name %s: '{' without '}'", tmpl);
      int f = 0;
      while (f < 3 && !(strlen(names[f]) == len && strncmp(names[f], s + 1, len) == 0))
        f++;
      if (f == 3)
        return cli_usage_error(command, "--name %s: unknown field {%.*s} (use {stem}, "
                               "{kind}, {ext})", tmpl, (int)len, s + 1);
      piece = fields[f];
      n = strlen(piece);
      s += len + 2;
    } else if (*s == '}') {
      return cli_usage_error(command, "--name %s: '}' without '{' (write }} for a brace)",
                             tmpl);
    } else {
      s++;
    }
    if (used + n >= cap)
      return cli_usage_error(command, "--name %s: the name is too long", tmpl);
    memcpy(out + used, piece, n);
    used += n;
  }
  out[used] = '\0';
  if (used == 0 || out[used - 1] == '/')
    return cli_usage_error(command, "--name %s: gives no file name", tmpl);
  return 0;
}

static int name_outputs(const cli_batch_client *c, const cli_batch_args *b, const int *chosen,
                        cli_batch_item *item) {
  char stem[1024], ext[64], name[4096];
  split_name(item->input, stem, sizeof stem, ext, sizeof ext);
  const char *tmpl = b->name_template ? b->name_template : CLI_BATCH_DEFAULT_NAME;
  for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++) {
    if (!chosen[k])
      continue;
    const char *fields[3] = {stem, cli_batch_kind_name(k), ext};
    int rc = expand_name(c->command, tmpl, fields, name, sizeof name);
    if (rc)
      return rc;
    if (!(item->paths[k] = join_path(b->out_dir, name))) {
      cli_file_error(item->input, "out of memory");
      return BB_EXIT_FAILURE;
    }
  }
  return 0;
}

/* --------------------------------------------------------------- clashes */

typedef struct planned_output {
  const char *path;
  int item, kind;
} planned_output;

static int by_path(const void *a, const void *b) {
  const planned_output *x = a, *y = b;
  int c = strcmp(x->path, y->path);
  return c ? c : (x->item > y->item) - (x->item < y->item);
}

/* Two outputs on one path, found by sorting the paths (all are made the
 * same way under one directory, so equal files have equal spellings). */
static int check_clashes(const cli_batch_client *c, const cli_batch_plan *plan,
                         planned_output *outs, int n) {
  qsort(outs, (size_t)n, sizeof *outs, by_path);
  for (int i = 1; i < n; i++) {
    if (strcmp(outs[i - 1].path, outs[i].path) != 0)
      continue;
    const planned_output *a = &outs[i - 1], *o = &outs[i];
    if (a->item == o->item)
      return cli_usage_error(c->command, "%s: %s and %s would both be written to %s",
                             plan->items[a->item].input, cli_batch_kind_name(a->kind),
                             cli_batch_kind_name(o->kind), o->path);
    return cli_usage_error(c->command, "%s and %s would both be written to %s",
                           plan->items[a->item].input, plan->items[o->item].input, o->path);
  }
  return 0;
}

/* An output that is one of the inputs (an existing file under another
 * name): baking would overwrite a height another bake of the batch reads. */
static int check_outputs_on_inputs(const cli_batch_client *c, const cli_batch_plan *plan,
                                   const planned_output *outs, int n) {
  file_id *in = malloc((size_t)plan->count * sizeof *in);
  if (!in) {
    cli_file_error(plan->items[0].input, "out of memory");
    return BB_EXIT_FAILURE;
  }
  for (int j = 0; j < plan->count; j++)
    in[j] = file_id_of(plan->items[j].input);
  int rc = 0;
  for (int i = 0; i < n && !rc; i++) {
    file_id out = file_id_of(outs[i].path);
    for (int j = 0; j < plan->count && out.exists && !rc; j++)
      if (same_file_id(in[j], out))
        rc = cli_usage_error(c->command, "%s: %s of %s would overwrite the input %s",
                             outs[i].path, cli_batch_kind_name(outs[i].kind),
                             plan->items[outs[i].item].input, plan->items[j].input);
  }
  free(in);
  return rc;
}

static int check_paths(const cli_batch_client *c, const cli_batch_plan *plan) {
  int n = 0;
  planned_output *outs = malloc((size_t)plan->count * (size_t)BB_OUTPUT_KIND_COUNT * sizeof *outs);
  if (!outs) {
    cli_file_error(plan->items[0].input, "out of memory");
    return BB_EXIT_FAILURE;
  }
  for (int i = 0; i < plan->count; i++)
    for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++)
      if (plan->items[i].paths[k])
        outs[n++] = (planned_output){plan->items[i].paths[k], i, k};
  int rc = check_outputs_on_inputs(c, plan, outs, n);
  if (!rc)
    rc = check_clashes(c, plan, outs, n);
  free(outs);
  return rc;
}

/* ------------------------------------------------------------------ plan */

int cli_batch_plan_make(const cli_batch_client *c, const cli_batch_args *b,
                        char *const *inputs, int input_count, cli_batch_plan *plan) {
  memset(plan, 0, sizeof *plan);
  int chosen[CLI_BATCH_MAX_KINDS] = {0};
  int rc = choose_kinds(c, b->maps, chosen);
  if (!rc)
    rc = gather_inputs(c, inputs, input_count, plan);
  for (int i = 0; i < plan->count && !rc; i++)
    rc = name_outputs(c, b, chosen, &plan->items[i]);
  return rc ? rc : check_paths(c, plan);
}

void cli_batch_plan_free(cli_batch_plan *plan) {
  for (int i = 0; i < plan->count; i++) {
    free(plan->items[i].input);
    for (int k = 0; k < CLI_BATCH_MAX_KINDS; k++)
      free(plan->items[i].paths[k]);
  }
  free(plan->items);
  memset(plan, 0, sizeof *plan);
}
