/* serve_watch.c: re-bakes when an input is saved. inotify watches the
 * directories of the inputs, not the files: editors and painting programs
 * (Krita, GIMP, Photoshop) write a new file and rename it over the old one,
 * which a watch on the old file's inode would miss. A rename into place or
 * a closed write is a whole save and bakes at once; a file written in
 * several goes without being closed (or through a writer that keeps it
 * open) bakes once it has been quiet and its size and time stable for a
 * moment. A save that is still half written when read fails to decode:
 * the page keeps the last good maps and shows the error until the next
 * save.
 *
 * A file deleted or moved away asks for a bake too: it fails on the
 * missing file, and the page says so in the library's words. A watch
 * follows its directory's inode, so each directory's parent is watched as
 * well: when the directory is moved away or deleted (its own
 * IN_MOVE_SELF, IN_DELETE_SELF) the watch is dropped, and when a
 * directory of its name appears again (the parent's IN_CREATE or
 * IN_MOVED_TO) it is watched again and baked from, so a folder moved
 * aside and made again keeps working, and one moved away is not watched
 * any more. */
#include "serve.h"

#include <errno.h>
#include <limits.h>
#include <poll.h>
#include <pthread.h>
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

/* What a file's directory gets told, and its parent about it. */
#define DIR_EVENTS                                                                       \
  (IN_MOVED_TO | IN_CLOSE_WRITE | IN_MODIFY | IN_CREATE | IN_DELETE | IN_MOVED_FROM |    \
   IN_DELETE_SELF | IN_MOVE_SELF)
#define PARENT_EVENTS (IN_CREATE | IN_MOVED_TO | IN_ONLYDIR)

struct serve_watch {
  serve_state *s;
  int fd;
  int stop_fd; /* an eventfd: written to stop the thread */
  pthread_t thread;
  /* per watched file: */
  char dir[SERVE_MAX_WATCHED][PATH_MAX];    /* its directory as its path names it */
  char parent[SERVE_MAX_WATCHED][PATH_MAX]; /* that directory's parent, "" for none */
  const char *dir_name[SERVE_MAX_WATCHED];  /* the directory's name in the parent */
  int wd[SERVE_MAX_WATCHED]; /* the watch of its directory, -1 while it is gone */
  int parent_wd[SERVE_MAX_WATCHED];
  const char *base[SERVE_MAX_WATCHED];
  int pending; /* a write without a close was seen */
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
    if (st.st_size != w->last[i].st_size ||
        st.st_mtim.tv_sec != w->last[i].st_mtim.tv_sec ||
        st.st_mtim.tv_nsec != w->last[i].st_mtim.tv_nsec)
      same = 0;
    w->last[i] = st;
  }
  return same;
}

/* Splits path's directory into w->dir[i] (as the path names it: "sub",
 * "/abs/sub", "." for a bare name), its parent and its name there. The
 * working directory ("." ) follows the process wherever it is moved, as
 * the reads of a bare name do, so it has no parent to watch. */
static void split(watch *w, int i, const char *path) {
  const char *slash = strrchr(path, '/');
  if (!slash)
    snprintf(w->dir[i], PATH_MAX, ".");
  else if (slash == path)
    snprintf(w->dir[i], PATH_MAX, "/");
  else
    snprintf(w->dir[i], PATH_MAX, "%.*s", (int)(slash - path), path);
  char *d = w->dir[i];
  size_t n = strlen(d);
  while (n > 1 && d[n - 1] == '/')
    d[--n] = '\0';
  w->parent[i][0] = '\0';
  w->dir_name[i] = d;
  if (!strcmp(d, "/") || !strcmp(d, ".") || !strcmp(d, ".."))
    return;
  const char *last = strrchr(d, '/');
  if (!last) {
    snprintf(w->parent[i], PATH_MAX, ".");
    w->dir_name[i] = d;
  } else {
    snprintf(w->parent[i], PATH_MAX, "%.*s", last == d ? 1 : (int)(last - d), d);
    w->dir_name[i] = last + 1;
  }
  if (!strcmp(w->dir_name[i], ".") || !strcmp(w->dir_name[i], ".."))
    w->parent[i][0] = '\0'; /* "a/.." names no directory of its own */
}

/* Watches the directory of every file that shares dir with file i again;
 * 1 when it is there. */
static int arm(watch *w, int i) {
  const int wd = inotify_add_watch(w->fd, w->dir[i], DIR_EVENTS);
  for (int k = 0; k < w->s->watched_count; k++)
    if (!strcmp(w->dir[k], w->dir[i]))
      w->wd[k] = wd;
  return wd >= 0;
}

/* The directory of file i went (moved away or deleted): its watch is
 * dropped, for every file in it. */
static void disarm(watch *w, int i) {
  const int wd = w->wd[i];
  if (wd < 0)
    return;
  inotify_rm_watch(w->fd, wd); /* a moved directory's watch would follow it */
  for (int k = 0; k < w->s->watched_count; k++)
    if (w->wd[k] == wd)
      w->wd[k] = -1;
}

/* Reads the events waiting; returns 2 for a whole save (or a file or its
 * directory gone or back: a bake says what is there), 1 for a partial
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
      for (int i = 0; i < w->s->watched_count; i++) {
        if (e->wd == w->wd[i] &&
            (e->mask & (IN_DELETE_SELF | IN_MOVE_SELF | IN_IGNORED))) {
          disarm(w, i);
          arm(w, i); /* there again already (renamed back): watched again */
          seen = 2;
        } else if (e->len && e->wd == w->parent_wd[i] && w->wd[i] < 0 &&
                   !strcmp(e->name, w->dir_name[i])) {
          arm(w, i); /* a directory of its name: what was saved there is baked */
          seen = 2;
        } else if (e->len && e->wd == w->wd[i] && !strcmp(e->name, w->base[i])) {
          const int whole =
              (e->mask & (IN_MOVED_TO | IN_CLOSE_WRITE | IN_DELETE | IN_MOVED_FROM)) != 0;
          if ((whole ? 2 : 1) > seen)
            seen = whole ? 2 : 1;
        }
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
    snprintf(err, cap, "cannot watch the inputs: %s: %s",
             w->fd < 0 ? "inotify" : "eventfd", strerror(errno));
    watch_free(w);
    return -1;
  }
  for (int i = 0; i < s->watched_count; i++) {
    split(w, i, s->watched[i]);
    w->base[i] = base_name(s->watched[i]);
    w->parent_wd[i] = -1;
    if (!arm(w, i)) {
      snprintf(err, cap, "cannot watch %s: %s", w->dir[i], strerror(errno));
      watch_free(w);
      return -1;
    }
    /* a parent that cannot be watched (not readable) only loses the
     * re-arming after a move */
    if (w->parent[i][0])
      w->parent_wd[i] = inotify_add_watch(w->fd, w->parent[i], PARENT_EVENTS);
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
