#pragma once
// QV_SOLVER_NEWTON, for both implicit integrators: exactly newton_iterations Newton iterations, the
// first linearised at the state itself (the predictor of Barbic & James 2005, and of Vega's
// implicit Newmark), then an energy budget like the minimiser's (incremental_potential.h).
//
// Linearised at the state, not at the guess the last acceleration makes: from the guess, one
// iteration per step threw a soft 3 m bar resting on rigid contacts off at thousands of m/s.
//
// The budget: with H = |v|^2/2 + E + S - f^T q at the step's loads, a fixed step may not end with
// more H than it began with, plus the slack earlier steps lost, less what damping dissipates. E at
// its end is known only once the next step evaluates there, so a step leaves the most E(q) its end
// may hold (qv_instance::elasticAllowance) and where it started, and the next step's start, which
// evaluates E(q) anyway, settles the account: a shortfall becomes slack; an excess is taken out as
// the minimiser's budget takes it (incremental_potential.h, holdToBudget()), from the velocity, or,
// where the position alone holds more, by drawing the state back toward the last step's start.
// So the check costs no evaluation but where it draws back; the price is one step of lag: the state
// a step hands out may hold more than its budget until the next step starts. Where one iteration
// overshoots so far that the position alone holds more, it tends to again, so after such a draw-back
// the next 60 steps evaluate E at their ends and hold them to the budget at once (holdToBudget()
// from the step's start), at one more evaluation each; an excess the velocity covers (common under
// sudden pushes: 13-30% of the energy under the runtime bench's load) arms none, for at 60 steps
// each it had nearly doubled that bench's step. (An undamped sliver beam released from a 180-degree
// twist at one iteration: 6-7 of 480 steps ended above its energy at the release, the highest at
// 8.2 times it; in runtime 0.11, 84% did, at a median of 33 times it, and it ran away.)
#include "integrator.h"

namespace quiver::rt {

// Evaluates at the state q (R + S into s.work.force, K into s.work.stiffness, E into
// s.elasticEnergyAtState), settles the account the last step left and returns J, with this step's
// budget in `budget`. Every fixed step begins here, before it can go to the minimiser.
const double* beginFixedNewton(qv_instance& s, double& budget);

// QV_SOLVER_NEWTON's way out, for both implicit integrators: a fixed Newton step whose system
// large compression made indefinite, or whose end would move a vertex past max_displacement or is
// not finite, is taken from the same start (after beginFixedNewton()) by the integrator's
// minimising step instead of being solved by pivoting LU or reset to rest; its budget starts from
// the settled account, and the next fixed step's account from where it ends. `stiffnessAtState`:
// s.work.stiffness still holds K(q) (no iteration evaluated elsewhere), which its damping takes.
qv_step_status minimizedInstead(qv_instance& s, StepFunction minimizing, bool stiffnessAtState);

// The end of a fixed Newton step (s.end) with its budget: past max_displacement or not finite, the
// minimiser's step instead; else taken, leaving the account for the next step.
qv_step_status endFixedNewton(qv_instance& s, double budget, StepFunction minimizing);

} // namespace quiver::rt
