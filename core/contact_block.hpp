// The Hertz–Mindlin no-slip law over a block of touching pairs held as structure of arrays, written without
// branches so that the compiler vectorises it across pairs (issue 6: the contact pass was ~86 % of a step,
// bound by the latency of scalar square roots and divisions). Same law, same operations in the same order
// as kernels::hertzForce + kernels::mindlinNoSlip (+ the Tsuji damping of the scalar pass), with every
// `if` turned into a select on safe operands; tests/contact_block_test.cpp checks it pair by pair against
// those scalar kernels, including new, sliding, unloading and damped contacts.
// Stateless: inputs and history in, results and updated history out; the caller gathers and scatters.
#pragma once

#include <algorithm>
#include <cmath>

#include "contact_kernels.hpp"

namespace fl::kernels {

// Pairs per block: ~40 arrays of 64 doubles (20 KiB) stay in L1 while the block is processed.
constexpr int kBlockPairs = 64;
// The law runs over the count rounded up to this many slots (one AVX-512 vector of doubles), so no pair
// falls to a scalar remainder loop, which g++ does not always vectorise.
constexpr int kSimdSlots = 8;
static_assert(kBlockPairs % kSimdSlots == 0, "padded counts stay within the block");

// Create it value-initialised (PairBlock b{}): the slots past count run through the law as padding, so they
// must hold determinate values (zeros, or an earlier block's pairs); their results are ignored.
struct alignas(64) PairBlock {
  int count = 0;  // touching pairs held, <= kBlockPairs
  // ---- inputs, gathered by the caller
  alignas(64) double dx[kBlockPairs], dy[kBlockPairs], dz[kBlockPairs];  // branch vector i -> j' [m]
  alignas(64) double dist2[kBlockPairs];                                 // |d|^2 < (r_i + r_j)^2 [m^2]
  alignas(64) double ri[kBlockPairs], rj[kBlockPairs];                   // radii [m]
  alignas(64) double vx[kBlockPairs], vy[kBlockPairs], vz[kBlockPairs];  // v_j - v_i (+ L d) [m/s]
  alignas(64) double wix[kBlockPairs], wiy[kBlockPairs], wiz[kBlockPairs];  // omega_i [rad/s]
  alignas(64) double wjx[kBlockPairs], wjy[kBlockPairs], wjz[kBlockPairs];  // omega_j [rad/s]
  alignas(64) double invMassSum[kBlockPairs];                            // 1/m_i + 1/m_j [1/kg]
  alignas(64) double effYoung[kBlockPairs], effShear[kBlockPairs];       // E*, G* [Pa]
  alignas(64) double friction[kBlockPairs], dampingRatio[kBlockPairs];   // mu, beta [-]
  // ---- history: in and out (ContactHistory)
  alignas(64) double tx[kBlockPairs], ty[kBlockPairs], tz[kBlockPairs];  // elastic F_t on j [N]
  alignas(64) double aPrev[kBlockPairs];  // contact radius of the previous step, 0 for a new contact [m]
  // ---- results
  alignas(64) double nx[kBlockPairs], ny[kBlockPairs], nz[kBlockPairs];  // unit normal i -> j
  alignas(64) double delta[kBlockPairs];                                 // overlap [m]
  alignas(64) double fn[kBlockPairs];                                    // F_n >= 0 [N]
  alignas(64) double fx[kBlockPairs], fy[kBlockPairs], fz[kBlockPairs];  // total force on j [N]
  alignas(64) double kn[kBlockPairs], kOverM[kBlockPairs];  // 2 E* a [N/m]; max(k_n, 3.5 k_t)(1/m_i + 1/m_j)
  alignas(64) double fnorm[kBlockPairs], overlapRatio[kBlockPairs];  // |f| [N]; delta / min(r_i, r_j)
  alignas(64) double sliding[kBlockPairs];                           // 1 at the Coulomb limit, else 0
  // energy terms [J] (and dissipation power [W]), only meaningful when the caller tracks energy
  alignas(64) double elasticN[kBlockPairs], storedT[kBlockPairs], dissipatedT[kBlockPairs];
  alignas(64) double dampPower[kBlockPairs];
};

// Hertz normal force, Tsuji damping (kDamping) and the incremental Mindlin no-slip spring with Coulomb cap,
// for b.count pairs. See contact_kernels.hpp for the law and its energy bookkeeping (Thornton et al. 2011).
// kEnergy: also write the energy terms (elasticN, storedT, dissipatedT, dampPower); without it they are left
// unwritten, and what only they need (the compliance 1/k_t among it) is dead code the compiler removes.
template <bool kDamping, bool kEnergy>
inline void hertzMindlinBlock(PairBlock& b, double dt) {
  const int m = (b.count + kSimdSlots - 1) / kSimdSlots * kSimdSlots;  // padding: see kSimdSlots
#pragma omp simd
  for (int s = 0; s < m; ++s) {
    const double d = std::sqrt(b.dist2[s]);
    const double invDist = 1.0 / d;
    const double nx = b.dx[s] * invDist, ny = b.dy[s] * invDist, nz = b.dz[s] * invDist;
    const double ri = b.ri[s], rj = b.rj[s];
    const double R = ri + rj;
    const double delta = R - d;
    const double li = ri - 0.5 * delta, lj = rj - 0.5 * delta;
    // v_rel = v_j - v_i - (l_j w_j + l_i w_i) x n
    const double cx = lj * b.wjx[s] + li * b.wix[s];
    const double cy = lj * b.wjy[s] + li * b.wiy[s];
    const double cz = lj * b.wjz[s] + li * b.wiz[s];
    const double vrx = b.vx[s] - (cy * nz - cz * ny);
    const double vry = b.vy[s] - (cz * nx - cx * nz);
    const double vrz = b.vz[s] - (cx * ny - cy * nx);
    const double vn = vrx * nx + vry * ny + vrz * nz;
    const double vtx = vrx - vn * nx, vty = vry - vn * ny, vtz = vrz - vn * nz;
    // Hertz (Johnson 1985, eq. 4.23) through the contact radius a = sqrt(R* delta)
    const double Rstar = ri * rj / R;
    const double a = std::sqrt(Rstar * delta);
    const double E = b.effYoung[s];
    const double fe = hertzForce(E, a, delta);
    const double kn = hertzStiffness(E, a);
    double fn = fe, dampPower = 0.0, mstar = 0.0;
    if constexpr (kDamping) {
      mstar = 1.0 / b.invMassSum[s];
      const double cn = dampingCoefficient(b.dampingRatio[s], kn, mstar);
      fn = std::max(0.0, fe - cn * vn);
      dampPower = (fe - fn) * vn;
    }
    // Mindlin no-slip spring (mindlinNoSlip): 1. rotate into the tangent plane, 2. scale on unloading,
    // 3. increment, 4. Coulomb cap
    const double kt = mindlinStiffness(b.effShear[s], a);
    const double compliance = kt > 0.0 ? 1.0 / (kt > 0.0 ? kt : 1.0) : 0.0;  // energy terms only
    double tx = b.tx[s], ty = b.ty[s], tz = b.tz[s];
    const double old2 = tx * tx + ty * ty + tz * tz;
    const double proj = tx * nx + ty * ny + tz * nz;
    const double px = tx - proj * nx, py = ty - proj * ny, pz = tz - proj * nz;
    const double new2 = px * px + py * py + pz * pz;
    const bool rotate = old2 > 0.0;
    const bool rescale = rotate && new2 > 0.0;
    const double keep = rescale ? std::sqrt(old2 / (rescale ? new2 : 1.0)) : 1.0;
    tx = rotate ? (rescale ? px * keep : px) : tx;
    ty = rotate ? (rescale ? py * keep : py) : ty;
    tz = rotate ? (rescale ? pz * keep : pz) : tz;
    const double aPrev = b.aPrev[s];
    const bool scaled = rotate && aPrev > 0.0;
    const double ratio = a / (aPrev > 0.0 ? aPrev : 1.0);  // k_t / k_t,prev where scaled
    const bool unloading = scaled && ratio < 1.0;
    tx = unloading ? tx * ratio : tx;
    ty = unloading ? ty * ratio : ty;
    tz = unloading ? tz * ratio : tz;
    const double kept2 = unloading ? old2 * ratio * ratio : old2;
    const double stiffnessWork = scaled ? (ratio * old2 - kept2) * (0.5 * compliance) : 0.0;
    const double ktdt = kt * dt;
    tx -= ktdt * vtx;
    ty -= ktdt * vty;
    tz -= ktdt * vtz;
    const double cap = b.friction[s] * fn;
    const double f2 = tx * tx + ty * ty + tz * tz;
    const bool slide = f2 > cap * cap;
    const double fmag = std::sqrt(f2);
    const double capScale = cap / (slide ? fmag : 1.0);
    tx = slide ? capScale * tx : tx;
    ty = slide ? capScale * ty : ty;
    tz = slide ? capScale * tz : tz;
    const double slipWork = slide ? cap * (fmag - cap) * compliance : 0.0;
    b.tx[s] = tx;
    b.ty[s] = ty;
    b.tz[s] = tz;
    b.aPrev[s] = a;
    double ftx = tx, fty = ty, ftz = tz;
    if constexpr (kDamping) {
      const double ct = slide ? 0.0 : dampingCoefficient(b.dampingRatio[s], kt, mstar);
      const double dx = -ct * vtx, dy = -ct * vty, dz = -ct * vtz;
      ftx += dx;
      fty += dy;
      ftz += dz;
      dampPower -= dx * vtx + dy * vty + dz * vtz;
    }
    const double fx = fn * nx + ftx, fy = fn * ny + fty, fz = fn * nz + ftz;
    b.nx[s] = nx;
    b.ny[s] = ny;
    b.nz[s] = nz;
    b.delta[s] = delta;
    b.fn[s] = fn;
    b.fx[s] = fx;
    b.fy[s] = fy;
    b.fz[s] = fz;
    b.kn[s] = kn;
    b.kOverM[s] = std::max(kn, 3.5 * kt) * b.invMassSum[s];
    b.fnorm[s] = std::sqrt(fx * fx + fy * fy + fz * fz);
    b.overlapRatio[s] = delta / std::min(ri, rj);
    b.sliding[s] = slide ? 1.0 : 0.0;
    // the energy terms stay computed in place above: g++ 12 stopped vectorising the loop when they were moved
    // into this block
    if constexpr (kEnergy) {
      b.elasticN[s] = hertzEnergy(fe, delta);
      b.storedT[s] = (tx * tx + ty * ty + tz * tz) * (0.5 * compliance);
      b.dissipatedT[s] = slipWork + stiffnessWork;
      b.dampPower[s] = dampPower;
    }
  }
}

}  // namespace fl::kernels
