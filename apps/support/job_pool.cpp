#include "apps/support/job_pool.h"

namespace quiver::app {

JobPool::JobPool(int threads) {
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { work(); });
}

JobPool::~JobPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

qv_job_runner JobPool::runner() {
  qv_job_runner r{};
  r.count = threads();
  r.run = [](void* user, qv_job_function job, void* data, int count) { static_cast<JobPool*>(user)->run(job, data, count); };
  r.user = this;
  return r;
}

void JobPool::drain() {
  for (int i = next_.fetch_add(1); i < count_; i = next_.fetch_add(1)) job_(data_, i);
}

void JobPool::run(qv_job_function job, void* data, int count) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = job;
    data_ = data;
    count_ = count;
    next_ = 0;
    busy_ = static_cast<int>(workers_.size());
    ++generation_;
  }
  wake_.notify_all();
  drain();
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return busy_ == 0; });
}

void JobPool::work() {
  long seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
      if (stopping_) return;
      seen = generation_;
    }
    drain();
    std::lock_guard<std::mutex> lock(mutex_);
    if (--busy_ == 0) done_.notify_one();
  }
}

} // namespace quiver::app
