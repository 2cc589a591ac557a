#pragma once
// Progress of a long stage: once the stage has run a few seconds, rank 0 prints
// "quiver-bake: derivatives: 96 of 210 solved, 12 s left" at most every few seconds. Quick stages
// print nothing extra. Stages report through a plain callback so that they need no context.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>

#include "precompute/bake_context.h"

namespace quiver {

// A number in a progress line: three significant digits ("0.00324", "1.39e+03").
inline std::string shortNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

// (done, total): called by a stage as work completes; may be empty.
using ProgressCallback = std::function<void(int64_t done, int64_t total)>;

class ProgressMeter {
public:
  // Lines read "STAGE: DONE of TOTAL VERB, about N s left".
  ProgressMeter(const BakeContext& ctx, std::string stage, std::string verb, double intervalSeconds = 3.0)
      : ctx_(ctx), stage_(std::move(stage)), verb_(std::move(verb)), interval_(intervalSeconds),
        start_(std::chrono::steady_clock::now()), lastPrint_(start_) {}

  // The rate is measured from the first update on, so set-up work done before it (a
  // factorization, say) does not inflate the estimate.
  void update(int64_t done, int64_t total) {
    const auto now = std::chrono::steady_clock::now();
    if (firstDone_ < 0) {
      firstDone_ = done;
      first_ = now;
      return;
    }
    if (done <= firstDone_ || done >= total || seconds(start_, now) < interval_ || seconds(lastPrint_, now) < interval_)
      return;
    lastPrint_ = now;
    const double left = seconds(first_, now) * static_cast<double>(total - done) / static_cast<double>(done - firstDone_);
    ctx_.progress(stage_ + ": " + std::to_string(done) + " of " + std::to_string(total) + " " + verb_ + ", about " +
                  std::to_string(static_cast<int64_t>(left + 0.5)) + " s left");
  }
  ProgressCallback callback() {
    return [this](int64_t done, int64_t total) { update(done, total); };
  }

private:
  static double seconds(std::chrono::steady_clock::time_point from, std::chrono::steady_clock::time_point to) {
    return std::chrono::duration<double>(to - from).count();
  }
  const BakeContext& ctx_;
  std::string stage_, verb_;
  double interval_;
  std::chrono::steady_clock::time_point start_, lastPrint_, first_;
  int64_t firstDone_ = -1;
};

} // namespace quiver
