// The vectorised block law alone (core/contact_block.hpp: hertzMindlinBlock, then blockSums) on one block of
// 64 touching pairs that stays in L1: nanoseconds per pair for each instantiation the contact pass uses
// (with and without contact damping, with and without the energy terms). bench_dense measures the whole step;
// this isolates the law from the gather and scatter around it, so that a change to the law can be judged
// without the machine's ±20 % noise on whole steps: the best of many short repeats is steady to ~1 %.
// Not a test: it prints numbers and asserts nothing.
//
//   bench_block_law [--repeats N]   (default 400; each repeat runs the law 200 times over the block)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>

#include "core/contact_block.hpp"

using namespace fl;
using namespace fl::kernels;

namespace {

// Glass-bead pairs touching by 1-5 um, with stored springs of a tenth of F_n in the tangent plane, some
// loading and some unloading (a_prev 1 % above or below a), random sliding and spin.
void fill(PairBlock& b, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), r(4e-4, 7e-4), frac(0.0, 1.0);
  b.count = kBlockPairs;
  for (int s = 0; s < kBlockPairs; ++s) {
    const double ri = r(rng), rj = r(rng), delta = 1e-6 + 4e-6 * frac(rng);
    const Vec3 dir = Vec3(u(rng), u(rng), u(rng)).normalized();
    const Vec3 d = (ri + rj - delta) * dir;
    b.dx[s] = d.x(), b.dy[s] = d.y(), b.dz[s] = d.z();
    b.dist2[s] = d.squaredNorm();
    b.ri[s] = ri, b.rj[s] = rj;
    b.vx[s] = 1e-3 * u(rng), b.vy[s] = 1e-3 * u(rng), b.vz[s] = 1e-3 * u(rng);
    b.wix[s] = u(rng), b.wiy[s] = u(rng), b.wiz[s] = u(rng);
    b.wjx[s] = u(rng), b.wjy[s] = u(rng), b.wjz[s] = u(rng);
    b.invMassSum[s] = 1e6;
    b.effYoung[s] = 3.6e10, b.effShear[s] = 1.5e10, b.friction[s] = 0.235, b.dampingRatio[s] = 0.3;
    const double a = std::sqrt(ri * rj / (ri + rj) * delta);
    const double fn = 4.0 / 3.0 * b.effYoung[s] * a * delta;
    const Vec3 t = 0.1 * fn * dir.cross(Vec3(u(rng), u(rng), u(rng))).normalized();
    b.tx[s] = t.x(), b.ty[s] = t.y(), b.tz[s] = t.z();
    b.aPrev[s] = a * (s % 2 ? 1.01 : 0.99);
  }
}

template <bool kDamping, bool kEnergy>
double nsPerPair(int repeats) {
  static PairBlock b{}, fresh{};
  fill(fresh, 7);
  constexpr int kCalls = 200;
  double best = 1e300;
  BlockSums sums;
  for (int k = 0; k < repeats; ++k) {
    std::memcpy(static_cast<void*>(&b), &fresh, sizeof b);  // the same inputs every repeat
    const auto t0 = std::chrono::steady_clock::now();
    for (int c = 0; c < kCalls; ++c) {
      hertzMindlinBlock<kDamping, kEnergy>(b, 1e-7);
      blockSums<kEnergy>(b, sums);
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::min(best, s / (kCalls * kBlockPairs));
  }
  if (!std::isfinite(sums.s[0][0])) std::printf("(non-finite sums)\n");  // keeps the sums alive
  return best * 1e9;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 400;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--repeats" && k + 1 < argc) {
      repeats = std::atoi(argv[++k]);
    } else {
      std::fprintf(stderr, "usage: bench_block_law [--repeats N]\n");
      return 2;
    }
  }
  if (repeats < 1) repeats = 1;
  std::printf("block law + block sums, %d pairs a block, best of %d repeats [ns per pair]\n", kBlockPairs, repeats);
  std::printf("  no damping, energy terms:    %.3f\n", nsPerPair<false, true>(repeats));
  std::printf("  no damping, no energy terms: %.3f\n", nsPerPair<false, false>(repeats));
  std::printf("  damping, energy terms:       %.3f\n", nsPerPair<true, true>(repeats));
  std::printf("  damping, no energy terms:    %.3f\n", nsPerPair<true, false>(repeats));
  return 0;
}
