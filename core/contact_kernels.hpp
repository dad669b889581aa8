// Stateless force kernels of the Hertz–Mindlin contact law (Cundall & Strack 1979 explicit DEM; the
// paper's "Hertz–Mindlin (Mindlin and Deresiewicz, 1953)"). Pure functions: geometry and immutable pair
// parameters in, history passed explicitly, so the OpenMP contact loop is re-entrant and every kernel is
// unit-testable alone. Sign convention: forces act on particle j; n points from i to j; a positive
// overlap delta means contact; F_n > 0 is repulsive.
#pragma once

#include <cmath>

#include "contact_store.hpp"
#include "material.hpp"
#include "types.hpp"

namespace fl::kernels {

// sqrt(5/6) * 2, the factor of the Tsuji et al. (1992) viscoelastic damping for Hertz contacts.
constexpr double kTsujiFactor = 1.8257418583505538;

// Hertz normal force (Johnson 1985, eq. 4.23): F_n = (4/3) E* sqrt(R*) delta^(3/2), written as
// (4/3) E* a delta with the contact radius a = sqrt(R* delta).
inline double hertzForce(double effYoung, double contactRadius, double overlap) {
  return (4.0 / 3.0) * effYoung * contactRadius * overlap;
}
// Tangent normal stiffness dF_n/d delta = 2 E* a [N/m].
inline double hertzStiffness(double effYoung, double contactRadius) { return 2.0 * effYoung * contactRadius; }
// Elastic energy stored in a Hertz contact: (8/15) E* sqrt(R*) delta^(5/2) = (2/5) F_n delta [J].
inline double hertzEnergy(double elasticForce, double overlap) { return 0.4 * elasticForce * overlap; }

// Viscous damping coefficient for a spring of tangent stiffness k between reduced mass m*:
// c = 2 sqrt(5/6) beta sqrt(k m*) (Tsuji et al. 1992; beta from the restitution coefficient).
inline double dampingCoefficient(double dampingRatio, double stiffness, double reducedMass) {
  return kTsujiFactor * dampingRatio * std::sqrt(stiffness * reducedMass);
}

// Mindlin (1949) no-slip tangential stiffness k_t = 8 G* a [N/m].
inline double mindlinStiffness(double effShear, double contactRadius) { return 8.0 * effShear * contactRadius; }

struct TangentialResult {
  Vec3 force;              // F_t on j [N]
  double slipWork = 0.0;   // energy dissipated by Coulomb sliding this step [J]
  double stiffnessWork = 0.0;  // spring energy removed by the stiffness update (steps 1-2) [J], >= 0
  double stiffness = 0.0;  // k_t used [N/m]
  double compliance = 0.0;  // 1/k_t [m/N] (0 when k_t = 0), so callers need no further division
  bool sliding = false;
};

// Incremental Mindlin no-slip spring with Coulomb cap (Thornton, Cummins & Cleary 2011, sec. 2.2):
//  1. the stored force is rotated into the current tangent plane (projected, magnitude kept);
//  2. when the contact unloads (a < a_prev) it is scaled by k_t/k_t,prev = a/a_prev, so that no energy is
//     created by the falling stiffness;
//  3. dF_t = -k_t v_t dt;
//  4. if |F_t| > mu F_n the spring is rewritten to mu F_n along F_t (gross sliding); the work of sliding is
//     F_cap · (F_trial - F_cap)/k_t.
// Energy: the spring stores |F_t|^2 / (2 k_t). Steps 1-2 change that at no displacement (k_t follows the
// normal load); the change is reported as stiffnessWork and is never negative, so the law cannot create
// energy: on unloading it is the micro-slip loss of Mindlin–Deresiewicz, on loading the stiffening spring.
// With r = a/a_prev and F0 the stored force: |F0|^2/(2 k_t,prev) - |F1|^2/(2 k_t) = (r |F0|^2 - |F1|^2)/(2 k_t),
// where |F1|^2 = r^2 |F0|^2 on unloading (>= 0 as 0 < r < 1) and |F0|^2 on loading (>= 0 as r >= 1).
// History is updated in place. v_t is the tangential velocity of j's contact point relative to i's.
// Cost: one division and one square root for the rotation, one division for a/a_prev, one for 1/k_t
// (the energy terms only; dropped by the compiler when the caller ignores them).
// The engine runs this law vectorised across pairs (kernels::hertzMindlinBlock, contact_block.hpp); this
// scalar form is its reference: the closed-form tests (contact_law_test.cpp) check it, and
// contact_block_test.cpp checks the block law against it pair by pair.
inline TangentialResult mindlinNoSlip(const Vec3& n, const Vec3& vt, double contactRadius, double normalForce,
                                      double effShear, double friction, double dt, ContactHistory& h) {
  TangentialResult r;
  const double kt = mindlinStiffness(effShear, contactRadius);
  const double compliance = kt > 0.0 ? 1.0 / kt : 0.0;
  Vec3 ft = h.tangentialForce;
  const double old2 = ft.squaredNorm();
  if (old2 > 0.0) {
    ft -= ft.dot(n) * n;
    const double new2 = ft.squaredNorm();
    if (new2 > 0.0) ft *= std::sqrt(old2 / new2);
    if (h.contactRadius > 0.0) {
      const double ratio = contactRadius / h.contactRadius;  // k_t / k_t,prev
      double kept2 = old2;                                    // |F_t|^2 after steps 1-2
      if (ratio < 1.0) {
        ft *= ratio;
        kept2 = old2 * ratio * ratio;
      }
      r.stiffnessWork = (ratio * old2 - kept2) * (0.5 * compliance);
    }
  }
  ft -= kt * dt * vt;
  const double cap = friction * normalForce;
  const double f2 = ft.squaredNorm();
  if (f2 > cap * cap) {
    const double fmag = std::sqrt(f2);
    const Vec3 capped = (cap / fmag) * ft;
    r.slipWork = cap * (fmag - cap) * compliance;
    ft = capped;
    r.sliding = true;
  }
  h.tangentialForce = ft;
  h.contactRadius = contactRadius;
  r.force = ft;
  r.stiffness = kt;
  r.compliance = compliance;
  return r;
}

}  // namespace fl::kernels
