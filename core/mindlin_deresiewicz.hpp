// Stateless kernel of the Mindlin–Deresiewicz tangential contact law with micro-slip
// (numerics.tangential_model = "mindlin_deresiewicz"; the default is the no-slip law in contact_kernels.hpp).
//
// Physics (Mindlin & Deresiewicz 1953, J. Appl. Mech. 20:327; Johnson 1985, Contact Mechanics §7.4): under a
// Hertz contact of radius a and normal force N, a tangential force T < mu N is carried by a central stick
// disc of radius c = a theta and a slipping annulus. At constant N, monotonic loading follows
//     T(delta) = mu N [1 - (1 - delta/delta_s)^(3/2)],   delta_s = 3 mu N / (16 G* a),
// with tangent stiffness dT/d delta = 8 G* a theta, theta^3 = 1 - T/(mu N); unloading and reloading follow
// Masing's rule (each branch is the loading curve doubled, starting from the reversal point).
//
// Incremental form (Thornton 1991, J. Phys. D 24:1942; Thornton & Yin 1991, Powder Technol. 65:153; restated in
// Thornton, Cummins & Cleary 2011, Powder Technol. 210:189, sec. 2.3, and 2013, Powder Technol. 233:267):
//     dT = 8 G* a theta d delta  +  (-1)^k mu dN (1 - theta),       k = 0 loading, 1 unloading, 2 reloading
//     loading     theta^3 = 1 - (T + mu dN) / (mu N)
//     unloading   theta^3 = 1 - (T* - T + 2 mu dN) / (2 mu N)
//     reloading   theta^3 = 1 - (T - T** + 2 mu dN) / (2 mu N)
//     theta = 1 while |dT| < mu dN (normal force growing faster than mu times the tangential one: no slip)
//     the reversal points follow the normal force: T* <- T* + mu dN, T** <- T** - mu dN
//     loading -> unloading at a reversal (T* = T), unloading -> reloading (T** = T), reloading -> unloading
//     (T* = T, one level of memory as in Thornton 1991); a branch that reaches its bound rejoins loading
//     (unloading at T = -T*, reloading at T = T*); gross sliding (|T| reaches mu N) wipes the memory.
// N is the current normal force, dN its change over the step, theta is clamped to [0, 1].
// Two changes to the rules as literally stated, both for the small-force limit and both vanishing where the
// literal rules are meant to act (documented in docs/contact-laws.md, found with the oblique-impact test):
//  (a) the (1 - theta) that multiplies mu dN is taken from the branch state before the normal change (the
//      theta^3 formula without its mu dN shift). With the shift, a falling N whose step mu |dN| exceeds the
//      branch distance clamps theta to 1 and drops the term; the result then depended on dt (tangential
//      restitution 0.695 vs 0.678 for dt and dt/4 at the smallest impact angle; 0.673 for both with (a)).
//      The two forms agree as dN -> 0 per step.
//  (b) the reversal points move by mu dN (1 - theta_r), theta_r^3 = 1 - |T_r|/(mu N), instead of mu dN:
//      Thornton's shift for a reversal at gross sliding (theta_r = 0), none for a reversal at a small
//      force, whose memory holds no slip annulus. Unshifted by (1 - theta_r), a few reversals during an impact
//      at a small angle moved T* by a sizeable part of mu N and produced micro-slip (and a tangential
//      restitution that fell towards 0 as the angle fell) at tangential forces far below mu N.
//
// 3D treatment (the choice and its limits). Stored vectors (F_t, T*, T**, the last increment direction u)
// are rotated into the current tangent plane each step, keeping their magnitudes, as the no-slip kernel does.
// The one-dimensional law is applied along the direction e of this step's tangential displacement increment
// ds = -v_t dt (force-direction convention: dF ~ +k ds): the scalars are the projections T = F_t.e,
// T* . e, T** . e, and the whole increment dF = [8 G* a theta |ds| + mu dN (1 - theta)] e is along e (written
// in e's frame the three branches have the same sign of the mu dN term). A reversal is an increment with
// e . u < 0 (turning by more than 90 degrees); a smaller turn continues the branch. This is exact for any
// path along one line (the closed forms of the tests), and it is the usual practice of applying the scalar
// law along the current increment (Thornton & Yin 1991; Vu-Quoc & Zhang 1999, Proc. R. Soc. A 455:4013).
// Limits: for curved tangential paths the stick-slip field of a 3D micro-slip solution is not represented
// (the force component across e keeps no memory of its own); the memory has one level (nested partial loops
// are not closed as Masing's extended rules would); the normal-force rules are Thornton's approximations.
//
// Energy (ledger). The stored tangential energy is |F_t|^2 / (2 k0) with k0 = 8 G* a (the least elastic
// energy that carries F_t, and the no-slip law's stored energy) plus L, the micro-slip energy locked in the
// contact (residual tractions of the slipped annulus), kept per contact. Each step the work done on the
// contact W = (F_prev + F_new)/2 . ds (the force the particles felt last step and this step: exactly the
// velocity-Verlet work) and X = E_old + W - |F_new|^2/(2 k0) are computed. X >= 0 (loading) is banked into
// L up to the locked energy of the Iwan (parallel spring-slider) form of the loading curve,
//     L_max = (mu N)^2 / (10 k0) [1 - 5 theta^3 + 9 theta^5 - 5 theta^6],  theta^3 = 1 - |F_t|/(mu N),
// and the rest is dissipated; X < 0 (unloading gives back locked energy) is taken from L. If L cannot cover
// it (Thornton's normal-force rules are approximations and can ask for energy the contact does not hold,
// and k0 falls when the normal load falls), the force is moved towards the one that maximises X just far
// enough that X = -L: the law does not create energy and the dissipation it reports is never negative.
// The one case no force can cover (k0 fell and one step reversed the displacement by about twice the
// spring's stretch) leaves a deficit of second order in the step, reported as createdEnergy. Over a closed
// cycle at constant N the dissipation equals the loop area (Johnson 1985 eq. 7.60, written with 1/G*);
// within a cycle the split between "locked" and "dissipated" is a bookkeeping choice. The caller adds L to
// the dissipation when the contact opens.
//
// Cost: up to five cube roots, about six square roots and roughly a hundred flops more than the no-slip
// kernel (a 50-step bisection in the rare steps where the energy guard acts), plus 96 bytes of history per
// pair (MdHistory) — paid only when this law is selected.
#pragma once

#include <algorithm>
#include <cmath>

#include "contact_store.hpp"
#include "types.hpp"

namespace fl::kernels {

struct MdResult {
  Vec3 force = Vec3::Zero();     // F_t on j [N]
  double work = 0.0;             // W = (F_prev + F_t)/2 . ds, work done on the contact this step [J]
  double slipWork = 0.0;         // dissipated in a step at gross sliding [J], >= 0
  double microSlipWork = 0.0;    // dissipated in a step below gross sliding (micro-slip, normal change) [J], >= 0
  double storedEnergy = 0.0;     // |F_t|^2/(2 k0) + locked micro-slip energy [J]
  double stiffness = 0.0;        // k0 = 8 G* a, the largest tangent stiffness (time step, damping) [N/m]
  double tangentStiffness = 0.0; // 8 G* a theta used this step [N/m]
  double theta = 1.0;            // stick-radius ratio c/a used this step [-]
  bool sliding = false;          // gross sliding: |F_t| = mu N
  bool guarded = false;          // the energy guard moved the force (see the header)
  double createdEnergy = 0.0;    // energy the step could not avoid creating (round-off, or see the guard) [J]
};

// Slip displacement of monotonic loading at constant N: delta_s = 3 mu N / (16 G* a) [m].
inline double mdSlipDisplacement(double effShear, double contactRadius, double friction, double normalForce) {
  return 3.0 * friction * normalForce / (16.0 * effShear * contactRadius);
}

// Locked micro-slip energy of the loading curve at force |F_t| (Iwan form, see the header) [J].
// muN = mu N [N], k0 = 8 G* a [N/m]. Zero at F = 0, (mu N)^2/(10 k0) at gross sliding.
inline double mdLockedCapacity(double force, double muN, double k0) {
  if (!(muN > 0.0) || !(k0 > 0.0)) return 0.0;
  const double t3 = 1.0 - std::min(force / muN, 1.0);
  const double t = std::cbrt(t3);
  const double t5 = t3 * t * t, t6 = t3 * t3;
  return std::max(0.0, muN * muN / (10.0 * k0) * (1.0 - 5.0 * t3 + 9.0 * t5 - 5.0 * t6));
}

namespace md_detail {
// Projects v onto the plane normal to n keeping its length (the rotation of the no-slip kernel).
inline void rotateIntoPlane(Vec3& v, const Vec3& n) {
  const double old2 = v.squaredNorm();
  if (old2 == 0.0) return;
  v -= v.dot(n) * n;
  const double new2 = v.squaredNorm();
  if (new2 > 0.0) v *= std::sqrt(old2 / new2);
}
// 1 - theta for a force t on the loading curve: theta^3 = 1 - t/(mu N) (the relative width of the slip annulus)
inline double annulusFraction(double t, double muN) { return 1.0 - std::cbrt(std::max(0.0, 1.0 - t / muN)); }
inline void capTo(Vec3& v, double cap) {
  const double v2 = v.squaredNorm();
  if (v2 > cap * cap) v *= cap / std::sqrt(v2);
}
}  // namespace md_detail

// One step of the law. n: unit normal (i to j); vt: tangential velocity of j's contact point relative to i's
// [m/s]; contactRadius a [m]; normalForce N >= 0 [N] (the value the Coulomb cap uses); effShear G* [Pa];
// friction mu [-]; dt [s]. h and md are updated in place.
inline MdResult mindlinDeresiewicz(const Vec3& n, const Vec3& vt, double contactRadius, double normalForce,
                                   double effShear, double friction, double dt, ContactHistory& h,
                                   MdHistory& md) {
  using md_detail::annulusFraction;
  using md_detail::capTo;
  using md_detail::rotateIntoPlane;
  MdResult r;
  const double k = 8.0 * effShear * contactRadius;  // k0 = 8 G* a (Mindlin 1949)
  const double kOld = 8.0 * effShear * h.contactRadius;
  r.stiffness = k;
  // 1. rotate the stored vectors into the current tangent plane (magnitudes kept)
  Vec3 F1 = h.tangentialForce;
  rotateIntoPlane(F1, n);
  rotateIntoPlane(md.turnLoad, n);
  rotateIntoPlane(md.turnUnload, n);
  Vec3 u = md.direction;
  u -= u.dot(n) * n;
  const double uNorm = u.norm();
  u = uNorm > 0.0 ? Vec3(u / uNorm) : Vec3::Zero();
  const double eOld = kOld > 0.0 ? F1.squaredNorm() / (2.0 * kOld) : 0.0;  // |F|^2/(2 k0) of the last step
  const double L0 = md.locked;
  const double muN = friction * normalForce;
  const double muDN = friction * (normalForce - md.prevNormalForce);
  const Vec3 ds = -dt * vt;  // tangential displacement increment, force-direction convention [m]
  const double dsNorm = ds.norm();

  if (!(muN > 0.0) || !(k > 0.0)) {
    // no friction capacity (mu = 0 or N = 0): F_t drops to zero, the spring and the locked energy are released
    const double W = 0.5 * F1.dot(ds);
    const double X = eOld + W + L0;
    r.work = W;
    r.slipWork = std::max(0.0, X);
    r.createdEnergy = std::max(0.0, -X);
    r.sliding = F1.squaredNorm() > 0.0 || dsNorm > 0.0;
    r.theta = 0.0;
    h.tangentialForce = Vec3::Zero();
    h.contactRadius = contactRadius;
    md = MdHistory{};
    md.direction = dsNorm > 0.0 ? Vec3(ds / dsNorm) : u;
    md.prevNormalForce = normalForce;
    return r;
  }

  // 2. direction of this increment, reversals (Thornton's branch changes)
  Vec3 e = u;
  if (dsNorm > 0.0) {
    e = ds / dsNorm;
    if (e.dot(u) < 0.0) {
      switch (md.branch) {
        case MdBranch::Loading: md.turnLoad = F1; md.branch = MdBranch::Unloading; break;
        case MdBranch::Unloading: md.turnUnload = F1; md.branch = MdBranch::Reloading; break;
        case MdBranch::Reloading: md.turnLoad = F1; md.branch = MdBranch::Unloading; break;
      }
    }
  }
  const double te = F1.dot(e);
  const double tLoad = md.turnLoad.dot(e), tUnload = md.turnUnload.dot(e);
  // a branch that reaches its bound rejoins the loading curve (continuous in theta when T** = -T*)
  if (md.branch == MdBranch::Unloading && te + tLoad >= 0.0) md.branch = MdBranch::Loading;
  else if (md.branch == MdBranch::Reloading && te >= tLoad) md.branch = MdBranch::Loading;

  // 3. theta (Thornton's three branches, in e's frame) and the increment
  double num, den;
  switch (md.branch) {
    case MdBranch::Loading: num = te + muDN; den = muN; break;
    case MdBranch::Unloading: num = (te - tLoad) + 2.0 * muDN; den = 2.0 * muN; break;
    default: num = (te - tUnload) + 2.0 * muDN; den = 2.0 * muN; break;
  }
  const double theta3 = std::clamp(1.0 - num / den, 0.0, 1.0);
  double theta = std::cbrt(theta3);
  // (1 - theta) of the normal-force term from the branch state before the normal change (change (a) in the
  // header): with Thornton's mu dN shift, a falling N whose step mu |dN| exceeds the branch distance (small T)
  // clamps theta to 1 and loses the term, whereas the continuous law gives dT = mu dN (1 - theta) ~ T dN/(3 N)
  // on loading (the no-slip law's unloading scaling, T ~ a). The two agree as dN -> 0.
  const double shift = (md.branch == MdBranch::Loading ? 1.0 : 2.0) * muDN;
  double thetaN = std::cbrt(std::clamp(1.0 - (num - shift) / den, 0.0, 1.0));
  if (muDN > 0.0 && k * dsNorm < muDN) theta = thetaN = 1.0;  // |dT| < mu dN: no slip (Mindlin & Deresiewicz)
  Vec3 Ft = F1 + (k * theta * dsNorm + muDN * (1.0 - thetaN)) * e;
  bool capped = false;
  {
    const double f2 = Ft.squaredNorm();
    if (f2 > muN * muN) {
      Ft *= muN / std::sqrt(f2);
      capped = true;
    }
  }
  const bool fullSlip = capped || (theta3 <= 0.0 && theta < 1.0);

  // 4. energy: X = E_old + W - |F|^2/(2 k0) must not fall below -L (see the header). W uses the force the
  // particles felt last step (F1), so the ledger is the integrator's work exactly.
  const double halfInvK = 0.5 / k;
  auto excess = [&](const Vec3& fin) { return eOld + 0.5 * (F1 + fin).dot(ds) - fin.squaredNorm() * halfInvK; };
  Vec3 Fnew = Ft;
  double X = excess(Fnew);
  const double roundOff =
      1e-12 * (eOld + L0 + Fnew.squaredNorm() * halfInvK + std::abs(0.5 * (F1 + Fnew).dot(ds)));
  if (X < -L0 - roundOff) {
    // X(F) = C - |F - k ds/2|^2 / (2 k): concave, largest on the friction disk at Fbest = k ds/2 capped at mu N.
    // Along the segment F_MD -> Fbest X does not decrease, so bisection finds the force nearest to the MD
    // one with X >= -L. If even Fbest cannot (the stiffness fell with the normal load and the step reversed
    // by about twice the spring's stretch), Fbest is taken and the deficit, second order in the step, is
    // reported as createdEnergy.
    Vec3 Fbest = 0.5 * k * ds;
    capTo(Fbest, muN);
    if (excess(Fbest) < -L0) {
      Fnew = Fbest;
    } else {
      const Vec3 dF = Fbest - Ft;
      double lo = 0.0, hi = 1.0;  // X(lo) < -L <= X(hi)
      for (int it = 0; it < 50; ++it) {
        const double mid = 0.5 * (lo + hi);
        if (excess(Ft + mid * dF) >= -L0) hi = mid;
        else lo = mid;
      }
      Fnew = Ft + hi * dF;
    }
    X = excess(Fnew);
    r.guarded = true;
  }
  const double W = 0.5 * (F1 + Fnew).dot(ds);
  const double fNew = Fnew.norm();
  double L = L0, D = 0.0;
  if (X >= 0.0) {
    const double deposit = std::clamp(mdLockedCapacity(fNew, muN, k) - L0, 0.0, X);
    L = L0 + deposit;
    D = X - deposit;
  } else {
    L = L0 + X;
    if (L < 0.0) {
      r.createdEnergy = -L;
      L = 0.0;
    }
  }
  const bool sliding = fullSlip || fNew >= muN;

  // 5. reversal points follow the normal force (Thornton 1991: T* += mu dN, T** -= mu dN), written in e's
  // frame and scaled by the slip-annulus fraction 1 - theta_r, theta_r^3 = 1 - |T_r|/(mu N), of the memory
  // they stand for (change (b) in the header).
  if (md.branch == MdBranch::Unloading) {
    md.turnLoad -= muDN * annulusFraction(md.turnLoad.norm(), muN) * e;
  } else if (md.branch == MdBranch::Reloading) {
    md.turnUnload -= muDN * annulusFraction(md.turnUnload.norm(), muN) * e;
    md.turnLoad += muDN * annulusFraction(md.turnLoad.norm(), muN) * e;
  }
  if (sliding) md.branch = MdBranch::Loading;  // gross sliding wipes the memory

  h.tangentialForce = Fnew;
  h.contactRadius = contactRadius;
  md.direction = e;
  md.prevNormalForce = normalForce;
  md.locked = L;
  r.force = Fnew;
  r.work = W;
  (sliding ? r.slipWork : r.microSlipWork) = D;
  r.storedEnergy = Fnew.squaredNorm() * halfInvK + L;
  r.tangentStiffness = k * theta;
  r.theta = theta;
  r.sliding = sliding;
  return r;
}

}  // namespace fl::kernels
