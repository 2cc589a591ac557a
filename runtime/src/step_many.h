#pragma once
// Many instances of one model stepped in one call (qv_instances_step): groups of up to
// ReducedPolynomial::kLanes St.Venant-Kirchhoff Newmark instances evaluate their first guess
// together (each coefficient read once per group, SIMD across the group), then each finishes its
// step as qv_instance_step would. The work is cut into the caller's jobs; each job owns a slice of
// the caller's scratch.
#include "instance.h"

namespace quiver::rt {

// Bytes of scratch each job needs (64-byte multiple).
size_t stepManyScratchPerJob(const qv_model& model);

// Steps `count` instances of one model (checked by the caller) in runner->count jobs run by
// `runner` (null: one job, here); job j uses `scratch` (64-byte aligned) from j times
// stepManyScratchPerJob on. statuses[i] for each, when `statuses` is not null.
void stepMany(qv_instance* const* instances, int count, const qv_job_runner* runner, void* scratch,
              qv_step_status* statuses);

} // namespace quiver::rt
