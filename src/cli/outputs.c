/* cli_outputs.c: checking output paths before a bake, and writing outputs
 * with provenance: one at a time, or staged and committed all or nothing. */
#include "common.h"

#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ---------------------------------------------------------------- outputs */

/* Lower-case extension of path's last component, without the dot ("" when
 * none), into buf. */
static const char *path_extension(const char *path, char *buf, size_t cap) {
  const char *slash = strrchr(path, '/');
  const char *dot = strrchr(slash ? slash + 1 : path, '.');
  size_t n = 0;
  if (dot)
    for (const char *c = dot + 1; *c && n + 1 < cap; c++)
      buf[n++] = (char)((*c >= 'A' && *c <= 'Z') ? *c - 'A' + 'a' : *c);
  buf[n] = '\0';
  return buf;
}

static const char *depth_name(bb_depth d) {
  switch (d) {
  case BB_DEPTH_8:
    return "8";
  case BB_DEPTH_16:
    return "16";
  case BB_DEPTH_HALF:
    return "half";
  case BB_DEPTH_FLOAT:
    return "float";
  case BB_DEPTH_DEFAULT:
    break;
  }
  return "default";
}

/* The directory part of path ("." when none), into dir. */
static void directory_part(const char *path, char *dir, size_t cap) {
  const char *slash = strrchr(path, '/');
  if (!slash)
    snprintf(dir, cap, ".");
  else if (slash == path)
    snprintf(dir, cap, "/");
  else
    snprintf(dir, cap, "%.*s", (int)(slash - path), path);
}

/* The directory entry a write of path replaces: its directory's device and
 * inode and its last component. Returns 0 when the directory exists. */
typedef struct dir_entry {
  dev_t dev;
  ino_t ino;
  const char *name;
} dir_entry;

static int entry_of(const char *path, dir_entry *e) {
  char dir[PATH_MAX];
  directory_part(path, dir, sizeof dir);
  struct stat st;
  if (stat(dir, &st) != 0)
    return -1;
  const char *slash = strrchr(path, '/');
  e->dev = st.st_dev;
  e->ino = st.st_ino;
  e->name = slash ? slash + 1 : path;
  return 0;
}

int cli_same_file(const char *a, const char *b) {
  /* Two names of one existing file (symbolic or hard links, "./", ".."). */
  struct stat sa, sb;
  if (stat(a, &sa) == 0 && stat(b, &sb) == 0)
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  /* Files not made yet: the same name in the same directory, however the
   * directory is spelled. */
  dir_entry ea, eb;
  if (entry_of(a, &ea) == 0 && entry_of(b, &eb) == 0)
    return ea.dev == eb.dev && ea.ino == eb.ino && strcmp(ea.name, eb.name) == 0;
  return strcmp(a, b) == 0;
}

int cli_check_output_directory(const char *path) {
  char dir[PATH_MAX];
  directory_part(path, dir, sizeof dir);
  struct stat st;
  if (stat(dir, &st) != 0) {
    char reason[PATH_MAX + 128];
    snprintf(reason, sizeof reason, "cannot write: directory %s: %s", dir,
             strerror(errno));
    cli_file_error(path, reason);
    return BB_EXIT_FAILURE;
  }
  if (!S_ISDIR(st.st_mode)) {
    char reason[PATH_MAX + 128];
    snprintf(reason, sizeof reason, "cannot write: %s is not a directory", dir);
    cli_file_error(path, reason);
    return BB_EXIT_FAILURE;
  }
  return 0;
}

int cli_check_output(const char *command, const char *input_path, const char *output_path,
                     bb_depth depth) {
  char ext[16];
  if (!bb_path_is_writable_format(output_path)) {
    if (!path_extension(output_path, ext, sizeof ext)[0])
      return cli_usage_error(command,
                             "%s: no extension to choose the format by (use .png, .tga, "
                             ".tif, .tiff or .exr)",
                             output_path);
    return cli_usage_error(
        command, "%s: unknown output format '.%s' (use .png, .tga, .tif, .tiff or .exr)",
        output_path, ext);
  }
  /* Checked before baking, so a bad combination fails before a long bake. */
  if (!bb_path_supports_depth(output_path, depth))
    return cli_usage_error(command, "%s: --depth %s is not available in .%s files",
                           output_path, depth_name(depth),
                           path_extension(output_path, ext, sizeof ext));
  if (cli_same_file(input_path, output_path)) {
    cli_file_error(output_path, "output would overwrite the input file");
    return BB_EXIT_FAILURE;
  }
  return cli_check_output_directory(output_path);
}

char *cli_path_with_suffix(const char *path, const char *suffix) {
  const char *slash = strrchr(path, '/');
  const char *dot = strrchr(slash ? slash + 1 : path, '.');
  size_t stem = dot ? (size_t)(dot - path) : strlen(path);
  size_t len = stem + strlen(suffix) + 1;
  char *out = malloc(len);
  if (out)
    snprintf(out, len, "%.*s%s", (int)stem, path, suffix);
  return out;
}

int cli_check_mips(const char *command, const cli_settings *s, const char *output_path) {
  if (!s->mips || bb_path_supports_mips(output_path))
    return 0;
  return cli_usage_error(command, "%s: --mips needs a .tif or .exr output", output_path);
}

/* img's mip chain (renormalised when wo->range is BB_RANGE_SIGNED) written
 * as one file: at path, or staged into *staged when staged is not NULL. */
static bb_status write_mip_file(const char *path, const bb_image *img,
                                const bb_write_options *wo, bb_staged_file **staged,
                                bb_error *err) {
  bb_image *levels = NULL;
  int count = 0;
  bb_mip_filter filter = wo->range == BB_RANGE_SIGNED ? BB_MIP_RENORMALIZE : BB_MIP_AVERAGE;
  bb_status st = bb_mip_chain(img, filter, &levels, &count, err);
  if (st == BB_OK)
    st = staged ? bb_image_write_mips_staged(path, levels, count, wo, staged, err)
                : bb_image_write_mips(path, levels, count, wo, err);
  bb_mip_chain_free(levels, count);
  return st;
}

bb_status cli_write_image(const char *path, const bb_image *img, const bb_write_options *wo,
                          int mips, bb_error *err) {
  return mips ? write_mip_file(path, img, wo, NULL, err) : bb_image_write(path, img, wo, err);
}

/* cli_write_image staged (complete under a temporary name) into *staged. */
static bb_status stage_image(const char *path, const bb_image *img, const bb_write_options *wo,
                             int mips, bb_staged_file **staged, bb_error *err) {
  *staged = NULL;
  return mips ? write_mip_file(path, img, wo, staged, err)
              : bb_image_write_staged(path, img, wo, staged, err);
}

static const char *file_name_of(const char *path) {
  const char *slash = strrchr(path, '/');
  return slash ? slash + 1 : path;
}

int cli_run_init(cli_run *run, int argc, char **argv) {
  memset(run, 0, sizeof *run);
  size_t len = strlen("bumpbake") + 1;
  for (int i = 0; i < argc; i++)
    len += strlen(argv[i]) + 1;
  run->command_line = malloc(len);
  if (!run->command_line) {
    fprintf(stderr, "bumpbake: out of memory\n");
    return BB_EXIT_FAILURE;
  }
  strcpy(run->command_line, "bumpbake");
  for (int i = 0; i < argc; i++) {
    strcat(run->command_line, " ");
    strcat(run->command_line, argv[i]);
  }
  return 0;
}

void cli_run_set_input(cli_run *run, const char *input_path, const bb_image *height,
                       const cli_settings *settings) {
  run->input_path = input_path;
  run->input_hash = bb_image_hash(height);
  if (!run->input_file_hash && bb_file_hash(input_path, &run->input_file_hash, NULL) != BB_OK)
    run->input_file_hash = 0; /* provenance then leaves the key out */
  run->settings = settings;
}

void cli_run_free(cli_run *run) {
  free(run->command_line);
  run->command_line = NULL;
}

/* The write options of one output of run: its depth and range and a
 * provenance description of kind (malloc'd into *description). */
static bb_status output_options(const cli_run *run, const char *kind, bb_range range,
                                bb_write_options *wo, char **description, bb_error *err) {
  bb_provenance p = {
      run->command_line,    file_name_of(run->input_path), run->input_hash, kind,
      &run->settings->bake, run->settings->channel,        run->rayset_id,
      run->input_file_hash};
  *description = bb_provenance_format(&p);
  if (!*description) {
    snprintf(err->message, sizeof err->message, "out of memory");
    return BB_ERR_MEMORY;
  }
  *wo = (bb_write_options){run->settings->depth, range, *description};
  return BB_OK;
}

int cli_write_output(cli_run *run, const char *kind, const char *path,
                     const bb_image *img, bb_range range) {
  bb_write_options wo;
  char *description = NULL;
  bb_error err = {{0}};
  bb_status st = output_options(run, kind, range, &wo, &description, &err);
  double t0 = cli_now_seconds();
  if (st == BB_OK)
    st = cli_write_image(path, img, &wo, run->settings->mips, &err);
  run->seconds_write += cli_now_seconds() - t0;
  free(description);
  return cli_status_exit(path, st, &err);
}

void cli_stage_output(const cli_run *run, cli_staged_output *out, const bb_image *img,
                      bb_range range) {
  bb_write_options wo;
  char *description = NULL;
  out->file = NULL;
  memset(&out->error, 0, sizeof out->error);
  out->status = output_options(run, out->kind, range, &wo, &description, &out->error);
  if (out->status == BB_OK)
    out->status = stage_image(out->path, img, &wo, run->settings->mips, &out->file,
                              &out->error);
  free(description);
}

/* The tasks of one cli_stage_outputs call, handed out in order. */
typedef struct stage_queue {
  const cli_stage_task *tasks;
  int n;
  atomic_int next;
} stage_queue;

static void *stage_worker(void *arg) {
  stage_queue *q = arg;
  for (int i; (i = atomic_fetch_add(&q->next, 1)) < q->n;) {
    const cli_stage_task *t = &q->tasks[i];
    cli_stage_output(t->run, t->out, t->image, t->range);
  }
  return NULL;
}

enum { MAX_STAGE_HELPERS = 15 };

void cli_stage_outputs(const cli_stage_task *tasks, int n, int threads) {
  stage_queue q = {.tasks = tasks, .n = n};
  atomic_init(&q.next, 0);
  int helpers = (threads <= 0 || threads > n ? n : threads) - 1;
  if (helpers > MAX_STAGE_HELPERS)
    helpers = MAX_STAGE_HELPERS;
  pthread_t tids[MAX_STAGE_HELPERS];
  int started = 0;
  while (started < helpers && pthread_create(&tids[started], NULL, stage_worker, &q) == 0)
    started++;
  /* The calling thread works too, so a helper that could not start only
   * makes the stage slower. */
  stage_worker(&q);
  for (int i = 0; i < started; i++)
    pthread_join(tids[i], NULL);
}

/* Appends to text (capacity cap) the outputs in place, or says that none
 * is. */
static void describe_written(const cli_staged_output *outs, int n, char *text, size_t cap) {
  size_t len = strlen(text);
  int any = 0;
  for (int i = 0; i < n && len < cap; i++) {
    if (!outs[i].written)
      continue;
    len += (size_t)snprintf(text + len, cap - len, "%s%s %s",
                            any ? ", " : "; already written: ", outs[i].kind, outs[i].path);
    any = 1;
  }
  if (!any && len < cap)
    snprintf(text + len, cap - len, "; no output was written");
}

static void discard_all(cli_staged_output *outs, int n) {
  for (int i = 0; i < n; i++) {
    bb_staged_file_discard(outs[i].file);
    outs[i].file = NULL;
  }
}

int cli_commit_outputs(cli_staged_output *outs, int n) {
  int failed = -1;
  for (int i = 0; i < n; i++) {
    outs[i].written = 0;
    if (failed < 0 && outs[i].status != BB_OK)
      failed = i;
  }
  /* All or nothing: one failure discards every staged file. Only a rename
   * can still fail after this, which leaves the ones before it in place. */
  for (int i = 0; i < n && failed < 0; i++) {
    bb_staged_file *f = outs[i].file;
    outs[i].file = NULL;
    outs[i].status = bb_staged_file_commit(f, &outs[i].error);
    if (outs[i].status == BB_OK)
      outs[i].written = 1;
    else
      failed = i;
  }
  discard_all(outs, n);
  if (failed < 0)
    return 0;
  char reason[2 * sizeof(bb_error)];
  snprintf(reason, sizeof reason, "%s",
           outs[failed].error.message[0] ? outs[failed].error.message
                                         : bb_status_name(outs[failed].status));
  if (n > 1)
    describe_written(outs, n, reason, sizeof reason);
  cli_file_error(outs[failed].path, reason);
  return BB_EXIT_FAILURE;
}
