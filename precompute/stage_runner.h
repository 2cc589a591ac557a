#pragma once
// What every bake stage shares, written once: a PETSc log stage of its name (so `-log_view` shows
// the bake's profile stage by stage), its wall time (barriers on both ends: the slowest rank's
// view), reuse of its checkpoint when resuming and the stored input hash matches, and its progress
// line "NAME: what it did [s]".
#include <chrono>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <petscsys.h>

#include "precompute/bake_context.h"
#include "precompute/checkpoint.h"
#include "precompute/progress_meter.h"

namespace quiver {

class StageRunner {
public:
  // `resume` lets checkpointed stages reuse what the archive holds. The bake opens the archive once
  // the partition is known: checkpointed stages need setArchive first, plain ones never.
  StageRunner(const BakeContext& ctx, bool resume) : ctx_(ctx), resume_(resume) {}
  void setArchive(Archive* archive) { archive_ = archive; }

  // Runs `body` as stage `name`; returns what it returns.
  template <class Body>
  auto run(const char* name, Body&& body) {
    PetscLogStage stage = logStage(name);
    PetscLogStagePush(stage);
    MPI_Barrier(ctx_.comm());
    const auto start = std::chrono::steady_clock::now();
    struct Finish {  // also when `body` throws: the log stage is popped and the time kept
      StageRunner& runner;
      const char* name;
      std::chrono::steady_clock::time_point start;
      ~Finish() {
        runner.seconds_.emplace_back(name, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        PetscLogStagePop();
      }
    };
    Finish finish{*this, name, start};
    auto result = body();
    MPI_Barrier(ctx_.comm());
    return result;
  }

  // A checkpointed stage: reads its results back from `group` when resuming and the archive holds
  // them under `inputHash`, otherwise computes and writes them. `reused` says which happened.
  template <class Read, class Compute, class Write>
  auto checkpointed(const char* name, const std::string& group, const std::string& inputHash, Read read,
                    Compute compute, Write write, bool& reused) {
    return run(name, [&] {
      reused = resume_ && storedInputHash(*archive_, group) == inputHash;
      if (reused) return read(*archive_);
      auto result = compute();
      write(*archive_, result, inputHash);
      return result;
    });
  }

  // "quiver-bake: NAME: text [0.123 s]" on rank 0, for the stage that ran last.
  void report(const std::string& text, bool reused = false) const {
    ctx_.progress(seconds_.back().first + ": " + (reused ? "reused, " : "") + text + " [" + shortNumber(last()) + " s]");
  }

  double last() const { return seconds_.back().second; }
  const std::vector<std::pair<std::string, double>>& all() const { return seconds_; }

private:
  static PetscLogStage logStage(const char* name) {
    static std::map<std::string, PetscLogStage> registered;  // PETSc wants each name registered once
    auto found = registered.find(name);
    if (found != registered.end()) return found->second;
    PetscLogStage stage = 0;
    PetscLogStageRegister(name, &stage);
    return registered.emplace(name, stage).first->second;
  }

  const BakeContext& ctx_;
  bool resume_;
  Archive* archive_ = nullptr;
  std::vector<std::pair<std::string, double>> seconds_;
};

} // namespace quiver
