/* parallel.c: a tiny thread pool for the per-row loops of smooth and trace. */
#include "core/internal.h"

#include <pthread.h>
#include <stdatomic.h>
#include <time.h>
#include <unistd.h>

double bb__now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

const bb__range bb__range_threads = {"threads", 0, BB_MAX_THREADS, 0, 1};

int bb__thread_count(int threads) {
  if (threads > 0) return threads;
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? (int)n : 1;
}

typedef struct work_queue {
  bb__work_fn fn;
  void *user;
  int items;
  atomic_int next;
  atomic_long done;
  /* The worker that ends the last item wakes the polling caller at once,
   * rather than at its next 50 ms tick (a stage's end, late by up to 50 ms,
   * is time a serve re-bake waits). */
  pthread_mutex_t lock;
  pthread_cond_t finished;
} work_queue;

static void *worker(void *arg) {
  work_queue *q = arg;
  for (;;) {
    int item = atomic_fetch_add(&q->next, 1);
    if (item >= q->items) break;
    q->fn(q->user, item);
    if (atomic_fetch_add(&q->done, 1) + 1 == q->items) {
      pthread_mutex_lock(&q->lock);
      pthread_cond_broadcast(&q->finished);
      pthread_mutex_unlock(&q->lock);
    }
  }
  return NULL;
}

/* Waits until every item is done or 50 ms have passed. */
static void wait_a_tick(work_queue *q) {
  struct timespec until;
  clock_gettime(CLOCK_REALTIME, &until);
  until.tv_nsec += 50 * 1000 * 1000;
  if (until.tv_nsec >= 1000 * 1000 * 1000) {
    until.tv_sec++;
    until.tv_nsec -= 1000 * 1000 * 1000;
  }
  pthread_mutex_lock(&q->lock);
  while (atomic_load(&q->done) < q->items)
    if (pthread_cond_timedwait(&q->finished, &q->lock, &until) != 0)
      break; /* the tick: ask the progress again */
  pthread_mutex_unlock(&q->lock);
}

bb_status bb__parallel_for(int items, int threads, bb__work_fn fn, void *user,
                           bb_progress_fn progress, void *progress_user,
                           bb_error *err) {
  work_queue q = {.fn = fn, .user = user, .items = items, .lock = PTHREAD_MUTEX_INITIALIZER,
                  .finished = PTHREAD_COND_INITIALIZER};
  atomic_init(&q.next, 0);
  atomic_init(&q.done, 0);
  int n = bb__thread_count(threads);
  if (n > items) n = items > 0 ? items : 1;
  if (n == 1 && !progress) {
    worker(&q);
    return BB_OK;
  }
  pthread_t tids[256];
  if (n > 256) n = 256;
  int started = 0, cancelled = 0;
  for (; started < n; started++)
    if (pthread_create(&tids[started], NULL, worker, &q) != 0) break;
  if (started == 0) {
    worker(&q); /* no thread could start: do the work here */
  } else if (progress) {
    /* Poll from the calling thread so the callback never runs concurrently. */
    while (atomic_load(&q.done) < items) {
      if (progress(progress_user, atomic_load(&q.done), items)) {
        cancelled = 1;
        atomic_store(&q.next, items); /* no new items; those running finish */
        break;
      }
      wait_a_tick(&q);
    }
  }
  for (int i = 0; i < started; i++) pthread_join(tids[i], NULL);
  pthread_cond_destroy(&q.finished);
  pthread_mutex_destroy(&q.lock);
  if (!cancelled && progress) cancelled = progress(progress_user, items, items) != 0;
  if (cancelled)
    return bb__fail(err, BB_ERR_CANCELLED, "cancelled by the progress callback");
  return BB_OK;
}

static int checkpoint_poll(void *user, long done, long total) {
  const bb__checkpoint *checkpoint = user;
  (void)done, (void)total;
  return checkpoint->fn(checkpoint->user, 0, 0);
}

bb_status bb__parallel_for_checked(int items, int threads, bb__work_fn fn, void *user,
                                   const bb__checkpoint *checkpoint, bb_error *err) {
  if (!checkpoint || !checkpoint->fn)
    return bb__parallel_for(items, threads, fn, user, NULL, NULL, err);
  return bb__parallel_for(items, threads, fn, user, checkpoint_poll, (void *)checkpoint, err);
}
