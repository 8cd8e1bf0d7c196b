/* serve_bake.c: `bumpbake serve`'s bake thread: whenever a save or a
 * control asks, plans the job of the current options and bakes its input
 * through it (bb_job_bake_item: the very read and bake `bumpbake bake`
 * runs, nothing written), then publishes the maps, which become the
 * page's 8-bit textures as the page asks for them; the job and the float
 * maps are kept for "write" (bb_job_write_item).
 * A newer request cancels the bake in flight through the progress
 * callback; a failure keeps the last good maps and shows why. */
#include "common.h"
#include "serve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
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

void serve_bake_release(serve_bake *b) {
  if (!b || --b->refs > 0)
    return;
  for (int t = 0; t < SERVE_TEX_COUNT; t++)
    free(b->tex[t]);
  bb_bake_result_free(&b->maps);
  bb_job_free(b->job);
  pthread_mutex_destroy(&b->tex_lock);
  free(b->provenance);
  free(b->command);
  free(b);
}

void serve_job_options(const serve_state *s, bb_job_options *o) {
  *o = s->job;
  /* the parameters, as bake takes them */
  o->bake = s->settings.bake;
  o->channel = s->settings.channel;
  o->depth = s->settings.depth;
  o->mips = s->settings.mips;
  o->texture = s->settings.texture;
  o->basis_file = s->settings.basis_file;
  o->brightness_file = s->use_brightness ? s->brightness_file : NULL;
  o->force = 1;       /* a single bake always bakes */
  o->command = NULL;  /* provenance: bb_job_command_text, the line the page shows */
  o->note = NULL;
}

/* ------------------------------------------------------------- progress */

typedef struct progress_ctx {
  serve_state *s;
  long wanted; /* the request this bake answers */
} progress_ctx;

/* Records the fraction for the page (ten times a second at most) and
 * cancels when a newer request came. */
static int on_progress(void *user, long done, long total) {
  progress_ctx *p = user;
  if (atomic_load(&p->s->wanted) != p->wanted)
    return 1;
  double now = now_seconds();
  pthread_mutex_lock(&p->s->lock);
  if (total > 0 && now - p->s->last_progress_seconds >= 0.1) {
    p->s->last_progress_seconds = now;
    p->s->progress = (double)done / (double)total;
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
 * signed vectors ((v + 1) / 2), and alpha from channel 0 of alpha_img. */
static void fill(unsigned char *tex, size_t n, const bb_image *img, int is_vector,
                 const bb_image *alpha_img) {
  for (size_t i = 0; i < n; i++) {
    for (int c = 0; c < 3; c++) {
      float v = img && img->pixels && c < img->channels
                    ? img->pixels[i * (size_t)img->channels + (size_t)c]
                    : 0.0f;
      tex[4 * i + (size_t)c] = unit_byte(is_vector ? 0.5f * (v + 1.0f) : v);
    }
    tex[4 * i + 3] = alpha_img && alpha_img->pixels
                         ? unit_byte(alpha_img->pixels[i * (size_t)alpha_img->channels])
                         : 255;
  }
}

const unsigned char *serve_bake_texture(serve_bake *b, int t) {
  pthread_mutex_lock(&b->tex_lock);
  if (!b->tex[t]) {
    const double t0 = now_seconds();
    const size_t n = (size_t)b->width * (size_t)b->height;
    const bb_bake_result *r = &b->maps;
    if ((b->tex[t] = malloc(4 * n))) {
      switch (t) {
      case SERVE_TEX_SSBUMP_AO: fill(b->tex[t], n, &r->ssbump, 0, &r->ao); break;
      case SERVE_TEX_NORMAL_HEIGHT: fill(b->tex[t], n, &r->normal, 1, &r->filtered); break;
      case SERVE_TEX_BENT: fill(b->tex[t], n, &r->bent, 1, NULL); break;
      default: fill(b->tex[t], n, &r->weights, 0, NULL); break;
      }
    }
    b->seconds_textures += now_seconds() - t0;
  }
  pthread_mutex_unlock(&b->tex_lock);
  return b->tex[t];
}

/* The ssbump's provenance as the job records it in the file it writes. */
static char *provenance_of(const bb_job_options *o, const bb_job_report *rep,
                           const bb_bake_result *r, const char *command, const char *input) {
  const char *name = strrchr(input, '/');
  bb_provenance p = {command,
                     name ? name + 1 : input,
                     rep->source.height_hash,
                     "ssbump",
                     &o->bake,
                     o->channel,
                     r->rayset_id[0] ? r->rayset_id : NULL,
                     rep->source.file_hash,
                     NULL};
  return bb_provenance_format(&p);
}

/* ----------------------------------------------------------------- bake */

/* One bake of the options as they are now; publishes it or the error. */
static void bake_once(serve_state *s, long wanted) {
  bb_job_options o;
  pthread_mutex_lock(&s->lock);
  serve_job_options(s, &o);
  const char *input = s->height_path;
  s->baking = 1;
  s->progress = 0.0;
  s->last_progress_seconds = 0.0;
  s->version++;
  pthread_cond_broadcast(&s->changed);
  pthread_mutex_unlock(&s->lock);

  const double t0 = now_seconds();
  bb_error err = {{0}};
  bb_job *job = NULL;
  bb_bake_result result;
  memset(&result, 0, sizeof result);
  serve_bake *b = NULL;
  bb_status st = bb_job_plan(&input, 1, &o, &job, &err);
  if (st == BB_OK) {
    bb_job_use_context(job, s->context); /* this thread's bakes only */
    progress_ctx p = {s, wanted};
    st = bb_job_bake_item(job, 0, BB_MAPS_BAKED, on_progress, &p, &result, &err);
  }
  if (st == BB_OK) {
    const bb_job_report *rep = bb_job_report_get(job, 0);
    if ((b = calloc(1, sizeof *b))) {
      b->refs = 1;
      b->width = rep->width;
      b->height = rep->height;
      pthread_mutex_init(&b->tex_lock, NULL);
      b->maps = result; /* kept for the textures */
      memset(&result, 0, sizeof result);
      b->basis = b->maps.basis;
      b->report = *rep;
      b->report.input = NULL;
      b->command = bb_job_command_text(&o, input);
      b->provenance = provenance_of(&o, rep, &b->maps, b->command, input);
      b->normal_y_up = o.bake.normal_y_up;
      b->scale = (double)o.bake.height_scale;
      b->seconds = now_seconds() - t0;
      bb_job_use_context(job, NULL); /* "write" may run it on another thread */
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

  pthread_mutex_lock(&s->lock);
  s->baking = 0;
  s->done = wanted;
  if (st == BB_OK) {
    b->id = ++s->next_id;
    serve_bake_release(s->current);
    s->current = b;
    s->error[0] = '\0';
    if (!s->quiet) {
      /* a save baked again where it changed says where */
      const bb_region c = bb_bake_context_changed(s->context);
      char where[96] = "";
      if (c.width < b->width || c.height < b->height)
        snprintf(where, sizeof where, ", again where it changed (%dx%d at %d,%d)", c.width,
                 c.height, c.x0, c.y0);
      fprintf(stderr, "serve: bake %ld: %dx%d in %.3f s%s\n", b->id, b->width, b->height,
              b->seconds, where);
    }
  } else if (st != BB_ERR_CANCELLED) {
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
