/* serve_watch.c: re-bakes when an input is saved. inotify watches the
 * directories of the inputs, not the files: editors and painting programs
 * (Krita, GIMP, Photoshop) write a new file and rename it over the old one,
 * which a watch on the old file's inode would miss. A rename into place or
 * a closed write is a whole save and bakes at once; a file written in
 * several goes without being closed (or through a writer that keeps it
 * open) bakes once it has been quiet and its size and time stable for a
 * moment. A save that is still half written when read fails to decode:
 * the page keeps the last good maps and shows the error until the next
 * save. */
#include "serve.h"

#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/eventfd.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* How long a file written without a close must stay unchanged. */
#define QUIET_MS 150

struct serve_watch {
  serve_state *s;
  int fd;
  int stop_fd;                     /* an eventfd: written to stop the thread */
  pthread_t thread;
  int wd[SERVE_MAX_WATCHED];       /* the watch of each file's directory */
  const char *base[SERVE_MAX_WATCHED];
  int pending;                     /* a write without a close was seen */
  struct stat last[SERVE_MAX_WATCHED];
};
typedef struct serve_watch watch;

static const char *base_name(const char *path) {
  const char *slash = strrchr(path, '/');
  return slash ? slash + 1 : path;
}

static void request(watch *w) {
  pthread_mutex_lock(&w->s->lock);
  serve_request_bake(w->s);
  pthread_mutex_unlock(&w->s->lock);
}

/* 1 when every watched file has the size and time it had last time. */
static int stable(watch *w) {
  int same = 1;
  for (int i = 0; i < w->s->watched_count; i++) {
    struct stat st;
    memset(&st, 0, sizeof st);
    stat(w->s->watched[i], &st);
    if (st.st_size != w->last[i].st_size || st.st_mtim.tv_sec != w->last[i].st_mtim.tv_sec ||
        st.st_mtim.tv_nsec != w->last[i].st_mtim.tv_nsec)
      same = 0;
    w->last[i] = st;
  }
  return same;
}

/* Reads the events waiting; returns 2 for a whole save, 1 for a partial
 * write, 0 for nothing of ours. */
static int read_events(watch *w) {
  char buf[16 * (sizeof(struct inotify_event) + NAME_MAX + 1)]
      __attribute__((aligned(__alignof__(struct inotify_event))));
  int seen = 0;
  for (;;) {
    ssize_t n = read(w->fd, buf, sizeof buf);
    if (n <= 0)
      break;
    for (char *p = buf; p < buf + n;) {
      const struct inotify_event *e = (const struct inotify_event *)p;
      p += sizeof *e + e->len;
      if (!e->len)
        continue;
      for (int i = 0; i < w->s->watched_count; i++) {
        if (e->wd != w->wd[i] || strcmp(e->name, w->base[i]) != 0)
          continue;
        const int whole = (e->mask & (IN_MOVED_TO | IN_CLOSE_WRITE)) != 0;
        if ((whole ? 2 : 1) > seen)
          seen = whole ? 2 : 1;
      }
    }
  }
  return seen;
}

static void *watch_thread(void *arg) {
  watch *w = arg;
  for (;;) {
    struct pollfd pfd[2] = {{w->fd, POLLIN, 0}, {w->stop_fd, POLLIN, 0}};
    int ready = poll(pfd, 2, w->pending ? QUIET_MS : -1);
    if (ready < 0 && errno != EINTR)
      break;
    if (ready > 0 && pfd[1].revents)
      break; /* serve_watch_stop */
    if (ready > 0) {
      int seen = read_events(w);
      if (seen == 2) {
        w->pending = 0;
        request(w); /* a newer save also cancels the bake in flight */
      } else if (seen == 1) {
        w->pending = 1;
        stable(w);
      }
    } else if (ready == 0 && w->pending && stable(w)) {
      w->pending = 0; /* quiet, and nothing moved since the last look */
      request(w);
    }
  }
  return NULL;
}

static void watch_free(watch *w) {
  if (w->fd >= 0)
    close(w->fd);
  if (w->stop_fd >= 0)
    close(w->stop_fd);
  free(w);
}

int serve_watch_start(serve_state *s, serve_watch **out, char *err, size_t cap) {
  *out = NULL;
  watch *w = calloc(1, sizeof *w);
  if (!w) {
    snprintf(err, cap, "out of memory");
    return -1;
  }
  w->s = s;
  w->fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  w->stop_fd = eventfd(0, EFD_CLOEXEC);
  if (w->fd < 0 || w->stop_fd < 0) {
    snprintf(err, cap, "cannot watch the inputs: %s: %s", w->fd < 0 ? "inotify" : "eventfd",
             strerror(errno));
    watch_free(w);
    return -1;
  }
  for (int i = 0; i < s->watched_count; i++) {
    char dir[PATH_MAX];
    const char *slash = strrchr(s->watched[i], '/');
    if (slash)
      snprintf(dir, sizeof dir, "%.*s", (int)(slash - s->watched[i] + 1), s->watched[i]);
    else
      snprintf(dir, sizeof dir, ".");
    w->base[i] = base_name(s->watched[i]);
    w->wd[i] = inotify_add_watch(w->fd, dir,
                                 IN_MOVED_TO | IN_CLOSE_WRITE | IN_MODIFY | IN_CREATE);
    if (w->wd[i] < 0) {
      snprintf(err, cap, "cannot watch %s: %s", dir, strerror(errno));
      watch_free(w);
      return -1;
    }
  }
  if (pthread_create(&w->thread, NULL, watch_thread, w) != 0) {
    snprintf(err, cap, "cannot start the watch thread");
    watch_free(w);
    return -1;
  }
  *out = w;
  return 0;
}

void serve_watch_stop(serve_watch *w) {
  if (!w)
    return;
  const uint64_t one = 1;
  if (write(w->stop_fd, &one, sizeof one) != (ssize_t)sizeof one)
    return; /* cannot happen on an eventfd below its maximum; the thread keeps w */
  pthread_join(w->thread, NULL);
  watch_free(w);
}
