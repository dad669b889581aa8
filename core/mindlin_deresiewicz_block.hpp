// The Mindlin–Deresiewicz tangential law (mindlin_deresiewicz.hpp: the law, its references and its energy
// ledger) over a block of touching pairs held as structure of arrays, written without branches so that the
// compiler vectorises it across pairs (issue 6: the scalar law took 94 % of a Mindlin–Deresiewicz run, a
// third of it in libm's cube root, and set the paper study's wall time).
// Same law, same steps as kernels::mindlinDeresiewicz, every `if` a select on safe operands, and its cube roots
// taken by cbrtUnit (below), so it agrees with the scalar kernel to rounding; tests/mindlin_deresiewicz_block_test.cpp
// checks it pair by pair against it on random paths through every branch.
// Three rare cases are not handled here but flagged (MdBlock::scalar) for the caller to run through the scalar
// kernel from the unchanged history (mdScatter): no friction capacity (mu N = 0 or a = 0), a step where the
// energy guard acts (its bisection), and stored forces so small that a shared reciprocal would overflow. A
// flagged slot's history in the block is not meaningful.
// Stateless: inputs and history in, results and updated history out; the caller gathers and scatters.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "contact_block.hpp"
#include "contact_store.hpp"
#include "mindlin_deresiewicz.hpp"

namespace fl::kernels {

// Cube root of x >= 0 without a call, so that a loop over it vectorises. The law's arguments all lie in
// {0} ∪ [2^-53, 1] (1 - a ratio, clamped). A first guess of x^(-1/3) from the exponent bits (the integer
// division of the bit pattern by 3, as in Kahan's cube root, taken in double: AVX-512 has no 64-bit integer
// division), three Newton steps for the reciprocal cube root r <- r (4 - x r^3)/3 (quadratic: 3.4e-2 ->
// ~1e-3 -> ~1e-6 -> ~1e-12), y = x r^2 and one Newton step on y (r^2 standing for 1/y^2). Within 4 ulp of
// libm's cbrt on [2^-100, 1] (3 or 4 by how the compiler contracts into FMAs;
// tests/mindlin_deresiewicz_block_test.cpp); exact at 0 and 1, so a contact without micro-slip keeps the
// stiffness 8 G* a exactly. ~0.7 ns a value vectorised against ~13 ns for libm.
inline double cbrtUnit(double x) {
  const auto bits = std::bit_cast<std::int64_t>(x);
  double r = std::bit_cast<double>(std::int64_t{0x553EF00000000000} -
                                   static_cast<std::int64_t>(static_cast<double>(bits) * (1.0 / 3.0)));
  for (int k = 0; k < 3; ++k) r = r * (4.0 - x * (r * r * r)) * (1.0 / 3.0);
  double y = x * (r * r);
  y -= (y * y * y - x) * (r * r) * (1.0 / 3.0);
  return x > 0.0 ? (x == 1.0 ? 1.0 : y) : 0.0;
}

// Create it value-initialised (MdBlock b{}): the slots past count run through the law as padding, so they
// must hold determinate values (zeros, or an earlier block's pairs); their results are ignored.
struct alignas(64) MdBlock {
  int count = 0;  // touching pairs held, <= kBlockPairs
  // ---- inputs, gathered by the caller (the arguments of kernels::mindlinDeresiewicz)
  alignas(64) double nx[kBlockPairs], ny[kBlockPairs], nz[kBlockPairs];     // unit normal i -> j
  alignas(64) double vtx[kBlockPairs], vty[kBlockPairs], vtz[kBlockPairs];  // tangential velocity [m/s]
  alignas(64) double a[kBlockPairs];                                        // contact radius [m]
  alignas(64) double fn[kBlockPairs];                                       // N >= 0 [N]
  alignas(64) double effShear[kBlockPairs], friction[kBlockPairs];          // G* [Pa], mu [-]
  // ---- history: in and out (ContactHistory, MdHistory)
  alignas(64) double tx[kBlockPairs], ty[kBlockPairs], tz[kBlockPairs];     // F_t on j [N]
  alignas(64) double aPrev[kBlockPairs];                                    // a of the last step [m]
  alignas(64) double lx[kBlockPairs], ly[kBlockPairs], lz[kBlockPairs];     // T* (turnLoad) [N]
  alignas(64) double ux[kBlockPairs], uy[kBlockPairs], uz[kBlockPairs];     // T** (turnUnload) [N]
  alignas(64) double ex[kBlockPairs], ey[kBlockPairs], ez[kBlockPairs];     // last increment direction [-]
  alignas(64) double prevFn[kBlockPairs];                                   // N of the last step [N]
  alignas(64) double locked[kBlockPairs];                                   // locked energy L [J]
  alignas(64) double branch[kBlockPairs];  // MdBranch as 0 (loading), 1 (unloading), 2 (reloading)
  // ---- results
  alignas(64) double storedEnergy[kBlockPairs];  // |F_t|^2/(2 k0) + L [J]
  alignas(64) double dissipated[kBlockPairs];    // slip + micro-slip work of this step [J]
  alignas(64) double sliding[kBlockPairs];       // 1 at gross sliding, else 0
  alignas(64) double scalar[kBlockPairs];        // 1: run this pair through kernels::mindlinDeresiewicz
};

namespace md_block_detail {
// 1 - theta for a force t on the loading curve, theta^3 = 1 - t/(mu N) (md_detail::annulusFraction)
inline double annulusFraction(double t, double invMuN) { return 1.0 - cbrtUnit(std::max(0.0, 1.0 - t * invMuN)); }
}  // namespace md_block_detail

// One step of the law for b.count pairs (the padding: kSimdSlots). Every step as in kernels::mindlinDeresiewicz,
// numbered alike; see there for the physics and the two documented changes to Thornton's rules.
inline void mindlinDeresiewiczBlock(MdBlock& b, double dt) {
  using md_block_detail::annulusFraction;
  const int m = (b.count + kSimdSlots - 1) / kSimdSlots * kSimdSlots;
  // One loop: split in three like hertzMindlinBlock (steps 1-2, 3-4, 5, passing values through the block) it
  // was 10 % slower on the paper's isotropic run (docs/performance.md, thirty-second session).
#pragma omp simd
  for (int s = 0; s < m; ++s) {
    const double nx = b.nx[s], ny = b.ny[s], nz = b.nz[s];
    const double a = b.a[s], N = b.fn[s];
    const double k = mindlinStiffness(b.effShear[s], a);  // k0 = 8 G* a (Mindlin 1949)
    const double kOld = mindlinStiffness(b.effShear[s], b.aPrev[s]);
    // 1. the stored vectors rotated into the current tangent plane (magnitudes kept: md_detail::rotateIntoPlane).
    // The quotients share reciprocals, each factor that may be 0 replaced by 1 (and then unused).
    double f1x = b.tx[s], f1y = b.ty[s], f1z = b.tz[s];
    double lx = b.lx[s], ly = b.ly[s], lz = b.lz[s];
    double ux = b.ux[s], uy = b.uy[s], uz = b.uz[s];
    const double f1old = f1x * f1x + f1y * f1y + f1z * f1z;
    const double lold = lx * lx + ly * ly + lz * lz;
    const double uold = ux * ux + uy * uy + uz * uz;
    const double pf = f1x * nx + f1y * ny + f1z * nz, pl = lx * nx + ly * ny + lz * nz;
    const double pu = ux * nx + uy * ny + uz * nz;
    f1x -= pf * nx, f1y -= pf * ny, f1z -= pf * nz;
    lx -= pl * nx, ly -= pl * ny, lz -= pl * nz;
    ux -= pu * nx, uy -= pu * ny, uz -= pu * nz;
    const double f1new = f1x * f1x + f1y * f1y + f1z * f1z;
    const double lnew = lx * lx + ly * ly + lz * lz;
    const double unew = ux * ux + uy * uy + uz * uz;
    const double f1safe = f1new > 0.0 ? f1new : 1.0, lsafe = lnew > 0.0 ? lnew : 1.0;
    const double usafe = unew > 0.0 ? unew : 1.0;
    const double w = 1.0 / (f1safe * lsafe * usafe);
    const bool representable = w < 1e300;  // else (|F|^2 products below 1e-300 N^6) the scalar kernel
    const double f1scale = f1new > 0.0 ? std::sqrt(f1old * (lsafe * usafe * w)) : 1.0;
    const double lscale = lnew > 0.0 ? std::sqrt(lold * (f1safe * usafe * w)) : 1.0;
    const double uscale = unew > 0.0 ? std::sqrt(uold * (f1safe * lsafe * w)) : 1.0;
    f1x *= f1scale, f1y *= f1scale, f1z *= f1scale;
    lx *= lscale, ly *= lscale, lz *= lscale;
    ux *= uscale, uy *= uscale, uz *= uscale;
    const double du = b.ex[s] * nx + b.ey[s] * ny + b.ez[s] * nz;
    double dx = b.ex[s] - du * nx, dy = b.ey[s] - du * ny, dz = b.ez[s] - du * nz;
    const double dNorm = std::sqrt(dx * dx + dy * dy + dz * dz);
    const double dScale = dNorm > 0.0 ? 1.0 / (dNorm > 0.0 ? dNorm : 1.0) : 0.0;
    dx *= dScale, dy *= dScale, dz *= dScale;
    const double f1sq = f1x * f1x + f1y * f1y + f1z * f1z;
    const double kOldSafe = kOld > 0.0 ? kOld : 1.0, kSafe = k > 0.0 ? k : 1.0;
    const double kk = 0.5 / (kOldSafe * kSafe);
    const double eOld = kOld > 0.0 ? f1sq * (kSafe * kk) : 0.0;  // |F|^2/(2 k0,old)
    const double halfInvK = kOldSafe * kk;                        // 1/(2 k0)
    const double L0 = b.locked[s];
    const double muN = b.friction[s] * N;
    const double muDN = b.friction[s] * (N - b.prevFn[s]);
    const double dsx = -dt * b.vtx[s], dsy = -dt * b.vty[s], dsz = -dt * b.vtz[s];
    const double dsNorm = std::sqrt(dsx * dsx + dsy * dsy + dsz * dsz);
    // no friction capacity: the scalar kernel (its first case)
    const bool capacity = muN > 0.0 && k > 0.0;
    const double invMuN = 1.0 / (capacity ? muN : 1.0);

    // 2. direction of this increment, reversals (Thornton's branch changes)
    const bool moving = dsNorm > 0.0;
    const double invDs = 1.0 / (moving ? dsNorm : 1.0);
    const double ex = moving ? dsx * invDs : dx, ey = moving ? dsy * invDs : dy, ez = moving ? dsz * invDs : dz;
    double br = b.branch[s];
    const bool reversal = moving && ex * dx + ey * dy + ez * dz < 0.0;
    // loading -> unloading (T* = F), unloading -> reloading (T** = F), reloading -> unloading (T* = F)
    const bool toReloading = reversal && br == 1.0;
    const bool newTurnLoad = reversal && br != 1.0;
    ux = toReloading ? f1x : ux, uy = toReloading ? f1y : uy, uz = toReloading ? f1z : uz;
    lx = newTurnLoad ? f1x : lx, ly = newTurnLoad ? f1y : ly, lz = newTurnLoad ? f1z : lz;
    br = reversal ? (br == 1.0 ? 2.0 : 1.0) : br;
    const double te = f1x * ex + f1y * ey + f1z * ez;
    const double tLoad = lx * ex + ly * ey + lz * ez, tUnload = ux * ex + uy * ey + uz * ez;
    // a branch that reaches its bound rejoins the loading curve
    const bool rejoin = (br == 1.0 && te + tLoad >= 0.0) || (br == 2.0 && te >= tLoad);
    br = rejoin ? 0.0 : br;

    // 3. theta (Thornton's three branches, in e's frame) and the increment
    const bool loading = br == 0.0;
    const double num = loading ? te + muDN : (te - (br == 1.0 ? tLoad : tUnload)) + 2.0 * muDN;
    const double invDen = loading ? invMuN : 0.5 * invMuN;  // 1/(mu N) or 1/(2 mu N)
    const double theta3 = std::clamp(1.0 - num * invDen, 0.0, 1.0);
    const double shift = (loading ? 1.0 : 2.0) * muDN;
    const bool noSlip = muDN > 0.0 && k * dsNorm < muDN;  // |dT| < mu dN (Mindlin & Deresiewicz)
    const double theta = noSlip ? 1.0 : cbrtUnit(theta3);
    // (1 - theta) of the normal-force term without the mu dN shift (change (a) in the scalar kernel's header)
    const double thetaN = noSlip ? 1.0 : cbrtUnit(std::clamp(1.0 - (num - shift) * invDen, 0.0, 1.0));
    const double inc = k * theta * dsNorm + muDN * (1.0 - thetaN);
    double ftx = f1x + inc * ex, fty = f1y + inc * ey, ftz = f1z + inc * ez;
    const double f2 = ftx * ftx + fty * fty + ftz * ftz;
    const bool capped = f2 > muN * muN;
    const double fmag = std::sqrt(f2);
    const double capScale = capped ? muN / fmag : 1.0;  // a capped force has |F_t| > 0
    ftx *= capScale, fty *= capScale, ftz *= capScale;
    // gross sliding as a 0/1 double: g++ 12 does not vectorise the loop with this chain of bools
    const double fullSlip = capped ? 1.0 : (theta3 <= 0.0 ? (theta < 1.0 ? 1.0 : 0.0) : 0.0);

    // 4. energy: X = E_old + W - |F|^2/(2 k0) must not fall below -L; where it would, the scalar kernel's guard
    const double fsq = ftx * ftx + fty * fty + ftz * ftz;
    const double W = 0.5 * ((f1x + ftx) * dsx + (f1y + fty) * dsy + (f1z + ftz) * dsz);
    const double X = eOld + W - fsq * halfInvK;
    const double roundOff = 1e-12 * (eOld + L0 + fsq * halfInvK + std::abs(W));
    const bool guard = X < -L0 - roundOff;
    const double fNew = capped ? muN : fmag;  // |F_t| after the cap
    // the locked capacity of the loading curve (mdLockedCapacity) at |F_t|
    const double t3 = 1.0 - std::min(fNew * invMuN, 1.0);
    const double t = cbrtUnit(t3);
    const double t5 = t3 * t * t, t6 = t3 * t3;
    const double lockedCap = std::max(0.0, muN * muN * (0.2 * halfInvK) * (1.0 - 5.0 * t3 + 9.0 * t5 - 5.0 * t6));
    const double deposit = std::clamp(lockedCap - L0, 0.0, std::max(X, 0.0));
    const double L = X >= 0.0 ? L0 + deposit : std::max(0.0, L0 + X);
    const double D = X >= 0.0 ? X - deposit : 0.0;
    const double sliding = fNew >= muN ? 1.0 : fullSlip;

    // 5. reversal points follow the normal force, scaled by the slip-annulus fraction of their memory
    const double aLoad = muDN * annulusFraction(std::sqrt(lx * lx + ly * ly + lz * lz), invMuN);
    const double aUnload = muDN * annulusFraction(std::sqrt(ux * ux + uy * uy + uz * uz), invMuN);
    const double moveLoad = br == 1.0 ? -aLoad : (br == 2.0 ? aLoad : 0.0);
    const double moveUnload = br == 2.0 ? -aUnload : 0.0;
    lx += moveLoad * ex, ly += moveLoad * ey, lz += moveLoad * ez;
    ux += moveUnload * ex, uy += moveUnload * ey, uz += moveUnload * ez;
    br = sliding != 0.0 ? 0.0 : br;  // gross sliding wipes the memory

    b.tx[s] = ftx, b.ty[s] = fty, b.tz[s] = ftz;
    b.aPrev[s] = a;
    b.lx[s] = lx, b.ly[s] = ly, b.lz[s] = lz;
    b.ux[s] = ux, b.uy[s] = uy, b.uz[s] = uz;
    b.ex[s] = ex, b.ey[s] = ey, b.ez[s] = ez;
    b.prevFn[s] = N;
    b.locked[s] = L;
    b.branch[s] = br;
    b.storedEnergy[s] = fsq * halfInvK + L;
    b.dissipated[s] = D;
    b.sliding[s] = sliding;
    b.scalar[s] = capacity && representable && !guard ? 0.0 : 1.0;
  }
}

// The caller's side, one pair at a time: its law inputs and history into slot s (the arguments of
// kernels::mindlinDeresiewicz); after the block, mdScatter. The contact pass gathers the history here and
// takes the geometry from the default law's normal-contact loop (mdTakeGeometry).
inline void mdGatherHistory(MdBlock& b, int s, const ContactHistory& h, const MdHistory& md) {
  b.tx[s] = h.tangentialForce.x(), b.ty[s] = h.tangentialForce.y(), b.tz[s] = h.tangentialForce.z();
  b.aPrev[s] = h.contactRadius;
  b.lx[s] = md.turnLoad.x(), b.ly[s] = md.turnLoad.y(), b.lz[s] = md.turnLoad.z();
  b.ux[s] = md.turnUnload.x(), b.uy[s] = md.turnUnload.y(), b.uz[s] = md.turnUnload.z();
  b.ex[s] = md.direction.x(), b.ey[s] = md.direction.y(), b.ez[s] = md.direction.z();
  b.prevFn[s] = md.prevNormalForce;
  b.locked[s] = md.locked;
  b.branch[s] = static_cast<double>(md.branch);
}
inline void mdGather(MdBlock& b, int s, const Vec3& n, const Vec3& vt, double contactRadius, double normalForce,
                     double effShear, double friction, const ContactHistory& h, const MdHistory& md) {
  b.nx[s] = n.x(), b.ny[s] = n.y(), b.nz[s] = n.z();
  b.vtx[s] = vt.x(), b.vty[s] = vt.y(), b.vtz[s] = vt.z();
  b.a[s] = contactRadius;
  b.fn[s] = normalForce;
  b.effShear[s] = effShear;
  b.friction[s] = friction;
  mdGatherHistory(b, s, h, md);
}
// The normal, tangential velocity, contact radius and normal force of slots [0, b.count) (padded) from arrays
// of a block's length (PairBlock's, after hertzNormalBlock).
inline void mdTakeGeometry(MdBlock& b, const double* nx, const double* ny, const double* nz, const double* vtx,
                           const double* vty, const double* vtz, const double* a, const double* fn) {
  const int m = (b.count + kSimdSlots - 1) / kSimdSlots * kSimdSlots;
#pragma omp simd
  for (int s = 0; s < m; ++s) {
    b.nx[s] = nx[s], b.ny[s] = ny[s], b.nz[s] = nz[s];
    b.vtx[s] = vtx[s], b.vty[s] = vty[s], b.vtz[s] = vtz[s];
    b.a[s] = a[s], b.fn[s] = fn[s];
  }
}

// What the caller needs of a slot's step (kernels::MdResult's fields the contact pass reads).
struct MdSlotResult {
  Vec3 force;          // F_t on j [N]
  double storedEnergy;  // [J]
  double dissipated;    // slip + micro-slip work [J]
  bool sliding;
};
// The step of slot s back into the pair's history: the block's where it did not flag the slot, else the scalar
// kernel's, run from the unchanged history (h, md as gathered) with the slot's inputs.
inline MdSlotResult mdScatter(const MdBlock& b, int s, double dt, ContactHistory& h, MdHistory& md) {
  if (b.scalar[s] != 0.0) {
    const MdResult r = mindlinDeresiewicz(Vec3(b.nx[s], b.ny[s], b.nz[s]), Vec3(b.vtx[s], b.vty[s], b.vtz[s]), b.a[s],
                                          b.fn[s], b.effShear[s], b.friction[s], dt, h, md);
    return {r.force, r.storedEnergy, r.slipWork + r.microSlipWork, r.sliding};
  }
  h.tangentialForce = Vec3(b.tx[s], b.ty[s], b.tz[s]);
  h.contactRadius = b.aPrev[s];
  md.turnLoad = Vec3(b.lx[s], b.ly[s], b.lz[s]);
  md.turnUnload = Vec3(b.ux[s], b.uy[s], b.uz[s]);
  md.direction = Vec3(b.ex[s], b.ey[s], b.ez[s]);
  md.prevNormalForce = b.prevFn[s];
  md.locked = b.locked[s];
  md.branch = static_cast<MdBranch>(static_cast<int>(b.branch[s]));
  return {h.tangentialForce, b.storedEnergy[s], b.dissipated[s], b.sliding[s] != 0.0};
}

// What the diagnostics and the energy ledger take from a block besides blockSums (contact_block.hpp): the sum of
// |f| and the extremes of ContactDiagnostics, and (kEnergy) the elastic energies. This law's pass sums them
// itself: its stored tangential energy includes the locked energy L, which measureContacts cannot read off
// the contacts.
struct MdBlockMeasures {
  double sumForce = 0.0, maxOverlapRatio = 0.0, maxKOverM = 0.0;  // [N], [-], [1/s^2]
  double elasticN = 0.0, elasticT = 0.0;                          // [J]
};
// After the pass has written the forces (g.f{x,y,z}) and the slots' stored energy (b, the scalar kernel's where
// it ran). Vectorised across the block's g.count pairs: a block's sums depend on its contents only, so a
// chunk's do not depend on the thread count.
template <bool kEnergy>
inline void mdBlockMeasures(const PairBlock& g, const MdBlock& b, MdBlockMeasures& sums) {
  double sumForce = 0.0, maxOverlap = 0.0, maxKOverM = 0.0, elasticN = 0.0, elasticT = 0.0;
#pragma omp simd reduction(+ : sumForce, elasticN, elasticT) reduction(max : maxOverlap, maxKOverM)
  for (int s = 0; s < g.count; ++s) {
    const double fx = g.fx[s], fy = g.fy[s], fz = g.fz[s];
    sumForce += std::sqrt(fx * fx + fy * fy + fz * fz);
    maxOverlap = std::max(maxOverlap, g.delta[s] / std::min(g.ri[s], g.rj[s]));
    const double kt = mindlinStiffness(b.effShear[s], g.a[s]);
    maxKOverM = std::max(maxKOverM, std::max(g.kn[s], 3.5 * kt) * g.invMassSum[s]);
    if constexpr (kEnergy) {
      elasticN += hertzEnergy(hertzForce(g.effYoung[s], g.a[s], g.delta[s]), g.delta[s]);
      elasticT += b.storedEnergy[s];
    }
  }
  sums.sumForce += sumForce;
  sums.maxOverlapRatio = std::max(sums.maxOverlapRatio, maxOverlap);
  sums.maxKOverM = std::max(sums.maxKOverM, maxKOverM);
  sums.elasticN += elasticN;
  sums.elasticT += elasticT;
}

}  // namespace fl::kernels
