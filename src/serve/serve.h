/* serve.h: what the parts of `bumpbake serve` share (src/serve/): the
 * state one bake thread, one watch thread and the HTTP server's threads
 * (its polling thread, the writer and the ticker) read and change under
 * one lock. The bakes go through the
 * library's job (bb_job_bake_item, bb_job_run_item); nothing here is a
 * bake rule. */
#ifndef BB_SERVE_H
#define BB_SERVE_H

#include "bumpbake.h"

#include <pthread.h>
#include <stdatomic.h>

/* The textures the page draws, 8-bit RGBA each, W x H: */
enum {
  SERVE_TEX_SSBUMP_AO,     /* ssbump s_0..s_2 in RGB, ao in A */
  SERVE_TEX_NORMAL_HEIGHT, /* the normal (N + 1) / 2 in RGB, the smoothed height in A */
  SERVE_TEX_BENT,          /* the bent normal (Nb + 1) / 2 in RGB, A 255 */
  SERVE_TEX_WEIGHTS,       /* the basis weights w_0..w_2 in RGB, A 255 */
  SERVE_TEX_ALBEDO,        /* --albedo FILE as read with this bake (grey: R = G = B),
                              A 255; made with the bake, NULL without one */
  SERVE_TEX_COUNT
};

/* The watched files: the height, the maps the options read and the albedo. */
enum { SERVE_MAX_WATCHED = 5 };

/* One finished bake: published at once, its textures made when first
 * asked (the picture shown asks for one first). The state holds the bake
 * shown and the one before it (downloads in flight when a newer one lands
 * finish from it); a request holds a reference while it reads the bake.
 * The float maps and the job, the bulk of a bake, are used only while the
 * bake is the one shown (a "write" from memory, textures made): once it
 * is not, they are freed as soon as their last user is done (maps_shed),
 * so what serve holds does not grow with the requests that hold bakes. */
typedef struct serve_bake {
  int refs;       /* under serve_state.lock */
  int maps_users; /* under serve_state.lock: users of maps and job */
  int maps_shed;  /* not shown any more: maps and job go with
                     their last user */
  long id;
  int width, height;
  pthread_mutex_t tex_lock;            /* makes tex[] (then under serve_state.lock) */
  unsigned char *tex[SERVE_TEX_COUNT]; /* NULL until asked */
  /* An edit's bake: base_id names the bake whose maps are this one's
   * outside changed (the library's changed rectangle: the bake context's
   * bake before was that bake, and every other file read is as it read
   * them), 0 when there is none; part[t] is texture t's changed rectangle
   * alone (4 x its width x height bytes, row by row), made when asked. */
  long base_id;
  bb_region changed;
  unsigned char *part[SERVE_TEX_COUNT];
  bb_job *job;                         /* the job that baked them (its report) */
  bb_bake_result maps;                 /* the bake's float maps: the textures and a
                                          "write" (bb_job_write_item) are made of them */
  long wanted;                         /* the request it answered (serve_state.wanted) */
  double seconds;                      /* from the start of the bake to its maps */
  double seconds_textures; /* making the textures asked so far (under serve_state.lock) */
  bb_job_report report;    /* the job's figures (input pointer not kept) */
  char *provenance;        /* the ssbump's provenance as the job writes it */
  char *command;           /* the `bumpbake bake` line that writes these maps */
  uint64_t input_hashes[SERVE_MAX_WATCHED]; /* bb_file_hash of serve_state.watched[i]
                                              as baked (0: unreadable) */
  int normal_y_up;
  bb_basis basis; /* the basis of the ssbump and weights: the page lights with it */
  double scale;   /* the bake's --scale: the relief's depth */
} serve_bake;

typedef struct serve_state {
  pthread_mutex_t lock;
  pthread_cond_t work;    /* the bake thread waits for wanted != done */
  pthread_cond_t changed; /* event streams wait for version to move */
  long version;           /* bumped on every change a page shows */
  /* what to bake: the command line's options, changed by the page's controls */
  const char *height_path;
  const bb_command *line;       /* the command line's command, as given (the files its
                                  file controls switch on) */
  bb_command *command;         /* the page's command: serve's command line with the page's
                                  controls set, checked as the command line is */
  char *write_files[BB_MAP_BAKED_COUNT]; /* the file a "write" writes each map to, NULL
                                            for none: the command line's
                                            (bb_command_map_file) */
  atomic_long wanted;          /* bumped by a save or a control: the bake in flight
                                  for an older value is cancelled */
  long done;                   /* the wanted value last baked (or failed) */
  const char *albedo_file;     /* --albedo FILE (render's row), or NULL */
  float light_color[3];        /* --light-color R,G,B (render's row), then the page's */
  /* what is going on */
  int baking;
  double progress;   /* 0..1 of the bake in flight */
  const char *stage; /* the stage it runs ("load and smooth", "trace", "bounce",
                        "derive"), from its progress callback */
  double last_progress_seconds;
  char error[1024];     /* the last bake's failure, "" after a success */
  serve_bake *current;  /* the last good bake, or NULL */
  serve_bake *previous; /* the one before it, or NULL (its maps shed) */
  long next_id;
  bb_bake_context *context; /* the bake thread's warm ray set and buffers */
  long context_id;          /* the published bake that the context's last bake is
                               (its changed rectangle is against it), 0: none */
  const char *watched[SERVE_MAX_WATCHED];
  int watched_count;
  int quiet;
  atomic_int quit; /* the process is stopping: the bake in flight is cancelled */
} serve_state;

/* serve_bake.c: the bake thread (runs until state->quit; a bake in flight
 * is cancelled when it is set). */
void *serve_bake_thread(void *state);
/* Asks for a new bake (a save or a control changed); the caller holds the lock. */
void serve_request_bake(serve_state *s);
/* Drops one reference; the caller holds the lock. */
void serve_bake_release(serve_bake *b);
/* The bake shown, with a reference and the use of its maps and job; NULL
 * when there is none. The caller holds the lock; serve_maps_done ends the
 * use (also with the lock held), then serve_bake_release. */
serve_bake *serve_maps_use(serve_state *s);
void serve_maps_done(serve_bake *b);
/* Texture t of b (4 x width x height bytes), made on first use; NULL when
 * out of memory, or when it was not made while b was shown. Any thread,
 * with a reference held and the lock not. */
const unsigned char *serve_bake_texture(serve_state *s, serve_bake *b, int t);
/* Texture t of b within b->changed only, as serve_bake_texture makes it
 * (b->base_id is not 0); the albedo, read whole with every bake and the
 * same as the base's, has an empty rectangle. NULL when out of memory or
 * when b is no longer shown; a pointer to nothing for an empty rectangle. */
const unsigned char *serve_bake_part(serve_state *s, serve_bake *b, int t);
/* The rectangle of texture t that serve_bake_part gives. */
bb_region serve_part_region(const serve_bake *b, int t);
/* The first watched file (0: the height) whose bytes are not those b was
 * baked from, or -1 when every one is as baked. Reads the files; the
 * caller does not hold the lock (watched is set before any thread runs). */
int serve_inputs_changed(const serve_state *s, const serve_bake *b);

/* serve_command.c: the `bumpbake bake` command of the options now (the
 * caller holds the lock): the page's command as a bake (bb_command_derive:
 * the options bake takes at other values than bake's defaults) with the
 * write action's files (write_files), checked, into *out (free with
 * bb_command_free); and *line, the line its files record and the page
 * shows (malloc'd), as bb_command_text spells the command. A bake or a
 * write plans through it (bb_command_plan). err not NULL. */
bb_status serve_bake_command(const serve_state *s, bb_command **out, char **line,
                             bb_error *err);

/* serve_watch.c: watches the directories of s->watched with inotify and
 * asks for a bake when one of the files is saved (renamed over, or written
 * and closed, or quiet for a moment after a write), on a thread of its
 * own. Returns 0 with the watch in *out, or -1 with a message in err
 * (capacity cap) when inotify cannot be set up. */
typedef struct serve_watch serve_watch;
int serve_watch_start(serve_state *s, serve_watch **out, char *err, size_t cap);
/* Stops the watch's thread, waits for it and frees w (NULL: nothing). */
void serve_watch_stop(serve_watch *w);

/* serve_http.c: the server. */
typedef struct serve_http_options {
  const char *address; /* --address's value (its default: 127.0.0.1) */
  int port;            /* 0: any free one */
  int token;           /* 1 (--address given): a random token in every path, and a
                          share of the connections per client */
} serve_http_options;
/* Starts serving s; the URL of the page into url (capacity cap). Returns 0,
 * or -1 with a message in url. */
int serve_http_start(serve_state *s, const serve_http_options *o, char *url, size_t cap);
/* Stops the server started for s: its threads end before it returns. */
void serve_http_stop(serve_state *s);

/* serve_params.c: the JSON text write(j, arg) makes, malloc'd; NULL when
 * out of memory (src/core/json.h's writer, compiled into the program). */
struct bb__json;
char *serve_json_text(void (*write)(struct bb__json *j, void *arg), void *arg);

/* serve_params.c: the state as one JSON object (malloc'd), as the page reads it. */
char *serve_state_json(serve_state *s);
/* serve_params.c: the page's controls (JSON, malloc'd; NULL when out of
 * memory), made from the rows of serve's options it offers (scale, rays,
 * slices, bias, bounce, bounces, brightness, light-color): {"controls":
 * [{"name", "key", "place" ("bake" or "light"), "type", "count",
 * "value_name", "help", "default", "range", "unset", "min", "max",
 * "min_exclusive"}...], "view": {"view_elevation", "light_elevation":
 * {"min", "max", "min_exclusive"}}}, the picture's ranges from render's
 * --view and --light (bb_option_bounds). */
char *serve_controls_json(void);
/* serve_params.c: applies the page's control values (name=value pairs,
 * the names those of serve_controls_json; sizes[i] the bytes of values[i],
 * which may hold a NUL) to the state, all or none: each set on a copy of
 * the page's command by the option of its name (a value at what a command
 * holds without the option leaves it out, as the line the page shows
 * does; a file option is "on", the file serve was given, or "off"), then
 * the copy checked as the command line is (bb_command_check: ranges and
 * the rules between options). *rebake is 1 when a control of the bake was
 * among them (light-color is a light of the picture). 0, or -1 with the
 * library's words in err. The caller holds the lock. */
int serve_apply_params(serve_state *s, const char *const *names,
                       const char *const *values, const size_t *sizes, int count,
                       int *rebake, char *err, size_t cap);

/* serve_params.c: command's --light-color (render's row, which serve
 * takes) as the picture's light, read by name (bb_command_numbers: the
 * value set, else the default). */
void serve_light_color(const bb_command *command, float rgb[3]);

/* serve_page.c: the page's files, embedded at build time. */
typedef struct serve_asset {
  const char *name, *type;
  const unsigned char *data;
  size_t size;
} serve_asset;
const serve_asset *serve_asset_find(const char *name);

#endif /* BB_SERVE_H */
