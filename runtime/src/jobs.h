#pragma once
// The caller's jobs (qv_job_runner): the runtime starts no threads of its own.
#include "quiver/quiver.h"

namespace quiver::rt {

// Calls work(job) once for each job in [0, count): through `jobs` (on whatever threads it runs them)
// when there are several, else here. A job index out of range (a runner's mistake) does nothing.
template <class Work>
void runJobs(const qv_job_runner* jobs, int count, const Work& work) {
  if (!jobs || count <= 1) {
    for (int job = 0; job < count; ++job) work(job);
    return;
  }
  struct Call {
    const Work* work;
    int count;
  } call{&work, count};
  jobs->run(jobs->user,
            [](void* data, int job) {
              const Call& c = *static_cast<const Call*>(data);
              if (job >= 0 && job < c.count) (*c.work)(job);
            },
            &call, count);
}

} // namespace quiver::rt
