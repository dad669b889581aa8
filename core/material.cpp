#include "material.hpp"

#include <algorithm>
#include <cmath>

#include "errors.hpp"
#include "types.hpp"

namespace fl {

namespace {
// Restitution of a Hertz contact with Tsuji damping of ratio beta. Scaled by the impact speed the motion
// obeys x'' = -x^(3/2) - sqrt(5) beta x^(1/4) x' (force clamped >= 0), x(0) = 0, x'(0) = 1, whatever the
// material and speed; e = -x'(t_end). Integrated with RK4.
double hertzTsujiRestitution(double beta) {
  auto acc = [beta](double x, double v) {
    const double xp = x > 0.0 ? x : 0.0;
    return std::min(0.0, -xp * std::sqrt(xp) - std::sqrt(5.0) * beta * std::sqrt(std::sqrt(xp)) * v);
  };
  double x = 0.0, v = 1.0;
  const double h = 2e-4;
  for (int k = 0; k < 200000; ++k) {
    const double k1x = v, k1v = acc(x, v);
    const double k2x = v + 0.5 * h * k1v, k2v = acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
    const double k3x = v + 0.5 * h * k2v, k3v = acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
    const double k4x = v + h * k3v, k4v = acc(x + h * k3x, v + h * k3v);
    x += h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
    v += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    if (x <= 0.0 && k > 0) break;
  }
  return -v;
}
}  // namespace

double dampingRatioFromRestitution(double e) {
  if (!(e >= kMinRestitution && e <= 1.0))
    throw InputError("restitution must be in [0.01, 1], got " + std::to_string(e));
  static_assert(kMinRestitution == 0.01, "the message names the bound");
  if (e == 1.0) return 0.0;
  // The linear-spring formula beta = -ln e / sqrt(ln^2 e + pi^2) is only approximate for Hertz contacts
  // (e = 0.5 would come out near 0.55), so beta is found by bisection on the exact Hertz-Tsuji restitution.
  double lo = 0.0, hi = 1.0;
  while (hertzTsujiRestitution(hi) > e) hi *= 2.0;
  for (int it = 0; it < 50; ++it) {
    const double mid = 0.5 * (lo + hi);
    (hertzTsujiRestitution(mid) > e ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

PairTable::PairTable(const std::vector<Material>& materials, double restitution)
    : m_count(static_cast<int>(materials.size())), m_params(materials.size() * materials.size()) {
  const double beta = dampingRatioFromRestitution(restitution);
  for (int a = 0; a < m_count; ++a) {
    for (int b = 0; b < m_count; ++b) {
      const Material& A = materials[a];
      const Material& B = materials[b];
      PairParams& p = m_params[a * m_count + b];
      p.effYoung = 1.0 / ((1.0 - A.poissonRatio * A.poissonRatio) / A.youngModulus +
                          (1.0 - B.poissonRatio * B.poissonRatio) / B.youngModulus);
      p.effShear = 1.0 / ((2.0 - A.poissonRatio) / A.shearModulus() + (2.0 - B.poissonRatio) / B.shearModulus());
      p.friction = std::min(A.friction, B.friction);
      p.dampingRatio = beta;
    }
  }
}

void PairTable::setFriction(double mu) {
  for (auto& p : m_params) p.friction = mu;
}

void PairTable::setRestitution(double e) {
  const double beta = dampingRatioFromRestitution(e);
  for (auto& p : m_params) p.dampingRatio = beta;
}

}  // namespace fl
