// The Hertz–Mindlin no-slip law over a block of touching pairs held as structure of arrays, written without
// branches so that the compiler vectorises it across pairs (issue 6: the contact pass was ~86 % of a step,
// bound by the latency of scalar square roots and divisions). Same law, same operations as
// kernels::hertzForce + kernels::mindlinNoSlip (+ the Tsuji damping of the scalar pass), with every `if`
// turned into a select on safe operands, but for the quotients: they share reciprocals where they can
// (1/(d R) gives 1/d and R*; 1/(k_t a_prev |F_t'|^2) gives 1/k_t, a/a_prev and the rotation's rescaling), as on
// AVX2 the law was bound by the divider (5 square roots and 7 divisions a pair before, 4 and 3 now), so it
// agrees with the kernels to rounding; tests/contact_block_test.cpp checks it pair by pair against them,
// including new, sliding, unloading and damped contacts. g++ vectorises it only with -fno-trapping-math
// (CMakeLists.txt): without AVX-512's masks the guarded quotients would otherwise stay branches.
// Stateless: inputs and history in, results and updated history out; the caller gathers and scatters.
// Per step it computes what every step needs: forces and their moments n x f (the kick's torques), history,
// and the terms of the stress, the axis
// stiffness, the sliding count and the energy ledger's dissipation (blockSums). The extreme and mean values
// of ContactDiagnostics and the stored elastic energies are read off the stored contacts when asked for
// (Simulation::measureContacts), so they cost the law no square root or division.
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
  alignas(64) double invMassSum[kBlockPairs];  // 1/m_i + 1/m_j [1/kg], read only with damping (and mdBlockMeasures)
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
  alignas(64) double mx[kBlockPairs], my[kBlockPairs], mz[kBlockPairs];  // its moment n x f [N]
  alignas(64) double kn[kBlockPairs];       // 2 E* a [N/m]
  // ---- between the law's two loops
  alignas(64) double vtx[kBlockPairs], vty[kBlockPairs], vtz[kBlockPairs];  // tangential velocity [m/s]
  alignas(64) double a[kBlockPairs];            // contact radius of this step [m]
  alignas(64) double reducedMass[kBlockPairs];  // m* [kg] (damping only)
  alignas(64) double compliance[kBlockPairs];   // 1/k_t [m/N] (energy only)
  // dissipatedT (below) holds the stiffness work of steps 1-2 between the second and the third loop
  alignas(64) double sliding[kBlockPairs];  // 1 at the Coulomb limit, else 0
  // energy terms, only meaningful when the caller tracks energy: tangential dissipation [J], damping power [W]
  alignas(64) double dissipatedT[kBlockPairs], dampPower[kBlockPairs];
};

// What a block adds to its chunk's sums (Simulation::Chunk): the Love–Weber sum f (x) d, the axis stiffness
// sum k_n (n_k d_k)^2, the count of sliding pairs and (kEnergy) the dissipated energies.
struct BlockSums {
  double s[3][3] = {};  // sum f_a d_b [N m]
  double k[3] = {};     // sum k_n (n_k d_k)^2 [N m]
  double sliding = 0.0;
  double dissipatedT = 0.0, dampPower = 0.0;  // [J], [W]
};

// The normal contact of b.count pairs (the first loop of hertzMindlinBlock, which the Mindlin–Deresiewicz pass
// runs too): unit normal, overlap, contact radius, Hertz force and stiffness, the tangential velocity and
// (kDamping) the Tsuji damping of the normal force, its power and the reduced mass.
template <bool kDamping>
inline void hertzNormalBlock(PairBlock& b) {
  const int m = (b.count + kSimdSlots - 1) / kSimdSlots * kSimdSlots;  // padding: see kSimdSlots
#pragma omp simd
  for (int s = 0; s < m; ++s) {
    const double d = std::sqrt(b.dist2[s]);
    const double ri = b.ri[s], rj = b.rj[s];
    const double R = ri + rj;
    const double q = 1.0 / (d * R);  // 1/d = R q and 1/R = d q
    const double invDist = R * q;
    const double nx = b.dx[s] * invDist, ny = b.dy[s] * invDist, nz = b.dz[s] * invDist;
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
    // Hertz (Johnson 1985, eq. 4.23) through the contact radius a = sqrt(R* delta)
    const double Rstar = ri * rj * (d * q);
    const double a = std::sqrt(Rstar * delta);
    const double E = b.effYoung[s];
    const double fe = hertzForce(E, a, delta);
    const double kn = hertzStiffness(E, a);
    double fn = fe;
    if constexpr (kDamping) {
      const double mstar = 1.0 / b.invMassSum[s];
      const double cn = dampingCoefficient(b.dampingRatio[s], kn, mstar);
      fn = std::max(0.0, fe - cn * vn);
      b.reducedMass[s] = mstar;
      b.dampPower[s] = (fe - fn) * vn;
    }
    b.nx[s] = nx;
    b.ny[s] = ny;
    b.nz[s] = nz;
    b.vtx[s] = vrx - vn * nx, b.vty[s] = vry - vn * ny, b.vtz[s] = vrz - vn * nz;
    b.delta[s] = delta;
    b.a[s] = a;
    b.fn[s] = fn;
    b.kn[s] = kn;
  }
}

// Hertz normal force, Tsuji damping (kDamping) and the incremental Mindlin no-slip spring with Coulomb cap,
// for b.count pairs. See contact_kernels.hpp for the law and its energy bookkeeping (Thornton et al. 2011).
// kEnergy: also write the energy terms (dissipatedT, dampPower); without it they are left unwritten, and what
// only they need (the compliance 1/k_t among it) is dead code the compiler removes.
template <bool kDamping, bool kEnergy>
inline void hertzMindlinBlock(PairBlock& b, double dt) {
  const int m = (b.count + kSimdSlots - 1) / kSimdSlots * kSimdSlots;  // padding: see kSimdSlots
  // Three loops: the normal contact; the stored spring's rotation and unloading; its increment, the Coulomb
  // cap and the forces. Each pair's law is one long chain of square roots and divisions; in one loop of ~270
  // instructions the out-of-order window held about one iteration, so the chains of consecutive vectors
  // hardly overlapped (AVX2: four pairs a vector), and the values live across it spilled to the stack. Short
  // loops overlap several iterations; what passes between them goes through the block (L1). bench_block_law
  // (no damping, energy terms, Zen 3): 14.1 ns a pair as two loops with vector selects, 12.6 as these three.
  hertzNormalBlock<kDamping>(b);
  // Mindlin no-slip spring (mindlinNoSlip): 1. rotate into the tangent plane, 2. scale on unloading,
  // 3. increment, 4. Coulomb cap
#pragma omp simd
  for (int s = 0; s < m; ++s) {
    const double nx = b.nx[s], ny = b.ny[s], nz = b.nz[s];
    const double a = b.a[s];
    const double kt = mindlinStiffness(b.effShear[s], a);
    double tx = b.tx[s], ty = b.ty[s], tz = b.tz[s];
    const double old2 = tx * tx + ty * ty + tz * tz;
    const double proj = tx * nx + ty * ny + tz * nz;
    const double px = tx - proj * nx, py = ty - proj * ny, pz = tz - proj * nz;
    const double new2 = px * px + py * py + pz * pz;
    // A stored spring is rotated into the tangent plane and rescaled to its length (without one, F_t = 0, and so
    // are its projection, the rescaling's effect and the energy terms below: no test on |F_t| is needed), then
    // scaled on unloading; the selects pick factors, not vectors. A touching pair has a > 0, so k_t > 0.
    const bool rescale = new2 > 0.0;
    const double aPrev = b.aPrev[s];
    // one reciprocal for three quotients, each factor that may be 0 replaced by 1 (and then unused)
    const double aPrevSafe = aPrev > 0.0 ? aPrev : 1.0;
    const double new2Safe = rescale ? new2 : 1.0;
    const double w = 1.0 / (kt * aPrevSafe * new2Safe);
    const double compliance = aPrevSafe * new2Safe * w;  // 1/k_t, energy terms only
    const double keep = rescale ? std::sqrt(old2 * (kt * aPrevSafe * w)) : 1.0;  // |F_t| / |F_t'|
    const bool scaled = aPrev > 0.0;
    const double ratio = a * (kt * new2Safe * w);  // a / a_prev = k_t / k_t,prev where scaled
    const bool unloading = scaled && ratio < 1.0;
    const double unload = unloading ? ratio : 1.0;
    tx = px * keep * unload;
    ty = py * keep * unload;
    tz = pz * keep * unload;
    const double kept2 = unloading ? old2 * ratio * ratio : old2;
    b.tx[s] = tx;
    b.ty[s] = ty;
    b.tz[s] = tz;
    if constexpr (kEnergy) {
      b.dissipatedT[s] = scaled ? (ratio * old2 - kept2) * (0.5 * compliance) : 0.0;  // the stiffness work
      b.compliance[s] = compliance;
    }
  }
#pragma omp simd
  for (int s = 0; s < m; ++s) {
    const double nx = b.nx[s], ny = b.ny[s], nz = b.nz[s];
    const double vtx = b.vtx[s], vty = b.vty[s], vtz = b.vtz[s];
    const double a = b.a[s], fn = b.fn[s];
    const double kt = mindlinStiffness(b.effShear[s], a);
    double tx = b.tx[s], ty = b.ty[s], tz = b.tz[s];
    const double ktdt = kt * dt;
    tx -= ktdt * vtx;
    ty -= ktdt * vty;
    tz -= ktdt * vtz;
    const double cap = b.friction[s] * fn;
    const double f2 = tx * tx + ty * ty + tz * tz;
    const bool slide = f2 > cap * cap;
    const double fmag = std::sqrt(f2);
    const double capScale = slide ? cap / fmag : 1.0;  // a sliding pair has |F_t| > 0
    tx *= capScale;
    ty *= capScale;
    tz *= capScale;
    b.tx[s] = tx;
    b.ty[s] = ty;
    b.tz[s] = tz;
    b.aPrev[s] = a;
    double ftx = tx, fty = ty, ftz = tz;
    double dampPower = 0.0;
    if constexpr (kDamping) {
      const double ct = slide ? 0.0 : dampingCoefficient(b.dampingRatio[s], kt, b.reducedMass[s]);
      const double dx = -ct * vtx, dy = -ct * vty, dz = -ct * vtz;
      ftx += dx;
      fty += dy;
      ftz += dz;
      dampPower = b.dampPower[s] - (dx * vtx + dy * vty + dz * vtz);
    }
    const double fx = fn * nx + ftx, fy = fn * ny + fty, fz = fn * nz + ftz;
    b.fx[s] = fx;
    b.fy[s] = fy;
    b.fz[s] = fz;
    b.mx[s] = ny * fz - nz * fy;
    b.my[s] = nz * fx - nx * fz;
    b.mz[s] = nx * fy - ny * fx;
    b.sliding[s] = slide ? 1.0 : 0.0;
    if constexpr (kEnergy) {
      b.dissipatedT[s] += slide ? cap * (fmag - cap) * b.compliance[s] : 0.0;  // + the slip work
      b.dampPower[s] = dampPower;
    }
  }
}

// Adds the block's b.count pairs (after hertzMindlinBlock) to `sums`, vectorised across the pairs: the sums of
// one block depend on its contents only, so a chunk's sums do not depend on the thread count.
template <bool kEnergy>
inline void blockSums(const PairBlock& b, BlockSums& sums) {
  double sxx = 0.0, sxy = 0.0, sxz = 0.0, syx = 0.0, syy = 0.0, syz = 0.0, szx = 0.0, szy = 0.0, szz = 0.0;
  double kx = 0.0, ky = 0.0, kz = 0.0, sliding = 0.0, dissipated = 0.0, damp = 0.0;
#pragma omp simd reduction(+ : sxx, sxy, sxz, syx, syy, syz, szx, szy, szz, kx, ky, kz, sliding, dissipated, damp)
  for (int s = 0; s < b.count; ++s) {
    const double dx = b.dx[s], dy = b.dy[s], dz = b.dz[s];
    const double fx = b.fx[s], fy = b.fy[s], fz = b.fz[s];
    sxx += fx * dx, sxy += fx * dy, sxz += fx * dz;
    syx += fy * dx, syy += fy * dy, syz += fy * dz;
    szx += fz * dx, szy += fz * dy, szz += fz * dz;
    const double ux = b.nx[s] * dx, uy = b.ny[s] * dy, uz = b.nz[s] * dz;
    kx += b.kn[s] * (ux * ux), ky += b.kn[s] * (uy * uy), kz += b.kn[s] * (uz * uz);
    sliding += b.sliding[s];
    if constexpr (kEnergy) {
      dissipated += b.dissipatedT[s];
      damp += b.dampPower[s];
    }
  }
  const double add[3][3] = {{sxx, sxy, sxz}, {syx, syy, syz}, {szx, szy, szz}};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) sums.s[r][c] += add[r][c];
  sums.k[0] += kx, sums.k[1] += ky, sums.k[2] += kz;
  sums.sliding += sliding;
  sums.dissipatedT += dissipated;
  sums.dampPower += damp;
}

}  // namespace fl::kernels
