// The vectorised block law (core/contact_block.hpp) against the scalar kernels it restates
// (contact_kernels.hpp: hertzForce, mindlinNoSlip, Tsuji damping), pair by pair, on random touching pairs
// covering new contacts, loading, unloading (spring scaled by a/a_prev), sliding at mu F_n, a spring that
// must be rotated into the new tangent plane, and damped contacts; block sizes that leave a vector remainder.
// Also the block's sums (stress, axis stiffness, sliding count, dissipation) against the pairs' terms.
// (A spring exactly along the new normal is ill-conditioned in both forms — the rotation rescales a
// round-off residue — so it is checked alone, for the exact case that leaves nothing.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/contact_block.hpp"

using namespace fl;
using namespace fl::kernels;

namespace {

struct PairInput {
  Vec3 d, vr, wi, wj;
  double ri, rj, invMassSum, E, G, mu, beta;
  ContactHistory h;
};

struct PairOutput {
  Vec3 n, f, ftElastic;
  double dist, delta, fn, kn, kt, aNew, storedT, dissipatedT, dampPower;
  bool sliding;
};

// The scalar contact pass for one pair, as it was before the block law (one pair at a time).
PairOutput scalarPair(PairInput in, bool damping, double dt) {
  PairOutput o;
  const double dist = std::sqrt(in.d.squaredNorm());
  const Vec3 n = in.d * (1.0 / dist);
  const double R = in.ri + in.rj;
  const double delta = R - dist;
  const double li = in.ri - 0.5 * delta, lj = in.rj - 0.5 * delta;
  const Vec3 vrel = in.vr - (lj * in.wj + li * in.wi).cross(n);
  const double vn = vrel.dot(n);
  const Vec3 vt = vrel - vn * n;
  const double a = std::sqrt(in.ri * in.rj / R * delta);
  const double fe = hertzForce(in.E, a, delta);
  const double kn = hertzStiffness(in.E, a);
  double fn = fe, dampPower = 0.0, mstar = 0.0;
  if (damping) {
    mstar = 1.0 / in.invMassSum;
    fn = std::max(0.0, fe - dampingCoefficient(in.beta, kn, mstar) * vn);
    dampPower = (fe - fn) * vn;
  }
  const TangentialResult tr = mindlinNoSlip(n, vt, a, fn, in.G, in.mu, dt, in.h);
  Vec3 ft = tr.force;
  if (damping && !tr.sliding) {
    const Vec3 fd = -dampingCoefficient(in.beta, tr.stiffness, mstar) * vt;
    ft += fd;
    dampPower -= fd.dot(vt);
  }
  o.n = n;
  o.f = fn * n + ft;
  o.ftElastic = in.h.tangentialForce;
  o.dist = dist;
  o.delta = delta;
  o.fn = fn;
  o.kn = kn;
  o.kt = tr.stiffness;
  o.aNew = in.h.contactRadius;
  o.storedT = tr.force.squaredNorm() * (0.5 * tr.compliance);
  o.dissipatedT = tr.slipWork + tr.stiffnessWork;
  o.dampPower = dampPower;
  o.sliding = tr.sliding;
  return o;
}

// Random touching pairs of glass-bead size with every branch of the law represented.
std::vector<PairInput> randomPairs(int count, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), r(4e-4, 7e-4), frac(0.0, 1.0);
  std::vector<PairInput> pairs;
  for (int k = 0; k < count; ++k) {
    PairInput p;
    p.ri = r(rng);
    p.rj = r(rng);
    const Vec3 dir = Vec3(u(rng), u(rng), u(rng)).normalized();
    const double delta = (1e-6 + 4e-6 * frac(rng)) * (k % 11 == 0 ? 0.01 : 1.0);
    p.d = (p.ri + p.rj - delta) * dir;
    p.vr = 1e-3 * Vec3(u(rng), u(rng), u(rng));
    p.wi = 3.0 * Vec3(u(rng), u(rng), u(rng));
    p.wj = 3.0 * Vec3(u(rng), u(rng), u(rng));
    p.invMassSum = 1.0 / 2e-6 + 1.0 / 3e-6;
    p.E = 3.6e10;
    p.G = 1.5e10;
    p.mu = 0.235;
    p.beta = 0.3;
    const double a = std::sqrt(p.ri * p.rj / (p.ri + p.rj) * delta);
    const double fn = 4.0 / 3.0 * p.E * a * delta;
    switch (k % 5) {
      case 0: break;  // a new contact: no history
      case 1:         // loading: a_prev below a, spring partly outside the tangent plane
        p.h.contactRadius = a * 0.98;
        p.h.tangentialForce = 0.1 * fn * Vec3(u(rng), u(rng), u(rng));
        break;
      case 2:  // unloading: a_prev above a
        p.h.contactRadius = a * 1.03;
        p.h.tangentialForce = 0.2 * fn * dir.cross(Vec3(u(rng), u(rng), u(rng))).normalized();
        break;
      case 3:  // sliding: stored spring beyond mu F_n
        p.h.contactRadius = a;
        p.h.tangentialForce = 2.0 * p.mu * fn * dir.cross(Vec3(u(rng), u(rng), u(rng))).normalized();
        break;
      default:  // the normal has turned: half of the stored spring lies along it and is rotated away
        p.h.contactRadius = a;
        p.h.tangentialForce = 0.1 * fn * (0.5 * dir + dir.cross(Vec3(u(rng), u(rng), u(rng))).normalized());
        break;
    }
    pairs.push_back(p);
  }
  return pairs;
}

void expectClose(double got, double want, double scale, const char* what, int k) {
  EXPECT_NEAR(got, want, 1e-12 * std::max(std::abs(want), scale)) << what << " of pair " << k;
}

void compareBlock(int count, bool damping, unsigned seed) {
  const double dt = 1e-7;
  const std::vector<PairInput> pairs = randomPairs(count, seed);
  PairBlock b{};
  b.count = count;
  for (int s = 0; s < count; ++s) {
    const PairInput& p = pairs[s];
    b.dx[s] = p.d.x(), b.dy[s] = p.d.y(), b.dz[s] = p.d.z();
    b.dist2[s] = p.d.squaredNorm();
    b.ri[s] = p.ri, b.rj[s] = p.rj;
    b.vx[s] = p.vr.x(), b.vy[s] = p.vr.y(), b.vz[s] = p.vr.z();
    b.wix[s] = p.wi.x(), b.wiy[s] = p.wi.y(), b.wiz[s] = p.wi.z();
    b.wjx[s] = p.wj.x(), b.wjy[s] = p.wj.y(), b.wjz[s] = p.wj.z();
    b.invMassSum[s] = p.invMassSum;
    b.effYoung[s] = p.E, b.effShear[s] = p.G, b.friction[s] = p.mu, b.dampingRatio[s] = p.beta;
    b.tx[s] = p.h.tangentialForce.x(), b.ty[s] = p.h.tangentialForce.y(), b.tz[s] = p.h.tangentialForce.z();
    b.aPrev[s] = p.h.contactRadius;
  }
  PairBlock lean = b;  // the same block without the energy terms
  damping ? hertzMindlinBlock<true, true>(b, dt) : hertzMindlinBlock<false, true>(b, dt);
  damping ? hertzMindlinBlock<true, false>(lean, dt) : hertzMindlinBlock<false, false>(lean, dt);
  int sliding = 0;
  for (int s = 0; s < count; ++s) {
    const PairOutput o = scalarPair(pairs[s], damping, dt);
    const double fs = o.fn;  // force scale of the pair
    expectClose(b.delta[s], o.delta, 1e-12 * o.dist, "overlap", s);
    expectClose(b.fn[s], o.fn, 0, "normal force", s);
    expectClose(b.kn[s], o.kn, 0, "normal stiffness", s);
    const Vec3 n(b.nx[s], b.ny[s], b.nz[s]), f(b.fx[s], b.fy[s], b.fz[s]);
    const Vec3 t(b.tx[s], b.ty[s], b.tz[s]);
    for (int c = 0; c < 3; ++c) {
      expectClose(n[c], o.n[c], 1, "normal", s);
      expectClose(f[c], o.f[c], fs, "force", s);
      expectClose(t[c], o.ftElastic[c], fs, "spring", s);
    }
    expectClose(b.aPrev[s], o.aNew, 0, "contact radius", s);
    const double es = fs * o.delta;  // energy scale
    expectClose(b.dissipatedT[s], o.dissipatedT, es, "tangential dissipation", s);
    expectClose(b.dampPower[s], o.dampPower, fs * 1e-3, "damping power", s);
    EXPECT_EQ(b.sliding[s] != 0.0, o.sliding) << "pair " << s;
    // without the energy terms the mechanics are the same to rounding (g++ may contract a multiply-add into
    // an FMA differently once the energy terms are gone, so the last bit can differ)
    const Vec3 lf(lean.fx[s], lean.fy[s], lean.fz[s]), lt(lean.tx[s], lean.ty[s], lean.tz[s]);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(lf[c], f[c], 1e-14 * fs) << "force without energy terms, pair " << s;
      EXPECT_NEAR(lt[c], t[c], 1e-14 * fs) << "spring without energy terms, pair " << s;
    }
    EXPECT_EQ(lean.aPrev[s], b.aPrev[s]) << "pair " << s;
    EXPECT_EQ(lean.sliding[s], b.sliding[s]) << "pair " << s;
    sliding += o.sliding;
  }
  EXPECT_GT(sliding, 0) << "the sample must contain sliding pairs";
  EXPECT_LT(sliding, count) << "and sticking ones";
  // the block's sums (what its chunk adds up), against the pairs' own terms summed one by one
  BlockSums sums;
  blockSums<true>(b, sums);
  double s[3][3] = {}, k[3] = {}, slides = 0, dissipated = 0, damp = 0;
  for (int q = 0; q < count; ++q) {
    const PairOutput o = scalarPair(pairs[q], damping, dt);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) s[r][c] += o.f[r] * pairs[q].d[c];
      k[r] += o.kn * std::pow(o.n[r] * pairs[q].d[r], 2);
    }
    slides += o.sliding;
    dissipated += o.dissipatedT;
    damp += o.dampPower;
  }
  const double fScale = 1e-3 * (pairs[0].ri + pairs[0].rj) * count;  // ~ sum |f| |d|
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sums.s[r][c], s[r][c], 1e-9 * fScale) << "stress sum " << r << c;
    EXPECT_NEAR(sums.k[r], k[r], 1e-12 * std::abs(k[r]) + 1e-300) << "stiffness sum " << r;
  }
  EXPECT_EQ(sums.sliding, slides);
  EXPECT_NEAR(sums.dissipatedT, dissipated, 1e-9 * std::abs(dissipated) + 1e-30);
  EXPECT_NEAR(sums.dampPower, damp, 1e-9 * std::abs(damp) + 1e-30);
}

}  // namespace

TEST(ContactBlock, MatchesTheScalarKernelsWithoutDamping) {
  compareBlock(kBlockPairs, false, 11);
  compareBlock(37, false, 12);  // a remainder after the vector body
}

TEST(ContactBlock, MatchesTheScalarKernelsWithTsujiDamping) {
  compareBlock(kBlockPairs, true, 21);
  compareBlock(13, true, 22);
}

TEST(ContactBlock, SpringExactlyAlongTheNewNormalIsDropped) {
  PairBlock b{};
  b.count = 1;
  b.dx[0] = 0, b.dy[0] = 0, b.dz[0] = 1e-3 - 1e-6;
  b.dist2[0] = b.dz[0] * b.dz[0];
  b.ri[0] = b.rj[0] = 5e-4;
  b.vx[0] = b.vy[0] = b.vz[0] = 0;
  b.wix[0] = b.wiy[0] = b.wiz[0] = b.wjx[0] = b.wjy[0] = b.wjz[0] = 0;
  b.invMassSum[0] = 1e6;
  b.effYoung[0] = 3.6e10, b.effShear[0] = 1.5e10, b.friction[0] = 0.235, b.dampingRatio[0] = 0;
  b.tx[0] = 0, b.ty[0] = 0, b.tz[0] = 0.5;
  b.aPrev[0] = std::sqrt(2.5e-4 * 1e-6);
  hertzMindlinBlock<false, true>(b, 1e-7);
  EXPECT_EQ(b.tx[0], 0.0);
  EXPECT_EQ(b.ty[0], 0.0);
  EXPECT_EQ(b.tz[0], 0.0);
}

TEST(ContactBlock, EmptyBlockWritesNothing) {
  PairBlock b{};
  b.count = 0;
  b.fn[0] = -1.0;
  hertzMindlinBlock<false, true>(b, 1e-7);
  EXPECT_EQ(b.fn[0], -1.0);
}
