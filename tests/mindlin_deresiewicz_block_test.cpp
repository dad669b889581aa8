// The Mindlin–Deresiewicz law over a block of pairs (core/mindlin_deresiewicz_block.hpp), which the contact pass
// runs: its cube root against libm's; the block pair by pair against the scalar kernel
// (core/mindlin_deresiewicz.hpp, whose closed-form and energy tests are in mindlin_deresiewicz_test.cpp) on
// random paths through every branch, reversal, opening and the energy guard; and the closed forms of monotonic
// loading and of a Masing cycle (Mindlin & Deresiewicz 1953; Johnson 1985 §7.4) through the block itself.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "core/mindlin_deresiewicz.hpp"
#include "core/mindlin_deresiewicz_block.hpp"

using namespace fl;

namespace {
double ulpsApart(double a, double b) {
  if (a == b) return 0.0;
  return std::abs(a - b) / (std::nextafter(b, std::numeric_limits<double>::infinity()) - b);
}
}  // namespace

TEST(MdBlockCubeRoot, WithinFourUlpOfLibmOnTheLawsArguments) {
  EXPECT_EQ(kernels::cbrtUnit(0.0), 0.0);
  EXPECT_EQ(kernels::cbrtUnit(1.0), 1.0);
  EXPECT_EQ(kernels::cbrtUnit(0.125), 0.5);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst = 0.0;
  long differ = 0;
  const long n = 2'000'000;
  for (long k = 0; k < n; ++k) {
    // uniform on [0, 1], spread over 100 binades, and just below 1 (1 - a small ratio, the no-slip limit)
    const double x = k % 3 == 0 ? U(rng) : (k % 3 == 1 ? std::exp2(-100.0 * U(rng)) : 1.0 - 1e-12 * U(rng));
    const double u = ulpsApart(kernels::cbrtUnit(x), std::cbrt(x));
    worst = std::max(worst, u);
    differ += u > 0.0;
  }
  // the law's smallest non-zero argument: one ulp below 1 away from 1
  EXPECT_LE(ulpsApart(kernels::cbrtUnit(0x1p-53), std::cbrt(0x1p-53)), 4.0);
  std::printf("cbrtUnit: max %.0f ulp from libm, %ld of %ld values differ\n", worst, differ, n);
  // 3 or 4 ulp by how the compiler contracts the Newton steps into FMAs (g++ and clang, -ffp-contract off, on
  // and fast: 4, 4, 3 and 4, 3, 3; CI's clang sanitizer build 4)
  EXPECT_LE(worst, 4.0);
}

namespace {
// One contact on a random path (the energy test's generator in mindlin_deresiewicz_test.cpp): a normal force
// that walks, drops to zero (the contact opens) and jumps back, a wandering tangential direction with frequent
// reversals up to 4 % of delta_s a step, and on some paths a turning normal.
struct RandomContact {
  std::mt19937_64 rng;
  std::uniform_real_distribution<double> U{0.0, 1.0};
  double G, mu, a0, N0, N, a, angle = 0.0;
  bool rotate;
  Vec3 n = Vec3::UnitZ();
  ContactHistory h;
  MdHistory md;
  RandomContact(std::uint64_t seed) : rng(seed) {
    G = 4e9 + 8e9 * U(rng);
    mu = 0.05 + 0.5 * U(rng);
    a0 = 5e-5 + 1e-4 * U(rng);
    N0 = 10.0 + 100.0 * U(rng);
    N = N0;
    a = a0;
    rotate = seed % 2 == 0;
    h.contactRadius = a;
    md.prevNormalForce = N;
  }
  // the next step's inputs: vt (dt = 1 s, so ds = -vt)
  Vec3 next() {
    const double x = U(rng);
    if (x < 0.002) N = 0.0;
    else if (N == 0.0) N = N0 * (0.05 + U(rng));
    else N *= std::exp(0.08 * (U(rng) - 0.5));
    N = std::min(N, 5 * N0);
    a = a0 * std::cbrt(N / N0);
    angle += 0.3 * (U(rng) - 0.5);
    const double sign = U(rng) < 0.3 ? -1.0 : 1.0;
    const double mag = 0.04 * kernels::mdSlipDisplacement(G, a0, mu, std::max(N, 0.05 * N0)) * U(rng);
    if (rotate) {
      const Vec3 axis = Vec3(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5).normalized();
      n = Eigen::AngleAxisd(2e-3 * U(rng), axis) * n;
      n.normalize();
    }
    const Vec3 t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    const double still = U(rng) < 0.01 ? 0.0 : 1.0;  // now and then no tangential motion at all
    return -still * sign * mag * (std::cos(angle) * t1 + std::sin(angle) * t2);
  }
};
}  // namespace

TEST(MdBlockLaw, AgreesWithTheScalarKernelPairByPairOnRandomPaths) {
  // 64 contacts in one block (a full block; and 61, to run the padding), each step gathered from the scalar
  // kernel's history, so every step compares the two laws from the same state.
  for (const int count : {kernels::kBlockPairs, kernels::kBlockPairs - 3}) {
    std::vector<RandomContact> cs;
    for (int s = 0; s < count; ++s) cs.emplace_back(1000 + 17 * s + count);
    kernels::MdBlock b{};
    long steps = 0, flagged = 0, guarded = 0, noCapacity = 0, branchDiff = 0, slidingDiff = 0;
    long branches[3] = {0, 0, 0};
    double worstForce = 0.0, worstMemory = 0.0, worstEnergy = 0.0;
    for (int k = 0; k < 6000; ++k) {
      std::vector<Vec3> vt(count);
      for (int s = 0; s < count; ++s) {
        RandomContact& c = cs[s];
        vt[s] = c.next();
        kernels::mdGather(b, s, c.n, vt[s], c.a, c.N, c.G, c.mu, c.h, c.md);
      }
      b.count = count;
      kernels::mindlinDeresiewiczBlock(b, 1.0);
      for (int s = 0; s < count; ++s, ++steps) {
        RandomContact& c = cs[s];
        ContactHistory hb = c.h;  // the block's step, through the caller's side (scalar fallback included)
        MdHistory mb = c.md;
        const kernels::MdSlotResult rb = kernels::mdScatter(b, s, 1.0, hb, mb);
        const kernels::MdResult r = kernels::mindlinDeresiewicz(c.n, vt[s], c.a, c.N, c.G, c.mu, 1.0, c.h, c.md);
        const bool flag = b.scalar[s] != 0.0;
        flagged += flag;
        guarded += r.guarded;
        noCapacity += !(c.mu * c.N > 0.0);
        // the block hands exactly the guard's steps and those without friction capacity to the scalar kernel
        // (the guard's threshold is the same expression, rounded alike to within its 1e-12 margin)
        if (flag) {
          ASSERT_TRUE(r.guarded || !(c.mu * c.N > 0.0)) << "step " << k << " slot " << s;
        } else {
          ASSERT_FALSE(r.guarded) << "step " << k << " slot " << s;
        }
        const double muN = c.mu * c.N, scale = muN > 0.0 ? muN : 1.0;
        const double k0 = 8.0 * c.G * c.a;
        const double energyScale = muN * muN / (k0 > 0.0 ? k0 : 1.0) + 1e-300;
        worstForce = std::max(worstForce, (rb.force - r.force).norm() / scale);
        worstMemory = std::max({worstMemory, (mb.turnLoad - c.md.turnLoad).norm() / scale,
                                (mb.turnUnload - c.md.turnUnload).norm() / scale,
                                (mb.direction - c.md.direction).norm()});
        worstEnergy = std::max({worstEnergy, std::abs(rb.storedEnergy - r.storedEnergy) / energyScale,
                                std::abs(rb.dissipated - (r.slipWork + r.microSlipWork)) / energyScale,
                                std::abs(mb.locked - c.md.locked) / energyScale});
        branchDiff += mb.branch != c.md.branch;
        slidingDiff += rb.sliding != r.sliding;
        EXPECT_EQ(hb.contactRadius, c.h.contactRadius);
        EXPECT_EQ(mb.prevNormalForce, c.md.prevNormalForce);
        ++branches[static_cast<int>(c.md.branch)];
      }
    }
    std::printf("block of %d: %ld pair-steps (loading %ld, unloading %ld, reloading %ld), %ld to the scalar kernel "
                "(guard %ld, no capacity %ld); max |dF|/(mu N) %.1e, memory %.1e, energy/((mu N)^2/k0) %.1e; "
                "branch differs %ld, sliding differs %ld\n",
                count, steps, branches[0], branches[1], branches[2], flagged, guarded, noCapacity, worstForce,
                worstMemory, worstEnergy, branchDiff, slidingDiff);
    EXPECT_GT(guarded, 0) << "the paths should exercise the energy guard";
    EXPECT_GT(noCapacity, 0) << "and openings";
    EXPECT_GT(branches[1], steps / 20);
    EXPECT_GT(branches[2], steps / 20);
    EXPECT_LT(worstForce, 1e-12);
    EXPECT_LT(worstMemory, 1e-12);
    EXPECT_LT(worstEnergy, 1e-10);
    EXPECT_EQ(branchDiff, 0);
    EXPECT_EQ(slidingDiff, 0);
  }
}

namespace {
// One pair through the block (slot 0 of a one-pair block) and its caller's side, normal along z, dt = 1 s.
struct BlockContact {
  double G, mu;
  ContactHistory h;
  MdHistory md;
  kernels::MdBlock b{};
  BlockContact(double effShear, double friction, double a, double N) : G(effShear), mu(friction) {
    h.contactRadius = a;
    md.prevNormalForce = N;
  }
  kernels::MdSlotResult step(const Vec3& ds, double a, double N) {
    kernels::mdGather(b, 0, Vec3::UnitZ(), -ds, a, N, G, mu, h, md);
    b.count = 1;
    kernels::mindlinDeresiewiczBlock(b, 1.0);
    return kernels::mdScatter(b, 0, 1.0, h, md);
  }
};
// the scalar kernel tests' contact: G* 8 GPa, a 0.1 mm, N 100 N, mu 0.3 (names of their own: CI's sanitizer
// build compiles the tests as a unity build, where mindlin_deresiewicz_test.cpp's kG etc. share the scope)
constexpr double kBlockG = 8e9, kBlockA = 1e-4, kBlockN = 100.0, kBlockMu = 0.3;
}  // namespace

TEST(MdBlockLaw, MonotonicLoadingAndAMasingCycleFollowTheClosedForms) {
  const double ds = kernels::mdSlipDisplacement(kBlockG, kBlockA, kBlockMu, kBlockN), muN = kBlockMu * kBlockN;
  const int perDs = 20000;
  const double dd = ds / perDs;
  // monotonic loading: T = mu N [1 - (1 - d/ds)^(3/2)] up to ds, mu N beyond (Johnson 1985 eq. 7.40)
  {
    BlockContact c(kBlockG, kBlockMu, kBlockA, kBlockN);
    double maxErr = 0.0;
    for (int k = 1; k <= 3 * perDs / 2; ++k) {
      const auto r = c.step(Vec3(dd, 0, 0), kBlockA, kBlockN);
      const double d = k * dd;
      if (d <= ds) maxErr = std::max(maxErr, std::abs(r.force.x() - muN * (1 - std::pow(1 - d / ds, 1.5))) / muN);
      if (d >= 1.05 * ds) {
        ASSERT_NEAR(r.force.x(), muN, 1e-12 * muN);
        ASSERT_TRUE(r.sliding);
      }
    }
    EXPECT_LT(maxErr, 5e-5);  // the scalar kernel: 1.4e-5 at this increment
  }
  // a cycle of amplitude d* = 0.5 ds after loading to d*: the loop area and the ledger's dissipation equal
  // 9 (mu N)^2/(10 a G*) [1 - (1-q)^(5/3) - (5q/6)(1 + (1-q)^(2/3))], q = T*/(mu N) (Johnson 1985 eq. 7.60)
  {
    BlockContact c(kBlockG, kBlockMu, kBlockA, kBlockN);
    const int n = perDs / 2;
    for (int k = 0; k < n; ++k) c.step(Vec3(dd, 0, 0), kBlockA, kBlockN);
    const double q = 1 - std::pow(0.5, 1.5);  // T*/(mu N) at d* = ds/2
    double area = 0.0, dissipated = 0.0;
    for (int cycle = 0; cycle < 2; ++cycle)
      for (int half = 0; half < 2; ++half)
        for (int k = 0; k < 2 * n; ++k) {
          const double sign = half == 0 ? -1.0 : 1.0, before = c.h.tangentialForce.x();
          const auto r = c.step(Vec3(sign * dd, 0, 0), kBlockA, kBlockN);
          if (cycle == 1) {
            area += 0.5 * (before + r.force.x()) * sign * dd;
            dissipated += r.dissipated;
          }
        }
    const double closed = 9 * muN * muN / (10 * kBlockA * kBlockG) *
                          (1 - std::pow(1 - q, 5.0 / 3.0) - 5 * q / 6 * (1 + std::pow(1 - q, 2.0 / 3.0)));
    std::printf("block law, cycle d* = ds/2: loop area %.6e J, closed form %.6e J, ledger %.6e J\n", area, closed,
                dissipated);
    EXPECT_NEAR(area / closed, 1.0, 1e-4);
    EXPECT_NEAR(dissipated / area, 1.0, 1e-9);
  }
}
