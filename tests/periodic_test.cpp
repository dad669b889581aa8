// Periodic cell (verification ladder §2): a pair touching only through the periodic image behaves
// exactly like the same pair inside the cell, including the image-shift velocity L·H·n under a
// deforming (even sheared) cell; wrapping; exact volume preservation for a trace-free L.
#include <gtest/gtest.h>

#include "test_support.hpp"

using namespace fl;

namespace {

struct PairRun {
  Vec3 branch, relVel, force, w1, w2;
};

PairRun runPair(const Vec3& x1, const Vec3& d, const Mat3& L, int steps) {
  const Material m = Material::paperGlass();
  NumericsSettings num;
  num.timeStep = 2e-8;
  num.restitution = 0.8;
  const double box = 0.01, R = 1e-3;
  ParticleStore p;
  Vec3 x2 = x1 + d;
  p.add(x1, R, m.density, 0);
  p.add(x2, 0.8 * R, m.density, 0);
  p.vel[0] = Vec3(0.01, -0.02, 0.005);
  p.vel[1] = Vec3(-0.01, 0.01, 0.0);
  p.angVel[0] = Vec3(3, 1, -2);
  p.angVel[1] = Vec3(-1, 4, 0.5);
  Simulation sim(std::move(p), PeriodicCell::box(box, box, box), {m}, num);
  sim.setVelocityGradient(L);
  sim.run(steps);
  const auto& c = sim.contacts();
  EXPECT_EQ(c.activeCount(), 1u);
  PairRun r{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  for (std::size_t k = 0; k < c.size(); ++k)
    if (c.active(k)) {
      r.branch = c.branch(k, sim.particles(), sim.cell());
      r.force = c.result[k].force;
    }
  r.relVel = sim.particles().vel[1] - sim.particles().vel[0];
  r.w1 = sim.particles().angVel[0];
  r.w2 = sim.particles().angVel[1];
  return r;
}

void expectClose(const Vec3& a, const Vec3& b, double rel) {
  EXPECT_LE((a - b).norm(), rel * std::max(a.norm(), 1e-30)) << a.transpose() << " vs " << b.transpose();
}

}  // namespace

TEST(PeriodicImage, PairAcrossTheBoundaryEqualsPairInside) {
  const Vec3 d = 1.79999e-3 * Vec3(1, 0.02, 0.005).normalized();  // just touching (R1 + R2 = 1.8 mm)
  Mat3 L = Mat3::Zero();
  L(0, 0) = -2.0;
  L(1, 1) = 0.5;
  L(2, 2) = 1.5;
  L(0, 1) = 0.7;  // a shear component: the maths is general
  const int steps = 250;  // within the ~11 us contact
  const PairRun inside = runPair(Vec3(4e-3, 5e-3, 5e-3), d, L, steps);
  const PairRun across = runPair(Vec3(9.2e-3, 9.95e-3, 5e-3), d, L, steps);  // x2 wraps in x and y
  EXPECT_GT(inside.force.norm(), 0.0);
  expectClose(across.branch, inside.branch, 1e-9);
  expectClose(across.force, inside.force, 1e-7);
  expectClose(across.relVel, inside.relVel, 1e-7);
  expectClose(across.w1, inside.w1, 1e-7);
  expectClose(across.w2, inside.w2, 1e-7);
}

TEST(PeriodicImage, ShiftVelocityIsLTimesHTimesN) {
  PeriodicCell cell = PeriodicCell::box(2, 3, 4);
  Mat3 L = Mat3::Zero();
  L(0, 0) = 0.5;
  L(0, 2) = 0.25;
  cell.setVelocityGradient(L);
  const Vec3i n(1, -1, 1);
  EXPECT_TRUE(cell.shift(n).isApprox(Vec3(2, -3, 4)));
  EXPECT_TRUE(cell.shiftVelocity(n).isApprox(Vec3(0.5 * 2 + 0.25 * 4, 0, 0)));
}

TEST(PeriodicCellTest, WrapReturnsTheImageAndLandsInside) {
  PeriodicCell cell = PeriodicCell::box(1, 2, 3);
  Vec3 x(1.5, -0.5, 7.0);
  const Vec3i k = cell.wrap(x);
  EXPECT_EQ(k, Vec3i(1, -1, 2));
  EXPECT_TRUE(x.isApprox(Vec3(0.5, 1.5, 1.0)));
}

TEST(PeriodicCellTest, TraceFreeDiagonalStrainRatePreservesVolumeToRoundOff) {
  PeriodicCell cell = PeriodicCell::box(0.01, 0.01, 0.01);
  const double V0 = cell.volume();
  Mat3 L = Mat3::Zero();
  L(2, 2) = -1.0;
  L(0, 0) = L(1, 1) = 0.5;
  cell.setVelocityGradient(L);
  for (int k = 0; k < 100000; ++k) cell.advance(1e-6);
  EXPECT_NEAR(cell.volume() / V0, 1.0, 1e-12);
  EXPECT_NEAR(cell.matrix()(2, 2) / (0.01 * std::exp(-0.1)), 1.0, 1e-12);
}

TEST(PeriodicCellTest, PerpendicularWidthsOfASkewedCell) {
  Mat3 H;
  H << 1, 0.5, 0, 0, 1, 0, 0, 0, 1;
  PeriodicCell cell(H);
  // shearing the second vector along x keeps the planes x = const at distance 1/|row0(H^-1)|
  const Vec3 w = cell.perpendicularWidths();
  EXPECT_NEAR(w.y(), 1.0, 1e-15);
  EXPECT_NEAR(w.x(), 1.0 / std::sqrt(1.25), 1e-12);
}
