/* serve_http.c: `bumpbake serve`'s HTTP side, on libmicrohttpd: the page
 * and its files, the state as JSON and as server-sent events, the page's
 * controls (made from the library's option rows), the textures of the last good bake as
 * raw 8-bit RGBA, the controls and the "write" action. Every path is one of
 * a fixed few: no part of a request names a file. Requests must come for
 * the host they were served as (a page elsewhere cannot rebind a name to
 * us), and those that change something must carry an X-Bumpbake header
 * (which a page of another origin cannot send without asking first); with
 * --address, every path also starts with a random token.
 *
 * It is held to a server's bounds, so that no client can lock the page
 * out or make serve grow: one polling thread serves every connection
 * (epoll), none waits on a thread of its own; a connection must send its
 * request's headers within HEADER_SECONDS and move a byte every
 * IDLE_SECONDS; there are at most CONNECTION_LIMIT connections (and with
 * --address PER_CLIENT_LIMIT from one address); an event stream waits
 * suspended, costs no thread, writes at least every KEEPALIVE_SECONDS (so
 * a client gone is noticed and its slot freed) and there are at most
 * STREAM_LIMIT of them; a request body is refused; a download holds no
 * bake (it reads the bake it began with while that bake is shown or the
 * one before, and ends otherwise); and "write" runs on one writer thread,
 * one write at a time, every request that waited during a write answered
 * by the next one. */
#include "serve.h"
#include "../core/json.h" /* the JSON writer, compiled into the program (Makefile) */
#include "serve_mhd.h" /* libmicrohttpd's calls, through the library loaded at start */

#include <arpa/inet.h>
#include <errno.h>
#include <limits.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <time.h>

enum {
  HEADER_SECONDS = 10, /* from a connection's start, or its last request's end */
  IDLE_SECONDS = 10,   /* MHD_OPTION_CONNECTION_TIMEOUT: nothing moved that long */
  CONNECTION_LIMIT = 2048,
  PER_CLIENT_LIMIT = 64, /* with --address: a browser opens 6 or so */
  STREAM_LIMIT = 256,
  KEEPALIVE_SECONDS = 2,
  TICK_MS = 250,                 /* the ticker's period: the bounds hold within it */
  CONNECTION_MEMORY = 32 * 1024, /* a request's headers and MHD's buffers */
  BLOCK_BYTES = 32 * 1024        /* a download's buffer */
};

/* A connection, from its accept to its close: when it started waiting for
 * a request's headers (the ticker cuts it HEADER_SECONDS later). */
typedef struct tracked {
  struct tracked *prev, *next;
  int fd;
  double since;
  int waiting; /* for a request's headers */
  int cut;
} tracked;

/* One event stream: the state each time it changes, as "data:" lines,
 * and a comment at least every KEEPALIVE_SECONDS. Between events the
 * connection is suspended; the ticker resumes it. */
typedef struct event_stream {
  struct event_stream *prev, *next;
  struct server *sv;
  struct MHD_Connection *conn;
  int fd;            /* its socket, looked at (never read) while it waits */
  int suspended;     /* under server.lock */
  int gone;          /* under server.lock: the client closed its end */
  long sent_version; /* the state's version last sent */
  double last_sent;
  char *pending; /* the event being sent, and how much of it went */
  size_t size, offset;
} event_stream;

/* One POST write waiting for the writer: answered, then resumed. */
typedef struct write_wait {
  struct write_wait *next;
  struct MHD_Connection *conn;
  int done; /* under server.lock */
  unsigned status;
  char *reply; /* JSON */
} write_wait;

/* A request's own state (MHD's con_cls). */
typedef struct request {
  write_wait write;
  int queued; /* write is in the writer's queue or answered */
} request;

typedef struct server {
  serve_state *s;
  struct MHD_Daemon *daemon;
  char prefix[64];      /* "/" or "/TOKEN/" */
  char host[128];       /* the Host header requests must carry ("127.0.0.1:8077") */
  char host_alt[128];   /* "localhost:8077" for the loopback, else "" */
  int check_host;       /* without a token: the Host header is checked */
  pthread_mutex_t lock; /* the lists below */
  pthread_cond_t wake;  /* the writer's queue */
  tracked *connections;
  event_stream *streams;
  int stream_count;
  write_wait *writes; /* the writer's queue, newest first */
  int stop;
  pthread_t ticker, writer;
  int threads; /* 1: ticker and writer run */
} server;

static double now_seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* ------------------------------------------------------------ responses */

/* Every response's headers: its type, never cached, never sniffed as
 * another type, and never shown in a frame (a page elsewhere cannot lay
 * the page under a decoy and have a click "write the maps"); the page
 * runs, styles and fetches only what this server sends. */
static const char *const policy =
    "default-src 'none'; script-src 'self'; style-src 'self'; "
    "connect-src 'self'; img-src 'self' data:; base-uri 'none'; "
    "form-action 'none'; frame-ancestors 'none'";

static enum MHD_Result queue(struct MHD_Connection *c, unsigned status,
                             struct MHD_Response *r, const char *type) {
  MHD_add_response_header(r, "Content-Type", type);
  MHD_add_response_header(r, "Cache-Control", "no-store");
  MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
  MHD_add_response_header(r, "X-Frame-Options", "DENY");
  MHD_add_response_header(r, "Content-Security-Policy", policy);
  enum MHD_Result ret = MHD_queue_response(c, status, r);
  MHD_destroy_response(r);
  return ret;
}

static enum MHD_Result send_bytes(struct MHD_Connection *c, unsigned status,
                                  const char *type, const void *data, size_t size,
                                  enum MHD_ResponseMemoryMode mode) {
  struct MHD_Response *r = MHD_create_response_from_buffer(size, (void *)data, mode);
  if (!r)
    return MHD_NO;
  return queue(c, status, r, type);
}

static enum MHD_Result send_text(struct MHD_Connection *c, unsigned status,
                                 const char *text) {
  return send_bytes(c, status, "text/plain; charset=utf-8", text, strlen(text),
                    MHD_RESPMEM_MUST_COPY);
}

/* A malloc'd JSON text, handed to the response. */
static enum MHD_Result send_json(struct MHD_Connection *c, unsigned status, char *json) {
  if (!json)
    return send_text(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "out of memory");
  return send_bytes(c, status, "application/json", json, strlen(json),
                    MHD_RESPMEM_MUST_FREE);
}

/* {"error": message}, malloc'd; NULL when out of memory. */
static void write_error(bb__json *j, void *msg) {
  bb__json_open(j, NULL, '{');
  bb__json_string(j, "error", msg);
  bb__json_close(j, '}');
}

static char *error_json(const char *msg) { return serve_json_text(write_error, (void *)msg); }

static enum MHD_Result send_error(struct MHD_Connection *c, unsigned status,
                                  const char *msg) {
  return send_json(c, status, error_json(msg));
}

/* ------------------------------------------------------------- textures */

/* A download names its bake; each read finds it again (the bake shown or
 * the one before) and holds it only while copying, so a client that stops
 * reading holds nothing. */
typedef struct texture_read {
  serve_state *s;
  long bake_id;
  int t;
  int part; /* serve_bake_part's bytes, not the whole texture's */
  uint64_t size;
} texture_read;

static ssize_t texture_reader(void *cls, uint64_t pos, char *buf, size_t max) {
  texture_read *r = cls;
  if (pos >= r->size)
    return MHD_CONTENT_READER_END_OF_STREAM;
  serve_state *s = r->s;
  pthread_mutex_lock(&s->lock);
  serve_bake *b = s->current && s->current->id == r->bake_id     ? s->current
                  : s->previous && s->previous->id == r->bake_id ? s->previous
                                                                 : NULL;
  if (b)
    b->refs++;
  pthread_mutex_unlock(&s->lock);
  if (!b)
    return MHD_CONTENT_READER_END_WITH_ERROR; /* two bakes newer: fetch again */
  const size_t n = r->size - pos < max ? (size_t)(r->size - pos) : max;
  /* made before the download began */
  memcpy(buf, (r->part ? b->part : b->tex)[r->t] + pos, n);
  pthread_mutex_lock(&s->lock);
  serve_bake_release(b);
  pthread_mutex_unlock(&s->lock);
  return (ssize_t)n;
}

static const char *const texture_names[SERVE_TEX_COUNT] = {"ssbump_ao", "normal_height",
                                                           "bent", "weights", "albedo"};

/* The bake id of ?since=ID (a bake the page holds whole), or 0. */
static long since_of(struct MHD_Connection *c) {
  const char *v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "since");
  char *end = NULL;
  const long id = v ? strtol(v, &end, 10) : 0;
  return v && end != v && !*end && id > 0 ? id : 0;
}

/* One texture of the last good bake; X-Bake-Id says which bake it is.
 * With ?since=ID, when that bake is an edit of bake ID (serve_bake's
 * base_id), only the texels it changed: X-Region says which
 * ("x0,y0,width,height"; "0,0,0,0" when none did), the body is that
 * rectangle's texels row by row, and the rest is bake ID's. */
static enum MHD_Result send_texture(server *sv, struct MHD_Connection *c,
                                    const char *name) {
  int t = 0;
  while (t < SERVE_TEX_COUNT && strcmp(texture_names[t], name) != 0)
    t++;
  if (t == SERVE_TEX_COUNT || (t == SERVE_TEX_ALBEDO && !sv->s->albedo_file))
    return send_text(c, MHD_HTTP_NOT_FOUND, "no such map");
  const long since = since_of(c);
  serve_state *s = sv->s;
  pthread_mutex_lock(&s->lock);
  serve_bake *b = s->current;
  if (b)
    b->refs++;
  pthread_mutex_unlock(&s->lock);
  if (!b)
    return send_text(c, MHD_HTTP_SERVICE_UNAVAILABLE, "no bake yet");
  const int part = since && b->base_id == since;
  const bb_region region = part ? serve_part_region(b, t) : (bb_region){0, 0, 0, 0};
  const int made =
      (part ? serve_bake_part(s, b, t) : serve_bake_texture(s, b, t)) != NULL;
  texture_read *r = made ? calloc(1, sizeof *r) : NULL;
  if (r) {
    r->s = s;
    r->bake_id = b->id;
    r->t = t;
    r->part = part;
    r->size = part ? 4 * (uint64_t)region.width * (uint64_t)region.height
                   : 4 * (uint64_t)b->width * (uint64_t)b->height;
  }
  char id[32], w[16], h[16], where[64];
  snprintf(id, sizeof id, "%ld", b->id);
  snprintf(w, sizeof w, "%d", b->width);
  snprintf(h, sizeof h, "%d", b->height);
  snprintf(where, sizeof where, "%d,%d,%d,%d", region.x0, region.y0, region.width,
           region.height);
  pthread_mutex_lock(&s->lock);
  serve_bake_release(b);
  pthread_mutex_unlock(&s->lock);
  if (!r) /* out of memory, or a newer bake landed before it was made */
    return send_text(c, MHD_HTTP_SERVICE_UNAVAILABLE,
                     made ? "out of memory" : "a newer bake");
  struct MHD_Response *resp =
      MHD_create_response_from_callback(r->size, BLOCK_BYTES, texture_reader, r, free);
  if (!resp) {
    free(r);
    return MHD_NO;
  }
  MHD_add_response_header(resp, "X-Bake-Id", id);
  MHD_add_response_header(resp, "X-Width", w);
  MHD_add_response_header(resp, "X-Height", h);
  if (part)
    MHD_add_response_header(resp, "X-Region", where);
  return queue(c, MHD_HTTP_OK, resp, "application/octet-stream");
}

/* --------------------------------------------------------------- events */

static ssize_t event_reader(void *cls, uint64_t pos, char *buf, size_t max) {
  (void)pos;
  event_stream *e = cls;
  pthread_mutex_lock(&e->sv->lock);
  const int gone = e->gone;
  pthread_mutex_unlock(&e->sv->lock);
  if (gone)
    return MHD_CONTENT_READER_END_WITH_ERROR; /* its slot is free at once */
  if (!e->pending) {
    serve_state *s = e->sv->s;
    pthread_mutex_lock(&s->lock);
    const long version = s->version;
    const int quit = atomic_load(&s->quit);
    pthread_mutex_unlock(&s->lock);
    if (quit)
      return MHD_CONTENT_READER_END_OF_STREAM;
    const double now = now_seconds();
    pthread_mutex_lock(&e->sv->lock); /* the ticker reads what was sent when */
    const int news = version != e->sent_version;
    const int due = now - e->last_sent >= KEEPALIVE_SECONDS;
    if (news || due) {
      e->sent_version = version;
      e->last_sent = now;
    } else {
      /* nothing to send: wait, suspended, for the ticker */
      e->suspended = 1;
      MHD_suspend_connection(e->conn);
    }
    pthread_mutex_unlock(&e->sv->lock);
    if (!news && !due)
      return 0;
    if (news) {
      char *json = serve_state_json(s);
      if (json) {
        size_t n = strlen(json) + 16;
        if ((e->pending = malloc(n)))
          snprintf(e->pending, n, "data: %s\n\n", json);
        free(json);
      }
    } else {
      e->pending = strdup(": still here\n\n");
    }
    if (!e->pending)
      return MHD_CONTENT_READER_END_WITH_ERROR;
    e->size = strlen(e->pending);
    e->offset = 0;
  }
  size_t n = e->size - e->offset < max ? e->size - e->offset : max;
  memcpy(buf, e->pending + e->offset, n);
  e->offset += n;
  if (e->offset == e->size) {
    free(e->pending);
    e->pending = NULL;
  }
  return (ssize_t)n;
}

static void event_free(void *cls) {
  event_stream *e = cls;
  server *sv = e->sv;
  pthread_mutex_lock(&sv->lock);
  if (e->prev)
    e->prev->next = e->next;
  else
    sv->streams = e->next;
  if (e->next)
    e->next->prev = e->prev;
  sv->stream_count--;
  pthread_mutex_unlock(&sv->lock);
  free(e->pending);
  free(e);
}

static enum MHD_Result send_events(server *sv, struct MHD_Connection *c) {
  pthread_mutex_lock(&sv->lock);
  const int full = sv->stream_count >= STREAM_LIMIT;
  pthread_mutex_unlock(&sv->lock);
  if (full)
    return send_text(c, MHD_HTTP_SERVICE_UNAVAILABLE, "too many event streams");
  event_stream *e = calloc(1, sizeof *e);
  if (!e)
    return send_text(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "out of memory");
  e->sv = sv;
  e->conn = c;
  const union MHD_ConnectionInfo *info =
      MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
  e->fd = info ? info->connect_fd : -1;
  e->sent_version = -1; /* the state at once */
  pthread_mutex_lock(&sv->lock);
  if ((e->next = sv->streams))
    e->next->prev = e;
  sv->streams = e;
  sv->stream_count++;
  pthread_mutex_unlock(&sv->lock);
  struct MHD_Response *r = MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 16 * 1024,
                                                             event_reader, e, event_free);
  if (!r) {
    event_free(e);
    return MHD_NO;
  }
  return queue(c, MHD_HTTP_OK, r, "text/event-stream");
}

/* ------------------------------------------------------------- controls */

typedef struct param_list {
  const char *name[16], *value[16];
  size_t size[16];
  char *spelled_name[16]; /* a name holding a NUL, "\\0" for it (malloc'd) */
  int count, too_many;
} param_list;

static enum MHD_Result collect_param(void *cls, enum MHD_ValueKind kind, const char *key,
                                     size_t key_size, const char *value,
                                     size_t value_size) {
  (void)kind;
  param_list *p = cls;
  if (p->count == 16) {
    p->too_many = 1;
    return MHD_NO;
  }
  const int i = p->count++;
  p->name[i] = key;
  if (memchr(key, '\0', key_size) && (p->spelled_name[i] = malloc(key_size + 1))) {
    for (size_t k = 0; k < key_size; k++)
      p->spelled_name[i][k] = key[k] ? key[k] : '?';
    p->spelled_name[i][key_size] = '\0';
    p->name[i] = p->spelled_name[i];
  }
  p->value[i] = value ? value : "";
  p->size[i] = value ? value_size : 0;
  return MHD_YES;
}

/* POST params?scale=64&rays=256...: all or none applied, then a re-bake. */
static enum MHD_Result apply_params(server *sv, struct MHD_Connection *c) {
  param_list p;
  memset(&p, 0, sizeof p);
  MHD_get_connection_values_n(c, MHD_GET_ARGUMENT_KIND, collect_param, &p);
  char err[512] = "";
  int rc = -1;
  if (p.too_many) {
    snprintf(err, sizeof err, "too many values");
  } else {
    pthread_mutex_lock(&sv->s->lock);
    int rebake = 0;
    rc = serve_apply_params(sv->s, p.name, p.value, p.size, p.count, &rebake, err,
                            sizeof err);
    if (rc == 0 && rebake)
      serve_request_bake(sv->s); /* cancels the bake in flight */
    pthread_mutex_unlock(&sv->s->lock);
  }
  for (int i = 0; i < p.count; i++)
    free(p.spelled_name[i]);
  if (rc != 0)
    return send_error(c, MHD_HTTP_BAD_REQUEST, err);
  return send_json(c, MHD_HTTP_OK, serve_state_json(sv->s));
}

/* ---------------------------------------------------------------- write */

/* The bake shown with a reference held and its maps in use, when it is
 * what the `bumpbake bake` line of the options now would bake: no save or
 * control came after it (nothing pending, in flight or failed since), and
 * its command line is the one of the options now. Else NULL. The caller
 * holds the lock. */
static serve_bake *bake_of_now(serve_state *s, const char *command) {
  serve_bake *b = s->current;
  if (!b || !b->job || s->baking || s->error[0] || atomic_load(&s->wanted) != s->done ||
      b->wanted != s->done)
    return NULL;
  const int same = b->command && strcmp(command, b->command) == 0;
  return same ? serve_maps_use(s) : NULL;
}

/* One write: the maps written through the job, as the `bumpbake bake`
 * line the page shows would write them: from the maps shown when they
 * are that line's bake (bb_job_write_item on the job that baked them: the
 * same bytes, no second bake), else by baking again (bb_job_run_item: a
 * save or control still pending, or Valve's detail variant). The reply is
 * the line `bake --json` prints, with "from" saying which (malloc'd). */
static char *write_maps(serve_state *s, unsigned *status) {
  bb_error err = {{0}};
  bb_command *command = NULL;
  char *line = NULL;
  pthread_mutex_lock(&s->lock);
  const bb_status made = serve_bake_command(s, &command, &line, &err);
  serve_bake *b = made == BB_OK ? bake_of_now(s, line) : NULL;
  free(line);
  pthread_mutex_unlock(&s->lock);
  if (made != BB_OK) {
    *status = 422;
    return error_json(err.message[0] ? err.message : bb_status_name(made));
  }
  bb_status st = BB_ERR_ARGUMENT;
  const char *from = "memory";
  char reason[PATH_MAX + 64] = "a save or a control came after the bake shown";
  bb_job *job = NULL;
  char *text = NULL;
  /* the maps shown are only the file's while the file is the one baked:
   * a change the watch did not see (a second name of the file elsewhere,
   * a network file system) bakes again */
  const int changed = b ? serve_inputs_changed(s, b) : -1;
  if (changed >= 0) {
    snprintf(reason, sizeof reason, "%s changed since the bake shown",
             s->watched[changed]);
    pthread_mutex_lock(&s->lock);
    serve_maps_done(b);
    serve_bake_release(b);
    pthread_mutex_unlock(&s->lock);
    b = NULL;
  }
  if (b) {
    st = bb_job_write_item(b->job, 0, &b->maps, &err);
    if (st == BB_OK)
      text = bb_command_report_json(command, bb_job_report_get(b->job, 0), "written");
  }
  if (b && st == BB_ERR_ARGUMENT)
    snprintf(reason, sizeof reason, "the line reads the height again to write its maps");
  if (st == BB_ERR_ARGUMENT) { /* not this bake's line, or a file it cannot write */
    from = "bake";
    free(text);
    text = NULL;
    memset(&err, 0, sizeof err);
    st = bb_command_plan(command, NULL, &job, &err);
    if (st == BB_OK) {
      st = bb_job_run_item(job, 0, NULL, NULL);
      if (st != BB_OK)
        err = bb_job_report_get(job, 0)->error;
    }
    if (st == BB_OK)
      text = bb_command_report_json(command, bb_job_report_get(job, 0), "written");
    bb_job_free(job);
  }
  if (b) {
    pthread_mutex_lock(&s->lock);
    serve_maps_done(b);
    serve_bake_release(b);
    pthread_mutex_unlock(&s->lock);
  }
  if (!s->quiet && st == BB_OK)
    fprintf(stderr, "serve: wrote the maps (%s)\n",
            strcmp(from, "memory") ? "baked again" : "from the bake shown");
  bb_command_free(command);
  if (st != BB_OK) {
    free(text);
    *status = 422;
    return error_json(err.message[0] ? err.message : bb_status_name(st));
  }
  /* {"from": "memory" or "bake", "reason" when baked again, then bake
   * --json's keys} */
  char *reply = NULL;
  size_t reply_size = 0;
  FILE *f = text && text[0] == '{' ? open_memstream(&reply, &reply_size) : NULL;
  if (f) {
    bb__json j = {f, 0};
    bb__json_open(&j, NULL, '{');
    bb__json_string(&j, "from", from);
    if (strcmp(from, "memory"))
      bb__json_string(&j, "reason", reason);
    fprintf(f, ",%s", text + 1);
    if (fclose(f) != 0) {
      free(reply);
      reply = NULL;
    }
  }
  free(text);
  *status = reply ? MHD_HTTP_OK : MHD_HTTP_INTERNAL_SERVER_ERROR;
  return reply;
}

/* The writer: one write at a time; every request queued while a write
 * ran is answered by the next one (they all asked for the maps of now). */
static void *writer_thread(void *arg) {
  server *sv = arg;
  pthread_mutex_lock(&sv->lock);
  for (;;) {
    while (!sv->writes && !sv->stop)
      pthread_cond_wait(&sv->wake, &sv->lock);
    if (sv->stop)
      break;
    write_wait *batch = sv->writes;
    sv->writes = NULL;
    pthread_mutex_unlock(&sv->lock);
    unsigned status = 0;
    char *reply = write_maps(sv->s, &status);
    pthread_mutex_lock(&sv->lock);
    for (write_wait *w = batch, *next; w; w = next) {
      next = w->next;
      w->status = status;
      w->reply = reply ? strdup(reply) : NULL;
      w->done = 1;
      MHD_resume_connection(w->conn); /* its handler sends the reply */
    }
    free(reply);
  }
  pthread_mutex_unlock(&sv->lock);
  return NULL;
}

/* POST write: queued for the writer, the connection suspended until it
 * answers; the call after the resume sends the answer. */
static enum MHD_Result queue_write(server *sv, struct MHD_Connection *c, request *rq) {
  if (!rq->queued) {
    rq->queued = 1;
    rq->write.conn = c;
    pthread_mutex_lock(&sv->lock);
    rq->write.next = sv->writes;
    sv->writes = &rq->write;
    MHD_suspend_connection(c);
    pthread_cond_signal(&sv->wake);
    pthread_mutex_unlock(&sv->lock);
    return MHD_YES;
  }
  pthread_mutex_lock(&sv->lock);
  const int done = rq->write.done;
  char *reply = rq->write.reply;
  rq->write.reply = NULL;
  if (!done)
    MHD_suspend_connection(c); /* resumed before its answer: wait on */
  pthread_mutex_unlock(&sv->lock);
  if (!done)
    return MHD_YES;
  return send_json(c, rq->write.status, reply);
}

/* --------------------------------------------------------------- routing */

static int host_ok(const server *sv, struct MHD_Connection *c) {
  const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Host");
  return host && (strcmp(host, sv->host) == 0 ||
                  (sv->host_alt[0] && !strcmp(host, sv->host_alt)));
}

/* The connection's record, marked as no longer waiting for headers. */
static void headers_arrived(server *sv, struct MHD_Connection *c) {
  const union MHD_ConnectionInfo *info =
      MHD_get_connection_info(c, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
  tracked *t = info ? info->socket_context : NULL;
  if (t) {
    pthread_mutex_lock(&sv->lock);
    t->waiting = 0;
    pthread_mutex_unlock(&sv->lock);
  }
}

static enum MHD_Result handle(void *cls, struct MHD_Connection *c, const char *url,
                              const char *method, const char *version,
                              const char *upload_data, size_t *upload_data_size,
                              void **con_cls) {
  (void)version;
  (void)upload_data;
  server *sv = cls;
  request *rq = *con_cls;
  if (!rq) { /* the first call: the headers are in */
    headers_arrived(sv, c);
    if (!(rq = calloc(1, sizeof *rq)))
      return MHD_NO;
    *con_cls = rq;
    /* no request of the page has a body: one is refused before it is read */
    const char *length =
        MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Content-Length");
    if ((length && strcmp(length, "0") != 0) ||
        MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Transfer-Encoding"))
      return send_text(c, MHD_HTTP_CONTENT_TOO_LARGE, "no request takes a body");
    return MHD_YES;
  }
  if (*upload_data_size) { /* cannot happen: a body was refused above */
    *upload_data_size = 0;
    return MHD_YES;
  }
  const int post = strcmp(method, "POST") == 0;
  if (!post && strcmp(method, "GET") != 0 && strcmp(method, "HEAD") != 0)
    return send_text(c, MHD_HTTP_METHOD_NOT_ALLOWED, "GET or POST");
  if (sv->check_host && !host_ok(sv, c))
    return send_text(c, MHD_HTTP_FORBIDDEN, "wrong host");
  const size_t plen = strlen(sv->prefix);
  if (strncmp(url, sv->prefix, plen) != 0)
    return send_text(c, MHD_HTTP_NOT_FOUND, "not found");
  const char *path = url + plen;
  if (post) {
    if (!MHD_lookup_connection_value(c, MHD_HEADER_KIND, "X-Bumpbake"))
      return send_text(c, MHD_HTTP_FORBIDDEN, "a change needs the X-Bumpbake header");
    if (!strcmp(path, "params"))
      return apply_params(sv, c);
    if (!strcmp(path, "write"))
      return queue_write(sv, c, rq);
    return send_text(c, MHD_HTTP_NOT_FOUND, "not found");
  }
  if (!strcmp(path, "state"))
    return send_json(c, MHD_HTTP_OK, serve_state_json(sv->s));
  if (!strcmp(path, "controls"))
    return send_json(c, MHD_HTTP_OK, serve_controls_json());
  if (!strcmp(path, "events"))
    return send_events(sv, c);
  if (!strncmp(path, "map/", 4))
    return send_texture(sv, c, path + 4);
  const serve_asset *a = serve_asset_find(path[0] ? path : "index.html");
  if (!a)
    return send_text(c, MHD_HTTP_NOT_FOUND, "not found");
  return send_bytes(c, MHD_HTTP_OK, a->type, a->data, a->size, MHD_RESPMEM_PERSISTENT);
}

/* A request's end: its state freed, the connection waiting for the next
 * request's headers. */
static void request_done(void *cls, struct MHD_Connection *c, void **con_cls,
                         enum MHD_RequestTerminationCode why) {
  (void)why;
  server *sv = cls;
  request *rq = *con_cls;
  if (rq) {
    free(rq->write.reply);
    free(rq);
    *con_cls = NULL;
  }
  const union MHD_ConnectionInfo *info =
      MHD_get_connection_info(c, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
  tracked *t = info ? info->socket_context : NULL;
  if (t) {
    pthread_mutex_lock(&sv->lock);
    t->waiting = 1;
    t->since = now_seconds();
    pthread_mutex_unlock(&sv->lock);
  }
}

/* Connections as they open and close: listed for the ticker. */
static void connection_seen(void *cls, struct MHD_Connection *c, void **socket_context,
                            enum MHD_ConnectionNotificationCode code) {
  server *sv = cls;
  if (code == MHD_CONNECTION_NOTIFY_STARTED) {
    const union MHD_ConnectionInfo *info =
        MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
    tracked *t = info ? calloc(1, sizeof *t) : NULL;
    *socket_context = t;
    if (!t)
      return; /* out of memory: only MHD's idle timeout bounds it */
    t->fd = info->connect_fd;
    t->since = now_seconds();
    t->waiting = 1;
    pthread_mutex_lock(&sv->lock);
    if ((t->next = sv->connections))
      t->next->prev = t;
    sv->connections = t;
    pthread_mutex_unlock(&sv->lock);
    return;
  }
  tracked *t = *socket_context;
  if (!t)
    return;
  /* MHD closes the socket after this: the ticker never sees it closed */
  pthread_mutex_lock(&sv->lock);
  if (t->prev)
    t->prev->next = t->next;
  else
    sv->connections = t->next;
  if (t->next)
    t->next->prev = t->prev;
  pthread_mutex_unlock(&sv->lock);
  free(t);
  *socket_context = NULL;
}

/* ---------------------------------------------------------------- ticker */

/* Every TICK_MS, and whenever the state changes: event streams with
 * something to send (a new state, or a keep-alive due) are resumed, and
 * connections that have waited HEADER_SECONDS for their headers are cut
 * (shut down: MHD sees the end and closes them). */
static void *ticker_thread(void *arg) {
  server *sv = arg;
  serve_state *s = sv->s;
  for (;;) {
    pthread_mutex_lock(&s->lock);
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_nsec += TICK_MS * 1000000L;
    if (until.tv_nsec >= 1000000000L) {
      until.tv_sec++;
      until.tv_nsec -= 1000000000L;
    }
    pthread_cond_timedwait(&s->changed, &s->lock, &until);
    const long version = s->version;
    pthread_mutex_unlock(&s->lock);
    const double now = now_seconds();
    pthread_mutex_lock(&sv->lock);
    if (sv->stop) {
      pthread_mutex_unlock(&sv->lock);
      break;
    }
    for (event_stream *e = sv->streams; e; e = e->next) {
      if (!e->suspended)
        continue;
      /* a client that closed its end: nothing more to read, ever */
      char byte;
      const ssize_t n = e->fd >= 0 ? recv(e->fd, &byte, 1, MSG_PEEK | MSG_DONTWAIT) : -1;
      e->gone =
          n == 0 || (n < 0 && e->fd >= 0 && errno != EAGAIN && errno != EWOULDBLOCK);
      if (e->gone || e->sent_version != version ||
          now - e->last_sent >= KEEPALIVE_SECONDS) {
        e->suspended = 0;
        MHD_resume_connection(e->conn);
      }
    }
    for (tracked *t = sv->connections; t; t = t->next)
      if (t->waiting && !t->cut && now - t->since > HEADER_SECONDS) {
        t->cut = 1;
        shutdown(t->fd, SHUT_RDWR);
      }
    pthread_mutex_unlock(&sv->lock);
  }
  return NULL;
}

/* ------------------------------------------------------------------ start */

static int random_token(char *out, size_t cap) {
  unsigned char bytes[16];
  if (getrandom(bytes, sizeof bytes, 0) != (ssize_t)sizeof bytes)
    return -1;
  for (size_t i = 0; i < sizeof bytes && 2 * i + 2 < cap; i++)
    snprintf(out + 2 * i, cap - 2 * i, "%02x", bytes[i]);
  return 0;
}

static server sv; /* lives as long as the process */

void serve_http_stop(serve_state *s) {
  if (sv.s != s || !sv.daemon)
    return;
  pthread_mutex_lock(&sv.lock);
  sv.stop = 1;
  pthread_cond_broadcast(&sv.wake);
  /* MHD stops only with no connection suspended */
  for (event_stream *e = sv.streams; e; e = e->next)
    if (e->suspended) {
      e->suspended = 0;
      MHD_resume_connection(e->conn);
    }
  pthread_mutex_unlock(&sv.lock);
  pthread_mutex_lock(&s->lock);
  pthread_cond_broadcast(&s->changed);
  pthread_mutex_unlock(&s->lock);
  if (sv.threads) {
    pthread_join(sv.ticker, NULL);
    pthread_join(sv.writer, NULL);
  }
  MHD_stop_daemon(sv.daemon);
  sv.daemon = NULL;
}

/* The connection limit, within what the process may open (raised to its
 * hard limit when that is needed). */
static unsigned connection_limit(void) {
  struct rlimit r;
  if (getrlimit(RLIMIT_NOFILE, &r) != 0)
    return 256;
  const rlim_t want = CONNECTION_LIMIT + 128;
  if (r.rlim_cur != RLIM_INFINITY && r.rlim_cur < want) {
    r.rlim_cur = r.rlim_max == RLIM_INFINITY || r.rlim_max > want ? want : r.rlim_max;
    setrlimit(RLIMIT_NOFILE, &r);
    getrlimit(RLIMIT_NOFILE, &r);
  }
  if (r.rlim_cur == RLIM_INFINITY || r.rlim_cur >= want)
    return CONNECTION_LIMIT;
  return r.rlim_cur > 256 ? (unsigned)(r.rlim_cur - 128) : 128;
}

int serve_http_start(serve_state *s, const serve_http_options *o, char *url, size_t cap) {
  if (!serve_mhd_load(url, cap)) return -1;
  memset(&sv, 0, sizeof sv);
  sv.s = s;
  pthread_mutex_init(&sv.lock, NULL);
  pthread_cond_init(&sv.wake, NULL);
  const char *address = o->address;
  struct sockaddr_storage addr;
  memset(&addr, 0, sizeof addr);
  struct sockaddr_in *v4 = (struct sockaddr_in *)&addr;
  struct sockaddr_in6 *v6 = (struct sockaddr_in6 *)&addr;
  unsigned flags = MHD_USE_AUTO_INTERNAL_THREAD | MHD_ALLOW_SUSPEND_RESUME;
  int is_v6 = 0;
  if (inet_pton(AF_INET, address, &v4->sin_addr) == 1) {
    v4->sin_family = AF_INET;
    v4->sin_port = htons((uint16_t)o->port);
  } else if (inet_pton(AF_INET6, address, &v6->sin6_addr) == 1) {
    v6->sin6_family = AF_INET6;
    v6->sin6_port = htons((uint16_t)o->port);
    flags |= MHD_USE_IPv6;
    is_v6 = 1;
  } else {
    snprintf(url, cap, "--address %s: not an IPv4 or IPv6 address", address);
    return -1;
  }
  /* Every local client is 127.0.0.1: a share per address only bounds
   * clients from elsewhere, which --address lets in. */
  const unsigned per_client = o->token ? PER_CLIENT_LIMIT : 0;
  sv.daemon = MHD_start_daemon(
      flags, (uint16_t)o->port, NULL, NULL, handle, &sv, MHD_OPTION_SOCK_ADDR,
      (struct sockaddr *)&addr, MHD_OPTION_CONNECTION_LIMIT, connection_limit(),
      MHD_OPTION_PER_IP_CONNECTION_LIMIT, per_client, MHD_OPTION_CONNECTION_TIMEOUT,
      (unsigned)IDLE_SECONDS, MHD_OPTION_CONNECTION_MEMORY_LIMIT,
      (size_t)CONNECTION_MEMORY, MHD_OPTION_NOTIFY_CONNECTION, connection_seen, &sv,
      MHD_OPTION_NOTIFY_COMPLETED, request_done, &sv, MHD_OPTION_END);
  if (!sv.daemon) {
    snprintf(url, cap, "cannot listen on %s port %d: %s", address, o->port,
             errno ? strerror(errno) : "libmicrohttpd refused");
    return -1;
  }
  if (pthread_create(&sv.ticker, NULL, ticker_thread, &sv) != 0) {
    MHD_stop_daemon(sv.daemon);
    sv.daemon = NULL;
    snprintf(url, cap, "cannot start the server's threads");
    return -1;
  }
  if (pthread_create(&sv.writer, NULL, writer_thread, &sv) != 0) {
    pthread_mutex_lock(&sv.lock);
    sv.stop = 1;
    pthread_mutex_unlock(&sv.lock);
    pthread_join(sv.ticker, NULL);
    MHD_stop_daemon(sv.daemon);
    sv.daemon = NULL;
    snprintf(url, cap, "cannot start the server's threads");
    return -1;
  }
  sv.threads = 1;
  const union MHD_DaemonInfo *info =
      MHD_get_daemon_info(sv.daemon, MHD_DAEMON_INFO_BIND_PORT);
  const int port = info ? (int)info->port : o->port;
  snprintf(sv.prefix, sizeof sv.prefix, "/");
  if (o->token) {
    char token[40];
    if (random_token(token, sizeof token) != 0) {
      serve_http_stop(s);
      snprintf(url, cap, "cannot make a random token");
      return -1;
    }
    snprintf(sv.prefix, sizeof sv.prefix, "/%s/", token);
  }
  sv.check_host = !o->token;
  snprintf(sv.host, sizeof sv.host, is_v6 ? "[%s]:%d" : "%s:%d", address, port);
  if (!strcmp(address, "127.0.0.1"))
    snprintf(sv.host_alt, sizeof sv.host_alt, "localhost:%d", port);
  snprintf(url, cap, "http://%s%s", sv.host, sv.prefix);
  return 0;
}
