/* serve_http.c: `bumpbake serve`'s HTTP side, on libmicrohttpd (a thread
 * per connection): the page and its scripts, the state as JSON and as
 * server-sent events, the ranges of the page's inputs (the library's), the
 * textures of the last good bake as raw 8-bit RGBA, the controls and the
 * "write" action. Every path is one of a fixed few: no part of a request
 * names a file. Requests must come for the host they were served as (a page
 * elsewhere cannot rebind a name to us), and those that change something
 * must carry an X-Bumpbake header (which a page of another origin cannot
 * send without asking first); with --address, every path also starts with
 * a random token. */
#include "serve.h"

#include <arpa/inet.h>
#include <errno.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/socket.h>
#include <time.h>

typedef struct server {
  serve_state *s;
  struct MHD_Daemon *daemon;
  char prefix[64]; /* "/" or "/TOKEN/" */
  char host[128];  /* the Host header requests must carry ("127.0.0.1:8077") */
  char host_alt[128]; /* "localhost:8077" for the loopback, else "" */
  int check_host;  /* without a token: the Host header is checked */
} server;

/* ------------------------------------------------------------ responses */

/* Every response's headers: its type, never cached, never sniffed as
 * another type, and never shown in a frame (a page elsewhere cannot lay
 * the page under a decoy and have a click "write the maps"); the page
 * runs, styles and fetches only what this server sends. */
static const char *const policy = "default-src 'none'; script-src 'self'; style-src 'self'; "
                                  "connect-src 'self'; img-src 'self' data:; base-uri 'none'; "
                                  "form-action 'none'; frame-ancestors 'none'";

static enum MHD_Result queue(struct MHD_Connection *c, unsigned status, struct MHD_Response *r,
                             const char *type) {
  MHD_add_response_header(r, "Content-Type", type);
  MHD_add_response_header(r, "Cache-Control", "no-store");
  MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
  MHD_add_response_header(r, "X-Frame-Options", "DENY");
  MHD_add_response_header(r, "Content-Security-Policy", policy);
  enum MHD_Result ret = MHD_queue_response(c, status, r);
  MHD_destroy_response(r);
  return ret;
}

static enum MHD_Result send_bytes(struct MHD_Connection *c, unsigned status, const char *type,
                                  const void *data, size_t size, enum MHD_ResponseMemoryMode mode) {
  struct MHD_Response *r = MHD_create_response_from_buffer(size, (void *)data, mode);
  if (!r)
    return MHD_NO;
  return queue(c, status, r, type);
}

static enum MHD_Result send_text(struct MHD_Connection *c, unsigned status, const char *text) {
  return send_bytes(c, status, "text/plain; charset=utf-8", text, strlen(text),
                    MHD_RESPMEM_MUST_COPY);
}

/* A malloc'd JSON text, handed to the response. */
static enum MHD_Result send_json(struct MHD_Connection *c, unsigned status, char *json) {
  if (!json)
    return send_text(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "out of memory");
  return send_bytes(c, status, "application/json", json, strlen(json), MHD_RESPMEM_MUST_FREE);
}

/* {"error": message} */
static enum MHD_Result send_error(struct MHD_Connection *c, unsigned status, const char *msg) {
  char *text = NULL;
  size_t size = 0;
  FILE *f = open_memstream(&text, &size);
  if (!f)
    return send_text(c, status, msg);
  bb_json j = {f, 0};
  bb_json_open(&j, NULL, '{');
  bb_json_string(&j, "error", msg);
  bb_json_close(&j, '}');
  fclose(f);
  return send_json(c, status, text);
}

/* ------------------------------------------------------------- textures */

typedef struct texture_read {
  serve_state *s;
  serve_bake *bake;
  const unsigned char *data;
} texture_read;

static ssize_t texture_reader(void *cls, uint64_t pos, char *buf, size_t max) {
  texture_read *t = cls;
  const size_t size = 4 * (size_t)t->bake->width * (size_t)t->bake->height;
  if (pos >= size)
    return MHD_CONTENT_READER_END_OF_STREAM;
  size_t n = size - (size_t)pos < max ? size - (size_t)pos : max;
  memcpy(buf, t->data + pos, n);
  return (ssize_t)n;
}

static void texture_free(void *cls) {
  texture_read *t = cls;
  pthread_mutex_lock(&t->s->lock);
  serve_bake_release(t->bake);
  pthread_mutex_unlock(&t->s->lock);
  free(t);
}

static const char *const texture_names[SERVE_TEX_COUNT] = {"ssbump_ao", "normal_height",
                                                           "bent", "weights"};

/* One texture of the last good bake; X-Bake-Id says which bake it is. */
static enum MHD_Result send_texture(server *sv, struct MHD_Connection *c, const char *name) {
  int t = 0;
  while (t < SERVE_TEX_COUNT && strcmp(texture_names[t], name) != 0)
    t++;
  if (t == SERVE_TEX_COUNT)
    return send_text(c, MHD_HTTP_NOT_FOUND, "no such map");
  texture_read *r = calloc(1, sizeof *r);
  if (!r)
    return send_text(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "out of memory");
  pthread_mutex_lock(&sv->s->lock);
  r->s = sv->s;
  r->bake = sv->s->current;
  if (r->bake)
    r->bake->refs++;
  pthread_mutex_unlock(&sv->s->lock);
  if (!r->bake) {
    free(r);
    return send_text(c, MHD_HTTP_SERVICE_UNAVAILABLE, "no bake yet");
  }
  r->data = serve_bake_texture(r->bake, t); /* made on first use */
  if (!r->data) {
    texture_free(r);
    return send_text(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "out of memory");
  }
  const uint64_t size = 4 * (uint64_t)r->bake->width * (uint64_t)r->bake->height;
  char id[32], w[16], h[16];
  snprintf(id, sizeof id, "%ld", r->bake->id);
  snprintf(w, sizeof w, "%d", r->bake->width);
  snprintf(h, sizeof h, "%d", r->bake->height);
  struct MHD_Response *resp =
      MHD_create_response_from_callback(size, 256 * 1024, texture_reader, r, texture_free);
  if (!resp) {
    texture_free(r);
    return MHD_NO;
  }
  MHD_add_response_header(resp, "X-Bake-Id", id);
  MHD_add_response_header(resp, "X-Width", w);
  MHD_add_response_header(resp, "X-Height", h);
  return queue(c, MHD_HTTP_OK, resp, "application/octet-stream");
}

/* --------------------------------------------------------------- events */

/* One event stream: the state each time it changes, as "data:" lines;
 * a comment every 15 s keeps proxies and the browser from giving up. */
typedef struct event_stream {
  serve_state *s;
  long sent_version;
  char *pending; /* the event being sent, and how much of it went */
  size_t size, offset;
} event_stream;

static ssize_t event_reader(void *cls, uint64_t pos, char *buf, size_t max) {
  (void)pos;
  event_stream *e = cls;
  if (!e->pending) {
    serve_state *s = e->s;
    pthread_mutex_lock(&s->lock);
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_sec += 15;
    int timed_out = 0;
    while (s->version == e->sent_version && !s->quit && !timed_out)
      timed_out = pthread_cond_timedwait(&s->changed, &s->lock, &until) == ETIMEDOUT;
    const int quit = s->quit;
    e->sent_version = s->version;
    pthread_mutex_unlock(&s->lock);
    if (quit)
      return MHD_CONTENT_READER_END_OF_STREAM;
    if (timed_out) {
      e->pending = strdup(": still here\n\n");
    } else {
      char *json = serve_state_json(s);
      if (json) {
        size_t n = strlen(json) + 16;
        if ((e->pending = malloc(n)))
          snprintf(e->pending, n, "data: %s\n\n", json);
        free(json);
      }
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
  free(e->pending);
  free(e);
}

static enum MHD_Result send_events(server *sv, struct MHD_Connection *c) {
  event_stream *e = calloc(1, sizeof *e);
  if (!e)
    return send_text(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "out of memory");
  e->s = sv->s;
  e->sent_version = -1; /* the state at once */
  struct MHD_Response *r =
      MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 64 * 1024, event_reader, e, event_free);
  if (!r) {
    event_free(e);
    return MHD_NO;
  }
  return queue(c, MHD_HTTP_OK, r, "text/event-stream");
}

/* ------------------------------------------------------------- controls */

typedef struct param_list {
  const char *name[16], *value[16];
  int count, too_many;
} param_list;

static enum MHD_Result collect_param(void *cls, enum MHD_ValueKind kind, const char *key,
                                     const char *value) {
  (void)kind;
  param_list *p = cls;
  if (p->count == 16) {
    p->too_many = 1;
    return MHD_NO;
  }
  p->name[p->count] = key;
  p->value[p->count++] = value ? value : "";
  return MHD_YES;
}

/* POST params?scale=64&rays=256...: all or none applied, then a re-bake. */
static enum MHD_Result apply_params(server *sv, struct MHD_Connection *c) {
  param_list p = {{0}, {0}, 0, 0};
  MHD_get_connection_values(c, MHD_GET_ARGUMENT_KIND, collect_param, &p);
  if (p.too_many)
    return send_error(c, MHD_HTTP_BAD_REQUEST, "too many values");
  char err[512] = "";
  pthread_mutex_lock(&sv->s->lock);
  int rc = serve_apply_params(sv->s, p.name, p.value, p.count, err, sizeof err);
  if (rc == 0)
    serve_request_bake(sv->s); /* cancels the bake in flight */
  pthread_mutex_unlock(&sv->s->lock);
  if (rc != 0)
    return send_error(c, MHD_HTTP_BAD_REQUEST, err);
  return send_json(c, MHD_HTTP_OK, serve_state_json(sv->s));
}

/* The bake shown with a reference held, when it is what the `bumpbake
 * bake` line of the options now would bake: no save or control came after
 * it (nothing pending, in flight or failed since), and its command line is
 * the one of the options now. Else NULL. The caller holds the lock. */
static serve_bake *bake_of_now(serve_state *s, const bb_job_options *o) {
  serve_bake *b = s->current;
  if (!b || !b->job || s->baking || s->error[0] || atomic_load(&s->wanted) != s->done ||
      b->wanted != s->done)
    return NULL;
  char *command = bb_job_command_text(o, s->height_path);
  const int same = command && b->command && strcmp(command, b->command) == 0;
  free(command);
  if (!same)
    return NULL;
  b->refs++;
  return b;
}

/* POST write: the maps written through the job, as the `bumpbake bake`
 * line the page shows would write them: from the maps shown when they are
 * that line's bake (bb_job_write_item on the job that baked them: the same
 * bytes, no second bake), else by baking again (bb_job_run_item: a save
 * or control still pending, or Valve's detail variant). The reply is the
 * line `bake --json` prints, with "from" saying which. */
static enum MHD_Result write_maps(server *sv, struct MHD_Connection *c) {
  bb_job_options o;
  pthread_mutex_lock(&sv->s->lock);
  serve_job_options(sv->s, &o);
  const char *input = sv->s->height_path;
  serve_bake *b = bake_of_now(sv->s, &o);
  pthread_mutex_unlock(&sv->s->lock);
  bb_error err = {{0}};
  bb_status st = BB_ERR_ARGUMENT;
  const char *from = "memory";
  bb_job *job = NULL;
  char *text = NULL;
  size_t size = 0;
  if (b) {
    pthread_mutex_lock(&b->tex_lock); /* one write of its job at a time */
    st = bb_job_write_item(b->job, 0, &b->maps, &err);
    if (st == BB_OK) {
      FILE *f = open_memstream(&text, &size);
      if (f) {
        bb_job_report_json(f, &o.bake, bb_job_report_get(b->job, 0), "written", NULL);
        fclose(f);
      }
    }
    pthread_mutex_unlock(&b->tex_lock);
  }
  if (st == BB_ERR_ARGUMENT) { /* not this bake's line, or a file it cannot write */
    from = "bake";
    free(text);
    text = NULL;
    memset(&err, 0, sizeof err);
    st = bb_job_plan(&input, 1, &o, &job, &err);
    if (st == BB_OK) {
      st = bb_job_run_item(job, 0, NULL, NULL);
      if (st != BB_OK)
        err = bb_job_report_get(job, 0)->error;
    }
    if (st == BB_OK) {
      FILE *f = open_memstream(&text, &size);
      if (f) {
        bb_job_report_json(f, &o.bake, bb_job_report_get(job, 0), "written", NULL);
        fclose(f);
      }
    }
    bb_job_free(job);
  }
  if (b) {
    pthread_mutex_lock(&sv->s->lock);
    serve_bake_release(b);
    pthread_mutex_unlock(&sv->s->lock);
  }
  if (!sv->s->quiet && st == BB_OK)
    fprintf(stderr, "serve: wrote the maps (%s)\n",
            strcmp(from, "memory") ? "baked again" : "from the bake shown");
  if (st != BB_OK) {
    free(text);
    return send_error(c, 422, err.message[0] ? err.message : bb_status_name(st));
  }
  /* {"from": "memory" or "bake", then bake --json's keys} */
  char *reply = NULL;
  if (text && text[0] == '{') {
    const size_t cap = strlen(text) + 32;
    if ((reply = malloc(cap)))
      snprintf(reply, cap, "{\"from\":\"%s\",%s", from, text + 1);
  }
  free(text);
  return send_json(c, MHD_HTTP_OK, reply);
}

/* --------------------------------------------------------------- routing */

static int host_ok(const server *sv, struct MHD_Connection *c) {
  const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Host");
  return host && (strcmp(host, sv->host) == 0 || (sv->host_alt[0] && !strcmp(host, sv->host_alt)));
}

static enum MHD_Result handle(void *cls, struct MHD_Connection *c, const char *url,
                              const char *method, const char *version, const char *upload_data,
                              size_t *upload_data_size, void **con_cls) {
  (void)version;
  (void)upload_data;
  server *sv = cls;
  const int post = strcmp(method, "POST") == 0;
  if (post && *con_cls == NULL) { /* the first call of a POST: its body comes next */
    *con_cls = sv;
    return MHD_YES;
  }
  if (post && *upload_data_size) { /* a body is not read: the values are in the query */
    *upload_data_size = 0;
    return MHD_YES;
  }
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
      return write_maps(sv, c);
    return send_text(c, MHD_HTTP_NOT_FOUND, "not found");
  }
  if (!strcmp(path, "state"))
    return send_json(c, MHD_HTTP_OK, serve_state_json(sv->s));
  if (!strcmp(path, "ranges"))
    return send_json(c, MHD_HTTP_OK, serve_ranges_json());
  if (!strcmp(path, "events"))
    return send_events(sv, c);
  if (!strncmp(path, "map/", 4))
    return send_texture(sv, c, path + 4);
  const serve_asset *a = serve_asset_find(path[0] ? path : "index.html");
  if (!a)
    return send_text(c, MHD_HTTP_NOT_FOUND, "not found");
  return send_bytes(c, MHD_HTTP_OK, a->type, a->data, a->size, MHD_RESPMEM_PERSISTENT);
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
  if (sv.s == s && sv.daemon)
    MHD_stop_daemon(sv.daemon);
  sv.daemon = NULL;
}

int serve_http_start(serve_state *s, const serve_http_options *o, char *url, size_t cap) {
  memset(&sv, 0, sizeof sv);
  sv.s = s;
  const char *address = o->address ? o->address : "127.0.0.1";
  struct sockaddr_storage addr;
  memset(&addr, 0, sizeof addr);
  struct sockaddr_in *v4 = (struct sockaddr_in *)&addr;
  struct sockaddr_in6 *v6 = (struct sockaddr_in6 *)&addr;
  unsigned flags = MHD_USE_THREAD_PER_CONNECTION | MHD_USE_INTERNAL_POLLING_THREAD;
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
  sv.daemon = MHD_start_daemon(flags, (uint16_t)o->port, NULL, NULL, handle, &sv,
                               MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr,
                               MHD_OPTION_CONNECTION_LIMIT, (unsigned)64,
                               /* an idle connection goes after 60 s; events send every 15 s */
                               MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)60, MHD_OPTION_END);
  if (!sv.daemon) {
    snprintf(url, cap, "cannot listen on %s port %d: %s", address, o->port,
             errno ? strerror(errno) : "libmicrohttpd refused");
    return -1;
  }
  const union MHD_DaemonInfo *info = MHD_get_daemon_info(sv.daemon, MHD_DAEMON_INFO_BIND_PORT);
  const int port = info ? (int)info->port : o->port;
  snprintf(sv.prefix, sizeof sv.prefix, "/");
  if (o->token) {
    char token[40];
    if (random_token(token, sizeof token) != 0) {
      snprintf(url, cap, "cannot make a random token");
      MHD_stop_daemon(sv.daemon);
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
