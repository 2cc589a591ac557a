#pragma once
// A small pool of worker threads that runs the runtime's jobs (qv_job_runner): the runtime starts no
// threads of its own, so the tools bring these. The caller's thread works too; run() returns once
// every job has run.
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "quiver/quiver.h"

namespace quiver::app {

class JobPool {
public:
  explicit JobPool(int threads);  // threads >= 1, the caller's included
  ~JobPool();
  JobPool(const JobPool&) = delete;
  JobPool& operator=(const JobPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }
  // For qv_instances_step: `threads()` jobs, run by this pool.
  qv_job_runner runner();
  void run(qv_job_function job, void* data, int count);

private:
  void work();
  void drain();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  long generation_ = 0;
  bool stopping_ = false;
  qv_job_function job_ = nullptr;
  void* data_ = nullptr;
  int count_ = 0;
  std::atomic<int> next_{0};
  int busy_ = 0;  // workers inside the current batch
};

} // namespace quiver::app
