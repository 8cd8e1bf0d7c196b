/* check.c: a golden check's runs: two trees walked and paired by relative
 * name, the goldens a bake no longer makes, goldens of trees updated where
 * a case does not pass, what the command line prints, the reports written,
 * and cases handed between processes. Cases are decided in check_cases.c,
 * a bake's made in check_bake.c, the report's pictures drawn in
 * check_pictures.c, the reports made in check_report.c.
 *
 * Trees are walked without following anything but a link to a file inside
 * the same tree: a golden tree may come from anywhere (an archive, a pull
 * request), and a link out of it must not make the check read, or an
 * update write, outside it. */
#define _XOPEN_SOURCE 700 /* realpath */
#include "job/check.h"
#include "core/input_file.h"
#include "core/internal.h"
#include "files/safe_file.h"
#include "job/job_internal.h"
#include "files/provenance.h"
#include "image/oiio.h"
#include "core/json.h"

#include <dirent.h>
#include <errno.h>
#include <fnmatch.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---------------------------------------------------------------- trees */

/* A file of a tree: its name relative to the root, and why it cannot be
 * read without looking (a link out of the tree, not a regular file), or
 * NULL. */
typedef struct tree_file {
  char *rel;
  const char *refused;
} tree_file;

typedef struct tree {
  const char *root;
  char real_root[PATH_MAX];
  tree_file *files;
  int count, capacity;
} tree;

static void tree_free(tree *t) {
  for (int i = 0; i < t->count; i++)
    free(t->files[i].rel);
  free(t->files);
  memset(t, 0, sizeof *t);
}

static bb_status tree_add(tree *t, const char *rel, const char *refused) {
  if (t->count == t->capacity) {
    const int cap = t->capacity ? 2 * t->capacity : 256;
    tree_file *grown = realloc(t->files, (size_t)cap * sizeof *grown);
    if (!grown)
      return bb__fail(NULL, BB_ERR_MEMORY, "out of memory");
    t->files = grown;
    t->capacity = cap;
  }
  if (!(t->files[t->count].rel = strdup(rel)))
    return bb__fail(NULL, BB_ERR_MEMORY, "out of memory");
  t->files[t->count++].refused = refused;
  return BB_OK;
}

/* Deeper than this, a tree is refused: no suite nests so far, and the
 * walk's memory stays bounded. */
enum { MAX_TREE_DEPTH = 64 };

static bb_status walk(tree *t, const char *rel, int depth, bb_error *err) {
  char dir[PATH_MAX];
  if ((size_t)snprintf(dir, sizeof dir, "%s%s%s", t->root, rel[0] ? "/" : "", rel) >=
      sizeof dir)
    return bb__fail(err, BB_ERR_IO, "%s/%s: the path is too long", t->root, rel);
  if (depth > MAX_TREE_DEPTH)
    return bb__fail(err, BB_ERR_IO, "%s: folders nested more than %d deep", dir,
                    MAX_TREE_DEPTH);
  DIR *d = opendir(dir);
  if (!d)
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", dir, strerror(errno));
  bb_status st = BB_OK;
  for (struct dirent *e; st == BB_OK && (e = readdir(d));) {
    if (e->d_name[0] == '.')
      continue;
    char sub[PATH_MAX], path[PATH_MAX];
    if ((size_t)snprintf(sub, sizeof sub, "%s%s%s", rel, rel[0] ? "/" : "", e->d_name) >=
            sizeof sub ||
        (size_t)snprintf(path, sizeof path, "%s/%s", dir, e->d_name) >= sizeof path) {
      st = bb__fail(err, BB_ERR_IO, "%s/%s: the path is too long", dir, e->d_name);
      break;
    }
    struct stat s;
    if (lstat(path, &s) != 0)
      continue; /* gone while walking */
    if (S_ISDIR(s.st_mode)) {
      st = walk(t, sub, depth + 1, err);
      continue;
    }
    if (!bb__path_is_readable_format(e->d_name))
      continue;
    if (S_ISREG(s.st_mode))
      st = tree_add(t, sub, NULL);
    else if (S_ISLNK(s.st_mode))
      st = tree_add(t, sub, bb__check_link_refusal(t->real_root, path));
    else
      st = tree_add(t, sub, "not a regular file");
  }
  closedir(d);
  return st;
}

static int by_rel(const void *a, const void *b) {
  return strcmp(((const tree_file *)a)->rel, ((const tree_file *)b)->rel);
}

/* Every image file under root, sorted by relative name. */
static bb_status tree_read(tree *t, const char *root, bb_error *err) {
  memset(t, 0, sizeof *t);
  t->root = root;
  if (!realpath(root, t->real_root))
    return bb__fail(err, BB_ERR_IO, "%s: %s", root, strerror(errno));
  bb_status st = walk(t, "", 0, err);
  if (st == BB_OK && t->count > 1)
    qsort(t->files, (size_t)t->count, sizeof *t->files, by_rel);
  if (st != BB_OK)
    tree_free(t);
  return st;
}

/* ----------------------------------------------------------- one case */

/* An image read for a case, or why not. */
typedef struct side {
  bb_image image;
  bb_image_info info;
  int read;
  char why[sizeof(((bb_error *)0)->message)];
} side;

static void side_read(side *s, const char *path, const char *refused) {
  memset(s, 0, sizeof *s);
  if (refused) {
    snprintf(s->why, sizeof s->why, "%s: %s", path, refused);
    return;
  }
  bb_error e = {{0}};
  if (bb_image_read(path, &s->image, &s->info, &e) == BB_OK)
    s->read = 1;
  else
    snprintf(s->why, sizeof s->why, "%s", e.message);
}

static void side_free(side *s) {
  bb_image_free(&s->image);
  bb_image_info_free(&s->info);
}

/* 1 when a file read holds raw signed values: a float file of a map of
 * unit vectors (an integer file stores 0.5 + 0.5 N). */
static int raw_signed(const side *s, const char *kind) {
  if (!s->read || !s->info.is_float)
    return 0;
  const bb_map_kind_info *info =
      bb_map_kind_get(bb__map_kind_of_output(kind, BB_RANGE_SIGNED, NULL));
  return info && info->range == BB_RANGE_SIGNED;
}

/* The bytes of the file at path copied to dest, all or nothing (an
 * update of a tree's golden): dest's directory made when missing. */
static bb_status copy_file(const char *path, const char *dest, bb_error *err) {
  int fd;
  bb_status st = bb__input_open(path, &fd, err);
  if (st != BB_OK)
    return st;
  struct stat s;
  char *bytes = NULL;
  if (fstat(fd, &s) != 0 || s.st_size < 0)
    st = bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
  else if (!(bytes = malloc((size_t)s.st_size + 1)))
    st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  else if (bb__input_read_at(fd, bytes, (size_t)s.st_size, 0) != (size_t)s.st_size)
    st = bb__fail(err, BB_ERR_IO, "%s: cannot read it whole", path);
  close(fd);
  char dir[PATH_MAX];
  bb__directory_part(dest, dir, sizeof dir);
  if (st == BB_OK)
    st = bb__directory_create(dir, err);
  if (st == BB_OK)
    st = bb__file_write(dest, bytes, (size_t)s.st_size, err);
  free(bytes);
  return st;
}

/* An update of a tree's golden where the case did not pass and there is a
 * new file to take it from. */
static bb_status update_from_tree(bb__check_case *k) {
  const bb_check_status s = k->pub.status;
  if (s == BB_CHECK_PASS || s == BB_CHECK_MISSING || !k->fresh)
    return BB_OK;
  bb_error e = {{0}};
  if (copy_file(k->fresh, k->golden, &e) == BB_OK) {
    k->pub.updated = 1;
    return BB_OK;
  }
  free(k->update_error);
  return (k->update_error = strdup(e.message)) ? BB_OK : BB_ERR_MEMORY;
}

static char *join(const char *root, const char *rel) {
  const size_t n = strlen(root) + 1 + strlen(rel) + 1;
  char *p = malloc(n);
  if (p)
    snprintf(p, n, "%s/%s", root, rel);
  return p;
}

/* The case of golden (may be NULL: EXTRA) and fresh (may be NULL: MISSING)
 * of name, decided and added. */
static bb_status tree_case(bb_check *c, const char *name, const char *golden,
                           const char *golden_refused, const char *fresh,
                           const char *fresh_refused, bb_check_case_fn each, void *user,
                           bb_error *err) {
  const double t0 = bb__now_seconds();
  bb__check_case *k = bb__check_case_new(name, golden, fresh, NULL);
  if (!k)
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  side g, n;
  memset(&g, 0, sizeof g);
  memset(&n, 0, sizeof n);
  struct stat s;
  const int golden_there = golden && lstat(golden, &s) == 0;
  /* a case of one side is read only for its thumbnail */
  const int both = golden_there && fresh;
  if (golden_there && (both || c->html))
    side_read(&g, golden, golden_refused);
  if (fresh && (both || c->html))
    side_read(&n, fresh, fresh_refused);
  char why[sizeof g.why + 64];
  bb_check_status status = BB_CHECK_PASS;
  if (!fresh) {
    status = BB_CHECK_MISSING;
    snprintf(why, sizeof why, "no new file for the golden %s", golden);
  } else if (!golden_there) {
    status = BB_CHECK_EXTRA;
    snprintf(why, sizeof why, "no golden for the new file %s", fresh);
  } else if (!g.read || !n.read) {
    status = BB_CHECK_UNREADABLE;
    snprintf(why, sizeof why, "%s", !g.read ? g.why : n.why);
  }
  char kind[64] = "";
  if (!bb__provenance_value(n.info.description, "output", kind, sizeof kind))
    bb__provenance_value(g.info.description, "output", kind, sizeof kind);
  const bb__check_sides sides = {g.read ? &g.image : NULL, n.read ? &n.image : NULL,
                                 g.info.description,       n.info.description,
                                 raw_signed(&g, kind),     raw_signed(&n, kind)};
  bb_status st =
      bb__check_decide(c, k, &sides, status, status == BB_CHECK_PASS ? NULL : why, err);
  side_free(&g);
  side_free(&n);
  if (st == BB_OK && c->setup.update && update_from_tree(k) != BB_OK)
    st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
  k->pub.seconds = bb__now_seconds() - t0;
  if (st != BB_OK) {
    bb__check_case_free(k);
    return st;
  }
  return bb__check_add(c, k, each, user, err);
}

/* Two trees, paired by relative name (both sorted: one merge). */
static bb_status check_trees(bb_check *c, bb_check_case_fn each, void *user,
                             bb_error *err) {
  tree g, n;
  bb_status st = tree_read(&g, c->golden, err);
  if (st != BB_OK)
    return st;
  if ((st = tree_read(&n, c->fresh, err)) != BB_OK) {
    tree_free(&g);
    return st;
  }
  int i = 0, j = 0;
  while (st == BB_OK && (i < g.count || j < n.count)) {
    const int order = i == g.count   ? 1
                      : j == n.count ? -1
                                     : strcmp(g.files[i].rel, n.files[j].rel);
    const tree_file *gf = order <= 0 ? &g.files[i] : NULL;
    const tree_file *nf = order >= 0 ? &n.files[j] : NULL;
    const char *rel = gf ? gf->rel : nf->rel;
    char *gp = join(c->golden, rel), *np = nf ? join(c->fresh, rel) : NULL;
    if (!gp || (nf && !np))
      st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
    else
      st = tree_case(c, rel, gp, gf ? gf->refused : NULL, np, nf ? nf->refused : NULL,
                     each, user, err);
    free(gp);
    free(np);
    i += order <= 0;
    j += order >= 0;
  }
  tree_free(&g);
  tree_free(&n);
  return st;
}

/* One file against another: a case named by the golden's file name. */
static bb_status check_files(bb_check *c, bb_check_case_fn each, void *user,
                             bb_error *err) {
  return tree_case(c, bb__file_name(c->golden), c->golden, NULL, c->fresh, NULL, each,
                   user, err);
}

/* ------------------------------------------------- a bake's missing goldens */

static int by_string(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

/* 1 when the file's provenance says bumpbake baked it as a map. */
static int is_baked_map(const char *path) {
  bb_image_info info;
  if (bb_image_read_info(path, NULL, NULL, NULL, &info, NULL) != BB_OK)
    return 0;
  char kind[64];
  int baked = 0;
  if (bb__provenance_classify(info.description) == BB_PROVENANCE_INTACT &&
      bb__provenance_value(info.description, "output", kind, sizeof kind))
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
      baked |= strcmp(kind, bb__map_kind_name((bb_map_kind)k)) == 0;
  bb_image_info_free(&info);
  return baked;
}

/* 1 when rel is a name the batch's template gives one of the kinds it
 * writes, for some input (its stem and extension any text). */
static int could_be_made(const bb_job *job, const char *rel) {
  const char *tmpl = job->name_template ? job->name_template : BB_JOB_DEFAULT_NAME;
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    char pattern[4096];
    const char *fields[3] = {"*", bb__map_kind_name((bb_map_kind)k), "*"};
    if ((job->options.bake.outputs & BB_MAP_BIT(k)) &&
        bb__job_expand_name(tmpl, fields, pattern, sizeof pattern, NULL) == BB_OK &&
        fnmatch(pattern, rel, FNM_PATHNAME) == 0)
      return 1;
  }
  return 0;
}

/* The goldens in the tree that the batch does not write: bumpbake's maps
 * under the names its template gives the kinds it writes that no input
 * makes any more (MISSING). Other files (another suite's goldens beside
 * these, other kinds, the heights themselves) are not this check's. */
static bb_status check_unmade(bb_check *c, bb_check_case_fn each, void *user,
                              bb_error *err) {
  const bb_job *job = c->setup.job;
  size_t root = strlen(job->out_dir);
  while (root > 1 && job->out_dir[root - 1] == '/')
    root--;
  char **made = malloc(((size_t)job->count * BB_MAP_BAKED_COUNT + 1) * sizeof *made);
  if (!made)
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  size_t n = 0;
  for (int i = 0; i < job->count; i++)
    for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
      if (job->items[i].paths[k] && strlen(job->items[i].paths[k]) > root)
        made[n++] = job->items[i].paths[k] + root + 1;
  qsort(made, n, sizeof *made, by_string);
  tree g;
  memset(&g, 0, sizeof g);
  struct stat s;
  bb_status st = stat(c->golden, &s) == 0 ? tree_read(&g, c->golden, err) : BB_OK;
  if (st != BB_OK || !g.root) {
    free(made);
    return st;
  }
  for (int i = 0; i < g.count && st == BB_OK; i++) {
    const char *rel = g.files[i].rel;
    if (bsearch(&rel, made, n, sizeof *made, by_string) || g.files[i].refused ||
        !could_be_made(job, rel))
      continue;
    char *path = join(c->golden, rel);
    if (!path)
      st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
    else if (is_baked_map(path))
      st = tree_case(c, rel, path, NULL, NULL, NULL, each, user, err);
    free(path);
  }
  tree_free(&g);
  free(made);
  return st;
}

/* ------------------------------------------------------------------ runs */

bb_status bb_check_run_rest(bb_check *c, bb_check_case_fn each, void *user,
                            bb_error *err) {
  if (!c)
    return bb__fail(err, BB_ERR_ARGUMENT, "check: no check");
  bb_status st;
  struct stat s;
  if (c->setup.job)
    st = check_unmade(c, each, user, err);
  else if (stat(c->fresh, &s) == 0 && !S_ISDIR(s.st_mode)) /* (a golden may be missing) */
    st = check_files(c, each, user, err);
  else
    st = check_trees(c, each, user, err);
  if (st == BB_OK)
    st = bb__check_pictures_flush(&c->atlas, err);
  return st;
}

int bb_check_input_count(const bb_check *c) {
  return c && c->setup.job ? bb_job_count(c->setup.job) : 0;
}

const char *bb_check_input(const bb_check *c, int i) {
  const bb_job_report *r = c && c->setup.job ? bb_job_report_get(c->setup.job, i) : NULL;
  return r ? r->input : NULL;
}

/* ------------------------------------------------------- what is printed */

static void json_case(FILE *f, const bb_check_case *k) {
  bb__json j = {f, 0};
  bb__json_open(&j, NULL, '{');
  bb__json_string(&j, "name", k->name);
  bb__json_string(&j, "golden", k->golden);
  bb__json_string(&j, "new", k->fresh);
  bb__json_string(&j, "kind", k->kind);
  bb__json_string(&j, "result", bb__check_status_name(k->status));
  bb__json_int(&j, "exit", k->exit_code);
  if (k->width)
    bb__json_int(&j, "width", k->width), bb__json_int(&j, "height", k->height),
        bb__json_int(&j, "channels", k->channels);
  if (k->status <= BB_CHECK_FAILURE)
    bb__compare_json(&j, &k->stats, &k->limits);
  if (k->provenance_diff)
    bb__json_lines(&j, "provenance_diff", k->provenance_diff);
  if (k->message[0])
    bb__json_string(&j, "message", k->message);
  bb__json_bool(&j, "updated", k->updated);
  if (k->update_error)
    bb__json_string(&j, "update_error", k->update_error);
  bb__json_number(&j, "seconds", k->seconds);
  bb__json_close(&j, '}');
  fputc('\n', f);
}

/* Text built through a memory stream (the JSON writer writes to FILEs). */
typedef struct stream {
  FILE *f;
  char *data;
  size_t size;
} stream;

static int stream_open(stream *s) {
  s->data = NULL;
  s->size = 0;
  s->f = open_memstream(&s->data, &s->size);
  return s->f != NULL;
}

static char *stream_take(stream *s) {
  if (fclose(s->f) != 0) {
    free(s->data);
    return NULL;
  }
  return s->data;
}

/* A line made printable (bb_text_printable) on f: first when given, else
 * two spaces and `indented`. */
static void print_line(FILE *f, const char *first, const char *indented) {
  const char *s = first ? first : indented ? indented : "";
  const size_t cap = 4 * strlen(s) + 1;
  char *printable = malloc(cap);
  if (!printable)
    return;
  bb_text_printable(s, printable, cap);
  fprintf(f, "%s%s\n", first ? "" : "  ", printable);
  free(printable);
}

char *bb_check_case_lines(const bb_check *c, const bb_check_case *k) {
  if (!c || !k)
    return NULL;
  if (c->setup.quiet)
    return strdup("");
  stream s;
  if (!stream_open(&s))
    return NULL;
  if (c->setup.json) {
    json_case(s.f, k);
    return stream_take(&s);
  }
  if (k->status != BB_CHECK_PASS) {
    char *account = bb__check_case_text(k);
    if (!account) {
      fclose(s.f);
      free(s.data);
      return NULL;
    }
    /* "STATUS NAME (KIND): " then the account's lines, those after the
     * first indented; every line made printable (names and provenance
     * values come from files) */
    bb__text head = {0};
    bb__text_printf(&head, "%s %s", bb__check_status_name(k->status), k->name);
    if (k->kind[0])
      bb__text_printf(&head, " (%s)", k->kind);
    bb__text_add(&head, ": ");
    for (const char *line = account; *line;) {
      const size_t n = strcspn(line, "\n");
      char *one = strndup(line, n);
      if (line == account)
        bb__text_add(&head, one ? one : "");
      print_line(s.f, line == account ? (head.data ? head.data : "") : NULL, one);
      free(one);
      line += n + (line[n] == '\n');
    }
    bb__text_free(&head);
    free(account);
  }
  if (k->updated) {
    char *line = malloc(strlen(k->golden) + 9);
    if (line)
      sprintf(line, "updated %s", k->golden);
    print_line(s.f, line, NULL);
    free(line);
  }
  return stream_take(&s);
}

char *bb_check_summary_lines(const bb_check *c) {
  if (!c)
    return NULL;
  if (c->setup.quiet)
    return strdup("");
  int counts[BB_CHECK_EXTRA + 1] = {0}, updated = 0;
  for (int i = 0; i < c->count; i++) {
    counts[c->cases[i]->pub.status]++;
    updated += c->cases[i]->pub.updated;
  }
  stream s;
  if (!stream_open(&s))
    return NULL;
  if (c->setup.json) {
    bb__json j = {s.f, 0};
    bb__json_open(&j, NULL, '{');
    bb__json_string(&j, "summary", "check");
    bb__json_int(&j, "maps", c->count);
    static const char *const keys[] = {"passed",         "warnings",   "failures",
                                       "different_size", "unreadable", "missing",
                                       "extra"};
    for (int k = 0; k <= BB_CHECK_EXTRA; k++)
      bb__json_int(&j, keys[k], counts[k]);
    bb__json_int(&j, "updated", updated);
    bb__json_int(&j, "exit", bb_check_exit_code(c));
    bb__json_close(&j, '}');
    fputc('\n', s.f);
    return stream_take(&s);
  }
  fprintf(s.f,
          "check: %d map%s: %d passed, %d warning%s, %d failed, %d of another size, "
          "%d unreadable, %d missing, %d extra",
          c->count, c->count == 1 ? "" : "s", counts[BB_CHECK_PASS],
          counts[BB_CHECK_WARNING], counts[BB_CHECK_WARNING] == 1 ? "" : "s",
          counts[BB_CHECK_FAILURE], counts[BB_CHECK_DIFFERENT_SIZE],
          counts[BB_CHECK_UNREADABLE], counts[BB_CHECK_MISSING], counts[BB_CHECK_EXTRA]);
  if (c->setup.update)
    fprintf(s.f, "; %d golden%s updated", updated, updated == 1 ? "" : "s");
  fputc('\n', s.f);
  return stream_take(&s);
}

/* --------------------------------------------------------------- reports */

bb_status bb_check_write_reports(bb_check *c, bb_error *err) {
  if (!c)
    return bb__fail(err, BB_ERR_ARGUMENT, "check: no check");
  bb_status st = bb__check_pictures_flush(&c->atlas, err);
  if (st == BB_OK && c->junit)
    st = bb__check_junit(c->junit, c->golden, c->cases, c->count, err);
  if (st == BB_OK && c->html)
    st = bb__check_html(c->html, c->golden, c->cases, c->count, err);
  if (st == BB_OK && c->html)
    bb__check_pictures_prune(c->html, c->cases, c->count);
  return st;
}

/* ---------------------------------------------------- export and import */

/* A case's fields as NUL-terminated texts, in this order; an optional
 * string starts with '+', or is "-" when there is none. */
static const char EXPORT_MAGIC[] = "bb-check-cases-1";

static void put_text(bb__text *t, const char *s) {
  bb__text_append(t, s, strlen(s) + 1);
}

static void put_optional(bb__text *t, const char *s) {
  if (!s) {
    put_text(t, "-");
    return;
  }
  bb__text_append(t, "+", 1);
  put_text(t, s);
}

static void put_number(bb__text *t, double v) {
  char buf[40];
  snprintf(buf, sizeof buf, "%.17g", v);
  put_text(t, buf);
}

char *bb_check_export(bb_check *c, int first, size_t *size) {
  if (!c || !size || bb__check_pictures_flush(&c->atlas, NULL) != BB_OK)
    return NULL;
  bb__text t = {0};
  put_text(&t, EXPORT_MAGIC);
  for (int i = first < 0 ? 0 : first; i < c->count; i++) {
    const bb__check_case *k = c->cases[i];
    const bb_check_case *p = &k->pub;
    put_text(&t, k->name);
    put_text(&t, k->golden);
    put_optional(&t, k->fresh);
    put_text(&t, k->kind);
    const double numbers[] = {p->status,
                              p->limits.fail,
                              p->limits.fail_percent,
                              p->limits.hard_fail,
                              (double)p->limits.allow_failures,
                              p->limits.warn,
                              p->limits.warn_percent,
                              p->limits.hard_warn,
                              p->width,
                              p->height,
                              p->channels,
                              p->new_width,
                              p->new_height,
                              p->new_channels,
                              p->stats.mean_abs,
                              p->stats.rms,
                              p->stats.max_abs,
                              p->stats.worst_x,
                              p->stats.worst_y,
                              p->stats.worst_channel,
                              (double)p->stats.pixels,
                              (double)p->stats.over_fail,
                              (double)p->stats.over_warn,
                              p->updated,
                              p->seconds,
                              k->thumb_cell,
                              k->thumb_width,
                              k->thumb_height,
                              k->strip_width,
                              k->strip_height,
                              k->strip_parts,
                              k->heat_max};
    for (size_t n = 0; n < sizeof numbers / sizeof numbers[0]; n++)
      put_number(&t, numbers[n]);
    put_optional(&t, k->provenance_diff);
    put_optional(&t, k->message);
    put_optional(&t, k->update_error);
    put_optional(&t, k->thumbs);
    put_optional(&t, k->strip);
  }
  if (t.failed) {
    free(t.data);
    return NULL;
  }
  *size = t.length;
  return t.data;
}

/* Reads the texts of an export one by one. */
typedef struct reader {
  const char *at, *end;
  int bad;
} reader;

static const char *next_text(reader *r) {
  const char *nul = r->bad ? NULL : memchr(r->at, '\0', (size_t)(r->end - r->at));
  if (!nul) {
    r->bad = 1;
    return "";
  }
  const char *s = r->at;
  r->at = nul + 1;
  return s;
}

/* A copy of an optional string (NULL for "-"); *ok 0 when memory ran out
 * or the field is not one. */
static char *next_optional(reader *r, int *ok) {
  const char *s = next_text(r);
  if (s[0] == '-' && !s[1])
    return NULL;
  if (s[0] != '+') {
    r->bad = 1;
    return NULL;
  }
  char *copied = strdup(s + 1);
  *ok &= copied != NULL;
  return copied;
}

static double next_number(reader *r) {
  const char *s = next_text(r);
  char *end;
  const double v = strtod(s, &end);
  if (end == s || *end)
    r->bad = 1;
  return v;
}

bb_status bb_check_import(bb_check *c, const char *data, size_t size, bb_error *err) {
  if (!c || (!data && size))
    return bb__fail(err, BB_ERR_ARGUMENT, "check import: bad arguments");
  reader r = {data, data + size, 0};
  if (!size || strcmp(next_text(&r), EXPORT_MAGIC) != 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "check import: not the cases of a check");
  while (!r.bad && r.at < r.end) {
    const char *name = next_text(&r), *golden = next_text(&r);
    int ok = 1;
    char *fresh = next_optional(&r, &ok);
    const char *kind = next_text(&r);
    double v[32];
    for (size_t n = 0; n < sizeof v / sizeof v[0]; n++)
      v[n] = next_number(&r);
    bb__check_case *k = r.bad ? NULL : bb__check_case_new(name, golden, fresh, kind);
    free(fresh);
    if (!k)
      return r.bad ? bb__fail(err, BB_ERR_ARGUMENT, "check import: a case is cut short")
                   : bb__fail(err, BB_ERR_MEMORY, "out of memory");
    bb_check_case *p = &k->pub;
    const int status = (int)v[0];
    if (status < BB_CHECK_PASS || status > BB_CHECK_EXTRA)
      r.bad = 1;
    p->status = (bb_check_status)status;
    p->limits = (bb_compare_limits){v[1], v[2], v[3], (long)v[4], v[5], v[6], v[7]};
    p->width = (int)v[8], p->height = (int)v[9], p->channels = (int)v[10];
    p->new_width = (int)v[11], p->new_height = (int)v[12], p->new_channels = (int)v[13];
    p->stats =
        (bb_compare_stats){v[14],      v[15],       v[16],       (int)v[17], (int)v[18],
                           (int)v[19], (long)v[20], (long)v[21], (long)v[22]};
    p->updated = (int)v[23];
    p->seconds = v[24];
    k->thumb_cell = (int)v[25], k->thumb_width = (int)v[26], k->thumb_height = (int)v[27];
    k->strip_width = (int)v[28], k->strip_height = (int)v[29],
    k->strip_parts = (int)v[30];
    k->heat_max = v[31];
    k->provenance_diff = next_optional(&r, &ok);
    k->message = next_optional(&r, &ok);
    k->update_error = next_optional(&r, &ok);
    k->thumbs = next_optional(&r, &ok);
    k->strip = next_optional(&r, &ok);
    /* the pictures are files of the report's folder, by the names the
     * check gives them: nothing else gets into a page */
    if ((k->thumbs && !bb__check_picture_path(k->thumbs)) ||
        (k->strip && !bb__check_picture_path(k->strip)))
      r.bad = 1;
    if (r.bad || !ok) {
      bb__check_case_free(k);
      return r.bad ? bb__fail(err, BB_ERR_ARGUMENT, "check import: a case is cut short")
                   : bb__fail(err, BB_ERR_MEMORY, "out of memory");
    }
    if (bb__check_add(c, k, NULL, NULL, err) != BB_OK)
      return BB_ERR_MEMORY;
  }
  return BB_OK;
}
