#pragma once
// Many instances of one model stepped in one call (qv_instances_step): St.Venant-Kirchhoff Newmark
// instances are evaluated up to ReducedPolynomial::kLanes at a time (each coefficient read once for
// them, SIMD across them) and their Newton matrices factorised together (the fixed Newton steps'
// first systems solved together too); each step otherwise runs as qv_instance_step would run it
// (docs/architecture.md, "Many instances"). The work is cut into
// the caller's jobs; each job owns a slice of the caller's scratch.
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
