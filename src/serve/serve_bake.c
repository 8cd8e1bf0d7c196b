/* serve_bake.c: `bumpbake serve`'s bake thread: whenever a save or a
 * control asks, plans the job of the current options and bakes its input
 * through it (bb_job_bake_item: the very read and bake `bumpbake bake`
 * runs, nothing written), then publishes the maps, which become the
 * page's 8-bit textures as the page asks for them; the job and the float
 * maps are kept for "write" (bb_job_write_item).
 * A newer request cancels the bake in flight through the progress
 * callback; a failure keeps the last good maps and shows why. */
#include "../cli/common.h"
#include "serve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

static double now_seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void serve_request_bake(serve_state *s) {
  atomic_fetch_add(&s->wanted, 1);
  pthread_cond_signal(&s->work);
}

static void free_maps(serve_bake *b) {
  bb_bake_result_free(&b->maps);
  bb_job_free(b->job);
  b->job = NULL;
}

void serve_bake_release(serve_bake *b) {
  if (!b || --b->refs > 0)
    return;
  for (int t = 0; t < SERVE_TEX_COUNT; t++) {
    free(b->tex[t]);
    free(b->part[t]);
  }
  free_maps(b);
  pthread_mutex_destroy(&b->tex_lock);
  free(b->provenance);
  free(b->command);
  free(b);
}

serve_bake *serve_maps_use(serve_state *s) {
  serve_bake *b = s->current;
  if (!b || b->maps_shed)
    return NULL;
  b->refs++;
  b->maps_users++;
  return b;
}

void serve_maps_done(serve_bake *b) {
  if (--b->maps_users == 0 && b->maps_shed)
    free_maps(b);
}

/* b is no longer shown: its maps and job go now, or with their last user.
 * The caller holds the lock. */
static void shed_maps(serve_bake *b) {
  b->maps_shed = 1;
  if (b->maps_users == 0)
    free_maps(b);
}

int serve_inputs_changed(const serve_state *s, const serve_bake *b) {
  for (int i = 0; i < s->watched_count; i++) {
    uint64_t now = 0;
    if (bb_file_hash(s->watched[i], &now, NULL) != BB_OK || now != b->input_hashes[i])
      return i;
  }
  return -1;
}

/* ------------------------------------------------------------- progress */

typedef struct progress_ctx {
  serve_state *s;
  long wanted;      /* the request this bake answers */
  long slices;      /* with inter-reflection, the trace's units of the whole (bumpbake.h:
                       bb_command_slices); 0 without */
  long most, total; /* the furthest done seen, and the whole */
} progress_ctx;

/* The stage running, from what the progress callback said so far: nothing
 * yet while the height is read and smoothed, then the trace's units (the
 * first slices ones with inter-reflection, the bounces' after them), then
 * the derived maps once the whole is done. */
static const char *stage_of(const progress_ctx *p) {
  if (p->most == 0)
    return "load and smooth";
  if (p->most >= p->total)
    return "derive";
  return p->slices && p->most > p->slices ? "bounce" : "trace";
}

/* Records the fraction and the stage for the page (a stage at once, the
 * fraction ten times a second at most) and cancels when a newer request
 * came. */
static int on_progress(void *user, long done, long total) {
  progress_ctx *p = user;
  if (atomic_load(&p->s->wanted) != p->wanted || atomic_load(&p->s->quit))
    return 1;
  if (total > 0) {
    p->total = total;
    if (done > p->most)
      p->most = done;
  }
  const char *stage = stage_of(p);
  double now = now_seconds();
  pthread_mutex_lock(&p->s->lock);
  const int moved = total > 0 && now - p->s->last_progress_seconds >= 0.1;
  if (moved || stage != p->s->stage) {
    p->s->last_progress_seconds = now;
    if (total > 0)
      p->s->progress = (double)done / (double)total;
    p->s->stage = stage;
    p->s->version++;
    pthread_cond_broadcast(&p->s->changed);
  }
  pthread_mutex_unlock(&p->s->lock);
  return 0;
}

/* ------------------------------------------------------------- textures */

static unsigned char unit_byte(float v) {
  if (!(v > 0.0f))
    return 0;
  if (v >= 1.0f)
    return 255;
  return (unsigned char)lrintf(v * 255.0f);
}

/* Channels c0..c2 of img (or of nothing: 0) into RGB of tex, unit values or
 * signed vectors ((v + 1) / 2), and alpha from channel 0 of alpha_img; a
 * grey img (1 or 2 channels) fills R, G and B alike. The texels of region
 * r of maps width texels wide, row by row (tex holds r's texels only). */
static void fill(unsigned char *tex, int width, bb_region r, const bb_image *img,
                 int is_vector, const bb_image *alpha_img) {
  const int grey = img && img->channels < 3;
  size_t o = 0;
  for (int y = r.y0; y < r.y0 + r.height; y++)
    for (int x = r.x0; x < r.x0 + r.width; x++, o += 4) {
      const size_t i = (size_t)y * (size_t)width + (size_t)x;
      for (int c = 0; c < 3; c++) {
        float v = img && img->pixels && (grey || c < img->channels)
                      ? img->pixels[i * (size_t)img->channels + (size_t)(grey ? 0 : c)]
                      : 0.0f;
        tex[o + (size_t)c] = unit_byte(is_vector ? 0.5f * (v + 1.0f) : v);
      }
      tex[o + 3] = alpha_img && alpha_img->pixels
                       ? unit_byte(alpha_img->pixels[i * (size_t)alpha_img->channels])
                       : 255;
    }
}

static bb_region whole_of(const serve_bake *b) {
  return (bb_region){0, 0, b->width, b->height};
}

/* Texture t of b's maps within r (malloc'd, 4 bytes a texel), or NULL when
 * out of memory or for the albedo, which is made with the bake. */
static unsigned char *make_texture(const serve_bake *b, int t, bb_region r) {
  const bb_bake_result *m = &b->maps;
  unsigned char *tex = malloc(4 * (size_t)r.width * (size_t)r.height);
  if (!tex)
    return NULL;
  switch (t) {
  case SERVE_TEX_SSBUMP_AO:
    fill(tex, b->width, r, &m->ssbump, 0, &m->ao);
    break;
  case SERVE_TEX_NORMAL_HEIGHT:
    fill(tex, b->width, r, &m->normal, 1, &m->filtered);
    break;
  case SERVE_TEX_BENT:
    fill(tex, b->width, r, &m->bent, 1, NULL);
    break;
  case SERVE_TEX_WEIGHTS:
    fill(tex, b->width, r, &m->weights, 0, NULL);
    break;
  default:
    free(tex);
    return NULL;
  }
  return tex;
}

bb_region serve_part_region(const serve_bake *b, int t) {
  return t == SERVE_TEX_ALBEDO || b->changed.width <= 0 || b->changed.height <= 0
             ? (bb_region){0, 0, 0, 0}
             : b->changed;
}

/* *slot, made from b's maps within r when it is not yet (while b is the
 * bake shown: its maps go once it is not). An empty region gives a
 * pointer to nothing. Holds b's tex_lock. */
static const unsigned char *texture_in(serve_state *s, serve_bake *b, int t, bb_region r,
                                       unsigned char **slot) {
  static const unsigned char nothing[1];
  if (r.width <= 0 || r.height <= 0)
    return nothing;
  pthread_mutex_lock(&b->tex_lock);
  if (!*slot && t != SERVE_TEX_ALBEDO) {
    pthread_mutex_lock(&s->lock);
    const int usable = !b->maps_shed;
    if (usable)
      b->maps_users++;
    pthread_mutex_unlock(&s->lock);
    if (usable) {
      const double t0 = now_seconds();
      *slot = make_texture(b, t, r);
      pthread_mutex_lock(&s->lock);
      b->seconds_textures += now_seconds() - t0;
      serve_maps_done(b);
      pthread_mutex_unlock(&s->lock);
    }
  }
  const unsigned char *tex = *slot;
  pthread_mutex_unlock(&b->tex_lock);
  return tex;
}

const unsigned char *serve_bake_texture(serve_state *s, serve_bake *b, int t) {
  return texture_in(s, b, t, whole_of(b), &b->tex[t]);
}

const unsigned char *serve_bake_part(serve_state *s, serve_bake *b, int t) {
  return texture_in(s, b, t, serve_part_region(b, t), &b->part[t]);
}

/* ----------------------------------------------------------------- bake */

/* Planning a job creates its outputs' folders; a bake writes nothing, not
 * even a folder, until the page asks. So a bake whose outputs' folder is
 * gone (the height's folder moved away, say) is not planned: it fails
 * with the height's own error when the height is gone too (the library's
 * words, read without a plan), else saying which folder is missing. 1 when
 * it fails so (message in err). */
static int folder_gone(const bb_command *bake, const char *input, bb_error *err) {
  char paths[BB_MAP_BAKED_COUNT + 1][4096];
  int n = 0;
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    char *path = NULL;
    if (bb_command_map_file(bake, (bb_map_kind)k, &path, NULL) == BB_OK && path)
      snprintf(paths[n++], sizeof paths[0], "%s", path);
    free(path);
  }
  if (bb_command_value(bake, "slope", paths[n], sizeof paths[0], NULL) == BB_OK && paths[n][0])
    n++;
  for (int i = 0; i < n; i++) {
    const char *slash = strrchr(paths[i], '/');
    if (!slash || slash == paths[i])
      continue;
    char dir[4096];
    snprintf(dir, sizeof dir, "%.*s", (int)(slash - paths[i]), paths[i]);
    struct stat st;
    if (stat(dir, &st) == 0)
      continue;
    if (bb_image_read_info(input, NULL, NULL, NULL, NULL, err) == BB_OK)
      snprintf(err->message, sizeof err->message,
               "%.200s: its folder %.200s is gone (serve makes none until \"write\")",
               paths[i], dir);
    return 1;
  }
  return 0;
}

/* render's --albedo as the page draws it, read with each bake (a save of
 * it bakes again): 8-bit RGBA into *tex, NULL without one. The words of a
 * refusal are render's. */
static bb_status read_albedo(const char *path, int width, int height, unsigned char **tex,
                             bb_error *err) {
  *tex = NULL;
  if (!path)
    return BB_OK;
  bb_image albedo = {0};
  bb_status st = bb_image_read(path, &albedo, NULL, err);
  if (st == BB_OK && (albedo.width != width || albedo.height != height)) {
    snprintf(err->message, sizeof err->message,
             "%.300s: albedo is %dx%d, but the maps are %dx%d", path, albedo.width,
             albedo.height, width, height);
    st = BB_ERR_SIZE;
  }
  const size_t n = (size_t)width * (size_t)height;
  if (st == BB_OK && !(*tex = malloc(4 * n))) {
    snprintf(err->message, sizeof err->message, "out of memory");
    st = BB_ERR_MEMORY;
  }
  if (st == BB_OK)
    fill(*tex, width, (bb_region){0, 0, width, height}, &albedo, 0, NULL);
  bb_image_free(&albedo);
  return st;
}

/* The maps of one bake of input through job: the job's read and bake of the
 * height (bb_job_bake_item, the read and bake `bumpbake bake` runs). The one
 * step a bake of only what an edit changed would stand in for. */
static bb_status bake_maps(serve_state *s, bb_job *job, progress_ctx *p,
                           bb_bake_result *result, bb_error *err) {
  bb_job_use_context(job, s->context); /* this thread's bakes only */
  bb_status st = bb_job_bake_item(job, 0, BB_MAPS_BAKED, on_progress, p, result, err);
  bb_job_use_context(job, NULL); /* "write" may run it on another thread */
  return st;
}

/* Is b, baked through the context, an edit of the bake shown: the
 * context's bake before was it (context_id), the library changed only a
 * rectangle (or nothing), and every other file read (brightness, albedo...)
 * has the bytes it had? Then b's maps are shown's outside b->changed. */
static int is_edit_of(const serve_bake *b, const serve_bake *shown, long context_id,
                      int watched_count) {
  if (!shown || shown->id != context_id || shown->width != b->width ||
      shown->height != b->height)
    return 0;
  if (b->changed.width == b->width && b->changed.height == b->height)
    return 0; /* baked whole */
  for (int i = 1; i < watched_count; i++)
    if (b->input_hashes[i] != shown->input_hashes[i])
      return 0;
  return 1;
}

/* One bake of the options as they are now; publishes it or the error. */
static void bake_once(serve_state *s, long wanted) {
  bb_error err = {{0}};
  bb_command *command = NULL;
  char *spelled = NULL; /* the line its files record */
  pthread_mutex_lock(&s->lock);
  bb_status st = serve_bake_command(s, &command, &spelled, &err);
  const char *input = s->height_path;
  s->baking = 1;
  s->stage = "load and smooth";
  s->progress = 0.0;
  s->last_progress_seconds = 0.0;
  s->version++;
  pthread_cond_broadcast(&s->changed);
  pthread_mutex_unlock(&s->lock);

  const double t0 = now_seconds();
  /* The other files the bake reads, hashed before it reads them: a change
   * after this shows at a write, which then bakes again (the height's own
   * hash is the job's, of the bytes it decoded). */
  uint64_t hashes[SERVE_MAX_WATCHED] = {0};
  for (int i = 1; i < s->watched_count; i++)
    if (bb_file_hash(s->watched[i], &hashes[i], NULL) != BB_OK)
      hashes[i] = 0;
  bb_job *job = NULL;
  bb_bake_result result;
  memset(&result, 0, sizeof result);
  serve_bake *b = NULL;
  if (st == BB_OK)
    st = folder_gone(command, input, &err) ? BB_ERR_IO
                                           : bb_command_plan(command, NULL, &job, &err);
  if (st == BB_OK) {
    const int bounces = bb_command_bounce(command) > 0.0;
    progress_ctx p = {s, wanted, bounces ? bb_command_slices(command) : 0, 0, 0};
    st = bake_maps(s, job, &p, &result, &err);
  }
  const int context_baked = st == BB_OK; /* the context's last bake is this one now */
  const bb_region changed = bb_bake_context_changed(s->context);
  unsigned char *albedo = NULL;
  if (st == BB_OK) {
    const bb_job_report *rep = bb_job_report_get(job, 0);
    st = read_albedo(s->albedo_file, rep->width, rep->height, &albedo, &err);
  }
  if (st == BB_OK) {
    const bb_job_report *rep = bb_job_report_get(job, 0);
    if ((b = calloc(1, sizeof *b))) {
      b->refs = 1;
      memcpy(b->input_hashes, hashes, sizeof hashes);
      b->input_hashes[0] = rep->source.file_hash;
      b->width = rep->width;
      b->height = rep->height;
      pthread_mutex_init(&b->tex_lock, NULL);
      b->maps = result; /* kept for the textures */
      memset(&result, 0, sizeof result);
      b->basis = b->maps.basis;
      b->report = *rep;
      b->report.input = NULL;
      b->command = spelled;
      spelled = NULL;
      b->provenance = bb_job_provenance(job, 0, "ssbump");
      char normal_y[8];
      b->normal_y_up = bb_command_value(command, "normal-y", normal_y, sizeof normal_y,
                                        NULL) == BB_OK && !strcmp(normal_y, "up");
      double scale = 0.0;
      bb_command_numbers(command, "scale", &scale, 1, NULL, NULL);
      b->scale = (double)(float)scale; /* the float the bake took */
      b->tex[SERVE_TEX_ALBEDO] = albedo;
      albedo = NULL;
      b->seconds = now_seconds() - t0;
      b->job = job; /* kept: "write" writes these maps through it */
      job = NULL;
      b->wanted = wanted;
    } else {
      st = BB_ERR_MEMORY;
      snprintf(err.message, sizeof err.message, "out of memory");
    }
  }
  bb_bake_result_free(&result);
  bb_job_free(job);
  bb_command_free(command);
  free(spelled);
  free(albedo);

  pthread_mutex_lock(&s->lock);
  s->baking = 0;
  s->stage = NULL;
  s->done = wanted;
  if (st == BB_OK) {
    b->id = ++s->next_id;
    b->changed = changed;
    if (is_edit_of(b, s->current, s->context_id, s->watched_count))
      b->base_id = s->current->id;
    s->context_id = b->id;
    serve_bake_release(s->previous);
    if ((s->previous = s->current))
      shed_maps(s->previous);
    s->current = b;
    s->error[0] = '\0';
    if (!s->quiet) {
      /* a save baked again where it changed says where */
      const bb_region c = b->changed;
      char where[96] = "";
      if (c.width < b->width || c.height < b->height)
        snprintf(where, sizeof where, ", again where it changed (%dx%d at %d,%d)", c.width,
                 c.height, c.x0, c.y0);
      fprintf(stderr, "serve: bake %ld: %dx%d in %.3f s%s\n", b->id, b->width, b->height,
              b->seconds, where);
    }
  } else if (context_baked) {
    s->context_id = 0; /* baked but not shown: the next change is against it */
  }
  if (st != BB_OK && st != BB_ERR_CANCELLED) {
    /* the last good maps stay on the page, with why the new ones are not */
    snprintf(s->error, sizeof s->error, "%s",
             err.message[0] ? err.message : bb_status_name(st));
    if (!s->quiet) {
      char line[1200];
      snprintf(line, sizeof line, "%s (the last good maps stay on the page)", s->error);
      cli_error_line(line); /* control characters escaped */
    }
  }
  s->version++;
  pthread_cond_broadcast(&s->changed);
  pthread_mutex_unlock(&s->lock);
}

void *serve_bake_thread(void *arg) {
  serve_state *s = arg;
  pthread_mutex_lock(&s->lock);
  while (!s->quit) {
    const long wanted = atomic_load(&s->wanted);
    if (wanted == s->done) {
      pthread_cond_wait(&s->work, &s->lock);
      continue;
    }
    pthread_mutex_unlock(&s->lock);
    bake_once(s, wanted);
    pthread_mutex_lock(&s->lock);
  }
  pthread_mutex_unlock(&s->lock);
  return NULL;
}
