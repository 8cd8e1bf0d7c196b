// exr_pool.cpp: bumpbake's provider for OpenEXR's global thread pool (see
// exr_pool.h for why and what it promises).
//
// OpenEXR asks the pool twice: globalThreadCount() when a file is opened,
// which sizes its chunk buffers (2 per thread, 1 for none) and decides
// whether chunks are compressed by tasks; and addTask() for each chunk. Both
// are answered per thread: only a thread inside an ExrWriteThreads sees
// workers, and its tasks go to them; any other thread's tasks run where
// they were added, as under OpenEXR's own pool of no threads. The bytes are
// the same either way: OpenEXR writes the chunks in order whoever
// compressed them.
#include "image/exr_pool.h"
#include "core/internal.h"

#include <OpenEXR/IlmThreadPool.h>

#include <pthread.h>
#include <unistd.h>

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <vector>

namespace {

namespace ilm = IlmThread;

// Workers the EXR write on this thread may use (0: none).
thread_local int write_threads = 0;

// The workers and their queue. Never freed (a process-lifetime object the
// provider below points to): OpenEXR deletes its provider when the global
// pool is destroyed at exit or replaced, and reserve() may still be called.
class Workers {
public:
  Workers() : owner_(getpid()) {}

  // Starts workers up to n, one at a time; returns how many of them the
  // caller may use (fewer when a thread could not start, 0 once stopped or
  // in a forked child).
  int reserve(int n) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopped_ || getpid() != owner_) return 0;
    while ((int)threads_.size() < n) {
      pthread_t t;
      if (pthread_create(&t, nullptr, main, this) != 0) break;
      threads_.push_back(t);
    }
    return (int)threads_.size() < n ? (int)threads_.size() : n;
  }

  void add(ilm::Task *task) {
    if (getpid() == owner_) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!stopped_ && !threads_.empty()) {
        tasks_.push_back(task);
        ready_.notify_one();
        return;
      }
    }
    run(task);
  }

  // Lets the queue run dry and joins the workers (none to join in a forked
  // child: they were not copied).
  void stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopped_ = true;
    }
    ready_.notify_all();
    if (getpid() == owner_)
      for (pthread_t t : threads_) pthread_join(t, nullptr);
    threads_.clear();
  }

  // As OpenEXR's own worker runs a task: the task is deleted before its
  // group hears it finished (deleting a chunk's task releases its buffer).
  static void run(ilm::Task *task) {
    ilm::TaskGroup *group = task->group();
    task->execute();
    delete task;
    group->finishOneTask();
  }

private:
  static void *main(void *self) {
    static_cast<Workers *>(self)->work();
    return nullptr;
  }

  void work() {
    for (;;) {
      ilm::Task *task;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait(lock, [this] { return stopped_ || !tasks_.empty(); });
        if (tasks_.empty()) return;
        task = tasks_.front();
        tasks_.pop_front();
      }
      run(task);
    }
  }

  const pid_t owner_;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<ilm::Task *> tasks_;
  std::vector<pthread_t> threads_;
  bool stopped_ = false;
};

Workers *workers = nullptr;

// What OpenEXR holds and deletes: numbers and tasks passed to the workers.
class Provider final : public ilm::ThreadPoolProvider {
public:
  int numThreads() const override { return write_threads; }
  // The count is the write's own (ExrWriteThreads); a call here (another
  // library in the process setting OpenEXR's global count) changes nothing.
  void setNumThreads(int) override {}
  void addTask(ilm::Task *task) override {
    if (write_threads > 0)
      workers->add(task);
    else
      Workers::run(task);
  }
  void finish() override {
    if (workers) workers->stop();
  }
};

std::once_flag installed;

void install() {
  ilm::ThreadPool &pool = ilm::ThreadPool::globalThreadPool();
  // A pool with threads was set up by the process itself: it stays.
  if (pool.numThreads() != 0) return;
  std::unique_ptr<Workers> w(new Workers());
  Provider *p = new Provider();
  workers = w.release();
  pool.setThreadProvider(p);
}

} // namespace

namespace bb {

ExrWriteThreads::ExrWriteThreads(int threads) : previous_(write_threads) {
  try {
    std::call_once(installed, install);
  } catch (...) {
    // No memory for the provider: the write runs without workers.
  }
  write_threads = workers ? workers->reserve(bb__thread_count(threads)) : 0;
}

ExrWriteThreads::~ExrWriteThreads() { write_threads = previous_; }

} // namespace bb
