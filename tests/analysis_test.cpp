// Measures and the per-cycle analysis on inputs with known answers: fabric of exact lattices and of
// sampled axisymmetric distributions, Z and Zm with rattlers, pore pressure identity, and synthetic
// tau–gamma loops.
#include <gtest/gtest.h>

#include <cmath>

#include "core/cycle_analysis.hpp"
#include "core/measurements.hpp"
#include "core/rng.hpp"
#include "core/simulation.hpp"

using namespace fl;

TEST(FabricMeasures, IsotropicAndUniaxialExtremes) {
  // SC lattice normals: phi = I/3, a = 0 in both definitions
  const FabricMeasures sc = fabricFromNormals({Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()});
  EXPECT_NEAR((sc.tensor - Mat3::Identity() / 3).norm(), 0.0, 1e-15);
  EXPECT_NEAR(sc.anisotropy3D, 0.0, 1e-15);
  EXPECT_NEAR(sc.anisotropy2D, 0.0, 1e-15);
  EXPECT_NEAR(sc.tensor.trace(), 1.0, 1e-15);
  // all normals vertical: phi_zz = 1 -> a_3D = 5/2; projected 2D fabric has lambda = (1, 0) -> a_2D = 2
  const FabricMeasures z = fabricFromNormals({Vec3::UnitZ(), -Vec3::UnitZ()});
  EXPECT_NEAR(z.anisotropy3D, 2.5, 1e-15);
  EXPECT_NEAR(z.anisotropy2D, 2.0, 1e-15);
  EXPECT_NEAR(z.direction2D, 0.0, 1e-12);
}

TEST(FabricMeasures, RecoversTheAnisotropyOfSampledDistributions) {
  Rng rng(3);
  // 3D: E(n) = (1/4pi)[1 + a (3 cos^2 theta - 1)], rejection sampling
  const double a = 0.2;
  std::vector<Vec3> n3;
  while (n3.size() < 400000) {
    const double z = rng.uniform(-1, 1), ph = rng.uniform(0, 2 * kPi);
    if (rng.uniform() * (1 + 2 * a) > 1 + a * (3 * z * z - 1)) continue;
    const double s = std::sqrt(1 - z * z);
    n3.push_back(Vec3(s * std::cos(ph), s * std::sin(ph), z));
  }
  EXPECT_NEAR(fabricFromNormals(n3).anisotropy3D, a, 0.01);
  // 2D (normals in the x-z plane): E(theta) = (1/2pi)[1 + a cos 2 theta], theta from vertical
  std::vector<Vec3> n2;
  while (n2.size() < 400000) {
    const double th = rng.uniform(0, 2 * kPi);
    if (rng.uniform() * (1 + a) > 1 + a * std::cos(2 * th)) continue;
    n2.push_back(Vec3(std::sin(th), 0, std::cos(th)));
  }
  // a_2D averages the x-z and y-z projections: the x-z plane carries a, and the y-z projection of
  // normals lying in the x-z plane is purely vertical (a = 2 exactly), so the average is (a + 2) / 2
  EXPECT_NEAR(fabricFromNormals(n2).anisotropy2D, (a + 2.0) / 2.0, 0.01);
  // an isotropic 3D set gives a_2D = a_3D = 0
  std::vector<Vec3> iso;
  while (iso.size() < 200000) {
    const Vec3 v(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    if (v.squaredNorm() <= 1 && v.squaredNorm() > 1e-6) iso.push_back(v.normalized());
  }
  EXPECT_NEAR(fabricFromNormals(iso).anisotropy2D, 0.0, 0.01);
  EXPECT_NEAR(fabricFromNormals(iso).anisotropy3D, 0.0, 0.01);
}

TEST(ContactCountsTest, MechanicalCoordinationExcludesRattlers) {
  // three spheres in a row touching (1-2, 2-3) plus one isolated: C = 2, N = 4, N0 = 1, N1 = 2
  ParticleStore p;
  const double r = 1e-3;
  p.add(Vec3(2e-3, 5e-3, 5e-3), r, 2500, 0);
  p.add(Vec3(3.99e-3, 5e-3, 5e-3), r, 2500, 0);
  p.add(Vec3(5.98e-3, 5e-3, 5e-3), r, 2500, 0);
  p.add(Vec3(5e-3, 5e-3, 8.5e-3), r, 2500, 0);
  Simulation sim(std::move(p), PeriodicCell::box(12e-3, 12e-3, 12e-3), {Material::paperGlass()}, NumericsSettings{});
  const ContactCounts c = contactCounts(sim);
  EXPECT_EQ(c.contacts, 2u);
  EXPECT_EQ(c.rattlers0, 1u);
  EXPECT_EQ(c.rattlers1, 2u);
  EXPECT_DOUBLE_EQ(c.coordination, 2.0 * 2 / 4);
  EXPECT_DOUBLE_EQ(c.mechanicalCoordination, (2.0 * 2 - 2) / (4 - 1 - 2));
}

TEST(StressMeasuresTest, InvariantsAndPorePressureIdentity) {
  Mat3 s = Mat3::Zero();
  s.diagonal() = Vec3(100e3, 100e3, 250e3);
  const StressMeasures m = stressMeasures(s);
  EXPECT_DOUBLE_EQ(m.p, 150e3);
  EXPECT_DOUBLE_EQ(m.q, 150e3);
  EXPECT_DOUBLE_EQ(m.tau, 75e3);
  // du = sigma'3,0 - sigma'3 equals dp_total - dp' with dp_total = dq/3 (constant cell pressure)
  Mat3 s1 = Mat3::Zero();
  s1.diagonal() = Vec3(80e3, 80e3, 260e3);
  const StressMeasures m1 = stressMeasures(s1);
  EXPECT_NEAR(m.lateral - m1.lateral, (m1.q - m.q) / 3 - (m1.p - m.p), 1e-9);
}

TEST(CycleAnalysisTest, EllipticLoopGivesKnownStiffnessAndDamping) {
  // tau = G gamma_a sin(wt + phi): G_sec = tau_a / gamma_a, D = sin(phi) / 2
  const double G = 200e6, ga = 3e-4, phi = 0.2;
  CycleAnalyzer an(318e3, FailureCriteria{});
  const int n = 4000;
  CycleRecord r;
  for (int cyc = 1; cyc <= 2; ++cyc) {
    for (int k = (cyc == 1 ? 0 : 1); k <= n; ++k) {
      const double t = 2 * kPi * k / n;
      an.add({ga * std::sin(t), G * ga * std::sin(t + phi), 1.5 * ga * std::sin(t), 2 * G * ga * std::sin(t + phi), 318e3, 0});
    }
    r = an.close(cyc, {});
  }
  EXPECT_NEAR(r.Gsec / G, 1.0, 1e-4);
  EXPECT_NEAR(r.damping, std::sin(phi) / 2, 1e-4);
  EXPECT_NEAR(r.Esec, 2 * G / 1.5, 1e-3 * G);
  EXPECT_FALSE(r.failed);
}

TEST(CycleAnalysisTest, FailureFlagByPressureOrStiffnessLoss) {
  CycleAnalyzer an(300e3, FailureCriteria{0.2, 0.2});
  auto cycle = [&](int c, double G, double pmin) {
    for (int k = 0; k <= 40; ++k) {
      const double t = 2 * kPi * k / 40;
      an.add({1e-4 * std::sin(t), G * 1e-4 * std::sin(t), 0, 0, k == 20 ? pmin : 300e3, 0});
    }
    return an.close(c, {});
  };
  EXPECT_FALSE(cycle(1, 200e6, 290e3).failed);
  EXPECT_FALSE(cycle(2, 100e6, 100e3).failed);
  EXPECT_TRUE(cycle(3, 100e6, 50e3).failed);   // p'_min < 0.2 p'_0
  EXPECT_TRUE(cycle(4, 30e6, 290e3).failed);   // G_sec < 0.2 G_sec,1
}
