/* write.c: a command's outputs written all or nothing. Every file is
 * encoded and synced under a temporary name first (several at once: zlib
 * is most of a write), and the set is renamed into place only when all of
 * them are complete; a signal that arrives during the renames waits for
 * the last one, so an interrupted command leaves the set all old or all
 * new. */
#include "core/internal.h"
#include "files/safe_file.h"
#include "image/image_write.h"
#include "image/oiio.h"
#include "job/job_internal.h"
#include "texture/blocks.h"
#include "texture/texture.h"

#include <errno.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- signals */

/* Sets being renamed into place right now, on any thread, and a signal
 * that arrived meanwhile. The handler stores the signal first and then
 * looks at the count; the committer lowers the count first and then looks
 * at the signal (both sequentially consistent), so one of the two always
 * sees the other and the process ends exactly once the last set is whole. */
static atomic_int commits_in_flight;
static atomic_int pending_signal;

static void die_of(int signal_number) {
  bb__tempfiles_remove();
  struct sigaction dfl;
  memset(&dfl, 0, sizeof dfl);
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  sigaction(signal_number, &dfl, NULL);
  /* In a handler the signal is blocked until it returns, and is then
   * delivered with its default action; elsewhere it ends us here. */
  raise(signal_number);
}

void bb_signal_cleanup(int signal_number) {
  const int saved_errno = errno;
  atomic_store(&pending_signal, signal_number);
  if (atomic_load(&commits_in_flight) == 0)
    die_of(signal_number);
  errno = saved_errno;
}

static void commit_begin(void) {
  atomic_fetch_add(&commits_in_flight, 1);
}

static void commit_end(void) {
  atomic_fetch_sub(&commits_in_flight, 1);
  const int sig = atomic_load(&pending_signal);
  if (sig && atomic_load(&commits_in_flight) == 0)
    die_of(sig);
}

/* --------------------------------------------------------------- staging */

/* One file of the set as it goes: staged, then put in place. */
typedef struct staged {
  const bb_output_file *file;
  int threads;            /* the set's: an OpenEXR file's chunks are
                             compressed on these (image/image_write.h) */
  bb_staged_file *handle; /* NULL when staging failed */
  bb_status status;
  bb_error error;
  bb__blocks_watch *watch; /* the set's block compression stage, or NULL */
} staged;

/* Text bytes under a temporary name, synced: the staged twin of bb__file_write. */
static bb_status stage_text(const bb_output_file *o, bb_staged_file **out, bb_error *err) {
  *out = NULL;
  if (!o->text && o->text_size)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: no text to write", o->path);
  bb_staged_file *f = bb__staged_new();
  if (!f)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", o->path);
  bb_status st = bb__safe_open(f, o->path, err);
  if (st == BB_OK) {
    bb__safe_write(f, o->text, o->text_size); /* an error is kept and reported next */
    st = bb__safe_finish(f, err);
  }
  if (st != BB_OK) {
    bb__safe_discard(f);
    free(f);
    return st;
  }
  *out = f;
  return BB_OK;
}

/* An image's mip chain, renormalised for normal maps, as one staged file. */
static bb_status stage_mips(const bb_output_file *o, const bb_write_options *wo, int threads,
                            bb_staged_file **out, bb_error *err) {
  bb_image *levels = NULL;
  int count = 0;
  bb_status st =
      bb_mip_chain(o->image, bb__mip_filter(o->range == BB_RANGE_SIGNED), &levels, &count, err);
  if (st == BB_OK)
    st = bb__image_write_mips_staged(o->path, levels, count, wo, threads, out, err);
  bb_mip_chain_free(levels, count);
  return st;
}

static void stage_one(void *user, int item) {
  staged *s = (staged *)user + item;
  const bb_output_file *o = s->file;
  s->handle = NULL;
  memset(&s->error, 0, sizeof s->error);
  if (!o->image) {
    s->status = stage_text(o, &s->handle, &s->error);
    return;
  }
  if (bb__path_is_texture_format(o->path)) {
    /* A texture makes its own chain (its mips option), as the map its kind is. */
    const bb_texture_options t = bb__job_texture_of(o->texture, o->kind, o->range);
    const bb_write_options wo = {o->depth, o->range, o->description, &t};
    bb__blocks_watch_thread(s->watch);
    s->status = bb__image_write_staged_all_cores(o->path, o->image, &wo, &s->handle, &s->error);
    bb__blocks_watch_thread(NULL);
    return;
  }
  const bb_write_options wo = {o->depth, o->range, o->description, NULL};
  s->status = o->mips ? stage_mips(o, &wo, s->threads, &s->handle, &s->error)
                      : bb__image_write_staged(o->path, o->image, &wo, s->threads, &s->handle,
                                               &s->error);
}

/* --------------------------------------------------------------- commits */

bb_status bb__staged_files_commit(bb_staged_file **files, const char *const *kinds, int count,
                                 bb_error *err) {
  if (count < 0 || (count > 0 && !files))
    return bb__fail(err, BB_ERR_ARGUMENT, "staged files commit: bad arguments");
  /* The paths of the ones renamed, for the message should a later one fail. */
  char **done = calloc((size_t)(count ? count : 1), sizeof *done);
  int failed = -1;
  bb_error why = {{0}};
  commit_begin();
  for (int i = 0; i < count && failed < 0; i++) {
    char *path = done ? strdup(bb__staged_file_path(files[i])) : NULL;
    bb_status st = bb__staged_file_commit(files[i], &why);
    files[i] = NULL;
    if (st != BB_OK)
      failed = i, free(path);
    else if (done)
      done[i] = path;
  }
  commit_end();
  bb_status st = BB_OK;
  if (failed >= 0) {
    for (int i = failed + 1; i < count; i++) {
      bb__staged_file_discard(files[i]);
      files[i] = NULL;
    }
    char reason[2 * sizeof(bb_error)];
    snprintf(reason, sizeof reason, "%s", why.message[0] ? why.message : "cannot rename");
    size_t len = strlen(reason);
    for (int i = 0; i < failed && len < sizeof reason; i++)
      len += (size_t)snprintf(reason + len, sizeof reason - len, "%s%s %s",
                              i ? ", " : "; already written: ",
                              kinds && kinds[i] ? kinds[i] : "file",
                              done && done[i] ? done[i] : "?");
    if (failed == 0 && count > 1 && len < sizeof reason)
      snprintf(reason + len, sizeof reason - len, "; no output was written");
    st = bb__fail(err, BB_ERR_IO, "%s", reason);
  }
  for (int i = 0; done && i < count; i++)
    free(done[i]);
  free(done);
  return st;
}

long bb__outputs_block_rows(const bb_output_file *files, int count) {
  long rows = 0;
  for (int i = 0; files && i < count; i++) {
    const bb_output_file *o = &files[i];
    if (!o->image || !bb__path_is_texture_format(o->path))
      continue;
    const bb_texture_options t = bb__job_texture_of(o->texture, o->kind, o->range);
    rows += bb__texture_block_rows(o->path, o->image->width, o->image->height,
                                   o->image->channels, &t);
  }
  return rows;
}

bb_status bb_outputs_write(const bb_output_file *files, int count, int threads, bb_error *err) {
  return bb__outputs_write(files, count, threads, NULL, err);
}

bb_status bb__outputs_write(const bb_output_file *files, int count, int threads,
                            bb__blocks_watch *watch, bb_error *err) {
  if (count < 0 || (count > 0 && !files))
    return bb__fail(err, BB_ERR_ARGUMENT, "outputs write: bad arguments");
  if (count == 0)
    return BB_OK;
  staged *set = calloc((size_t)count, sizeof *set);
  if (!set)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", files[0].path);
  for (int i = 0; i < count; i++)
    set[i].file = &files[i], set[i].threads = threads, set[i].watch = watch;
  /* Files are encoded side by side, at most one thread per file; within a
   * file, an engine texture's blocks and an OpenEXR file's chunks are
   * compressed on `threads` more (the bytes are the same on any count). */
  int workers = threads <= 0 || threads > count ? count : threads;
  bb_status st = bb__parallel_for(count, workers, stage_one, set, NULL, NULL, err);
  int failed = -1;
  for (int i = 0; i < count && failed < 0 && st == BB_OK; i++)
    if (set[i].status != BB_OK)
      failed = i;
  if (st == BB_OK && failed < 0) {
    bb_staged_file **handles = malloc((size_t)count * sizeof *handles);
    const char **kinds = malloc((size_t)count * sizeof *kinds);
    if (!handles || !kinds) {
      st = bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", files[0].path);
    } else {
      for (int i = 0; i < count; i++) {
        handles[i] = set[i].handle;
        kinds[i] = files[i].kind;
        set[i].handle = NULL;
      }
      st = bb__staged_files_commit(handles, kinds, count, err);
    }
    free(handles);
    free(kinds);
    failed = -1; /* the commit's message is the whole story */
  }
  for (int i = 0; i < count; i++)
    bb__staged_file_discard(set[i].handle);
  if (st == BB_OK && failed >= 0) {
    char reason[2 * sizeof(bb_error)];
    snprintf(reason, sizeof reason, "%s",
             set[failed].error.message[0] ? set[failed].error.message
                                           : bb_status_name(set[failed].status));
    if (count > 1 && strlen(reason) < sizeof reason)
      snprintf(reason + strlen(reason), sizeof reason - strlen(reason),
               "; no output was written");
    st = bb__fail(err, set[failed].status, "%s", reason);
  }
  free(set);
  return st;
}
