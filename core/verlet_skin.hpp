// The automatic Verlet skin (numerics.skin = 0; issue 6: "a skin tuned to rebuild rarely").
// A list with skin s holds every pair within s of contact. It is rebuilt when the displacement bound of
// Simulation::displacementBound, u(n) = 2 max|Δx| + ||F - I|| l_cut after n steps, exceeds s. The per-step cost of a
// skin is the list's pairs that do not touch: each is read, tested and gathered every step (~7 ns a pair on the
// dense 4000-sphere benchmark, ~10 % of a particle-step), and their number grows about linearly with s. A
// rebuild costs R steps (R ≈ 10 on that benchmark, 1 thread) once every s / ů steps, ů = u(n)/n the rate at
// which the bound grows. Cost per step, in steps: R ů / s + c g s, with g the non-touching pairs per particle
// per mean diameter d of skin (~20–36 in dense packings) and c their cost in particle-steps (~0.1); the
// minimum is at s* = sqrt(κ d ů), κ = R / (c g d) ≈ 3–5 steps. The cost ratio depends weakly on the machine
// and the packing; the optimum is flat (a factor 2 in s costs ~25 % more overhead than s*).
// Measured on the dense 4000-sphere benchmark (docs/performance.md, twenty-first session): the fixed skin of
// 0.1 d left 5689 listed pairs that do not touch beside 11 722 contacts; a skin of 0.005 d, 881.
// The rule is deterministic: it reads step counts and the displacement bound (a maximum: the same for any
// thread count), never timings, so the list and the results do not depend on the machine's speed.
#pragma once

#include <algorithm>
#include <cmath>

namespace fl::verlet_skin {

constexpr double kMinFraction = 0.002;  // of the mean diameter: the smallest automatic skin
constexpr double kMaxFraction = 0.1;    // the largest, and the first list's (the fixed default before issue 6's
                                        // twenty-first session: never a larger cut-off, so never a new
                                        // CellTooSmallError)
constexpr double kCostRatio = 4.0;      // κ [steps], see above
constexpr long kFirstCheck = 64;        // steps after a rebuild when a list may first be found too wide

// The skin that minimises the cost per step for a bound that grew by `used` [m] in `steps` steps; clamped to
// [kMinFraction, kMaxFraction] x meanDiameter. Without a step, the widest.
inline double optimal(double used, long steps, double meanDiameter) {
  const double lo = kMinFraction * meanDiameter, hi = kMaxFraction * meanDiameter;
  if (steps <= 0) return hi;
  const double rate = std::max(0.0, used) / static_cast<double>(steps);  // ů [m per step]
  return std::clamp(std::sqrt(kCostRatio * meanDiameter * rate), lo, hi);
}

// A list that has lived `steps` steps is checked for being too wide at 64, 128, 256, ... steps: a few times per
// list, so the check costs nothing; early enough that a run of a few hundred steps (a benchmark at a million
// spheres) runs on the narrow list; and a list built for a fast phase (a specimen's compression) does not outlive
// it by much. An estimate from few steps overrates the rate (a vibration's amplitude is reached at once), which
// errs toward the wider skin; later checks narrow it further.
inline bool isCheckStep(long steps) { return steps >= kFirstCheck && (steps & (steps - 1)) == 0; }

// Whether a list of skin `skin` should be rebuilt narrower now: its optimum is less than half of it (a
// rebuild costs ~10 steps; below a factor 2 the saving would not repay it soon).
inline bool tooWide(double skin, double used, long steps, double meanDiameter) {
  return isCheckStep(steps) && optimal(used, steps, meanDiameter) < 0.5 * skin;
}

}  // namespace fl::verlet_skin
