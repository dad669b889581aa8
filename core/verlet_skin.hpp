// The automatic Verlet skin (numerics.skin = 0; issue 6: "a skin tuned to rebuild rarely").
// A list with skin s holds every pair within s of contact. It is rebuilt when the displacement bound of
// Simulation::displacementBound, u(n) = 2 max|Δx| + ||F - I|| l_cut after n steps, exceeds s. Two costs pull s
// apart:
//   - the listed pairs that do not touch: each is read, tested and gathered every step (~7 ns a pair on the
//     dense 4000-sphere benchmark, ~10 % of a particle-step); there are g s of them per particle, g [1/m] the
//     density of gaps below s (a dense packing's near-contact peak: g ≈ 36 per mean diameter d at s = 0.01 d,
//     a loose gas's ≈ 24 φ/d, ten times fewer);
//   - the rebuilds: one costs as much per particle as ρ such pairs for one step (ρ ≈ 100 measured on the dense
//     benchmark, 0.75 µs a particle against 7.3 ns a pair; 150 here for what follows a rebuild: fresh arrays,
//     cold caches, the threads' shares made again), once every s / ů steps, ů = u(n)/n. Since the fortieth
//     session a rebuild reuses its arrays and costs ~0.33 µs a particle (ρ ≈ 45 before what follows it); ρ is
//     kept at 150 until a smaller one is measured to pay: it would change every run's lists and results.
// Per step and particle, in pair-steps: ρ ů / s + g s; the minimum is at s* = sqrt(ρ ů / g). g is read off the
// list being replaced, (listed − touching pairs) / (particles s): the packing's own density of gaps, so a gas
// gets a wider skin than a dense packing moving as fast. The optimum is flat (a factor 2 in s costs 25 % more
// overhead than s*).
// Measured on the dense 4000-sphere benchmark (docs/performance.md, twenty-first session): the fixed skin of
// 0.1 d listed 5689 pairs that do not touch beside 11 722 contacts, the automatic one ~800.
// The rule is deterministic: it reads step counts, pair counts and the displacement bound (a maximum: the same
// for any thread count), never timings, so the list and the results do not depend on the machine's speed.
#pragma once

#include <algorithm>
#include <cmath>

namespace fl::verlet_skin {

constexpr double kMinFraction = 0.002;  // of the mean diameter: the smallest automatic skin
constexpr double kMaxFraction = 0.1;    // the largest, and the first list's (the fixed default before issue 6's
                                        // twenty-first session: never a larger cut-off, so never a new
                                        // CellTooSmallError)
constexpr double kRebuildCost = 150.0;  // ρ: a rebuild's cost per particle in listed-pair steps, see above
constexpr long kFirstCheck = 64;        // steps after a rebuild when a list may first be found too wide

// What the rule reads of the list being replaced.
struct ListStats {
  double skin = 0.0;        // its skin [m]
  long steps = 0;           // steps it lived
  double used = 0.0;        // the displacement bound after them [m]
  double gapPairs = 0.0;    // its listed pairs that did not touch at the last pass, per particle
};

// The skin that minimises the cost per step, clamped to [kMinFraction, kMaxFraction] x meanDiameter. Without a
// step, or without a pair that does not touch (nothing to save), the widest.
inline double optimal(const ListStats& list, double meanDiameter) {
  const double lo = kMinFraction * meanDiameter, hi = kMaxFraction * meanDiameter;
  if (list.steps <= 0 || !(list.gapPairs > 0.0) || !(list.skin > 0.0)) return hi;
  const double rate = std::max(0.0, list.used) / static_cast<double>(list.steps);  // ů [m per step]
  const double density = list.gapPairs / list.skin;                                // g [1/m]
  return std::clamp(std::sqrt(kRebuildCost * rate / density), lo, hi);
}

// A list that has lived `steps` steps is checked for being too wide at 64, 128, 256, ... steps: a few times per
// list, so the check costs nothing; early enough that a run of a few hundred steps (a benchmark at a million
// spheres) runs on the narrow list; and a list built for a fast phase (a specimen's compression) does not outlive
// it by much. An estimate from few steps overrates the rate (a vibration's amplitude is reached at once), which
// errs toward the wider skin; later checks narrow it further.
inline bool isCheckStep(long steps) { return steps >= kFirstCheck && (steps & (steps - 1)) == 0; }

// Whether the list should be rebuilt narrower now: its optimum is less than half its skin (a rebuild costs
// about ρ pair-steps a particle; below a factor 2 the saving would not repay it soon).
inline bool tooWide(const ListStats& list, double meanDiameter) {
  return isCheckStep(list.steps) && optimal(list, meanDiameter) < 0.5 * list.skin;
}

}  // namespace fl::verlet_skin
