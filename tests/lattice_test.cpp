// Exact lattices (verification ladder §2): SC and FCC under isotropic strain give the closed-form
// Love–Weber stress within 0.5 %, with contacts crossing the periodic boundary; uniaxial strain of SC
// gives zero lateral stress; porosity and coordination number.
#include <gtest/gtest.h>

#include <cmath>

#include "test_support.hpp"

using namespace fl;

namespace {

enum class Lattice { SC, FCC };

// Lattice of touching spheres (radius R), n unit cells per side.
Simulation touchingLattice(Lattice type, int n, double R, const Material& m) {
  ParticleStore p;
  double a = 0;
  std::vector<Vec3> basis;
  if (type == Lattice::SC) {
    a = 2 * R;
    basis = {Vec3(0, 0, 0)};
  } else {
    a = 2 * std::sqrt(2.0) * R;  // nearest neighbours at a / sqrt(2) = 2R
    basis = {Vec3(0, 0, 0), Vec3(0.5, 0.5, 0), Vec3(0.5, 0, 0.5), Vec3(0, 0.5, 0.5)};
  }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const Vec3& b : basis) p.add(a * (Vec3(i + 0.25, j + 0.25, k + 0.25) + b), R, m.density, 0);
  NumericsSettings num;
  num.timeStepFactor = 0.2;
  num.skin = 0.2 * R;
  return Simulation(std::move(p), PeriodicCell::box(n * a, n * a, n * a), {m}, num);
}

// Strain the cell by eps along the axes flagged in `axes` through the velocity gradient, in `steps` steps.
double strainCell(Simulation& sim, const Vec3& axes, double eps, int steps) {
  const double T = steps * sim.timeStep();
  const double rate = std::log(1.0 - eps) / T;  // exp(rate T) = 1 - eps
  Mat3 L = Mat3::Zero();
  for (int k = 0; k < 3; ++k) L(k, k) = axes[k] * rate;
  sim.setVelocityGradient(L);
  sim.run(steps);
  sim.setVelocityGradient(Mat3::Zero());
  return eps;
}

}  // namespace

TEST(Lattice, SimpleCubicIsotropicStrainMatchesClosedForm) {
  const Material m = Material::paperGlass();
  const double R = 0.55e-3;
  Simulation sim = touchingLattice(Lattice::SC, 4, R, m);
  const double eps = 5.520e-4;  // the ladder's strain for 318 kPa
  strainCell(sim, Vec3(1, 1, 1), eps, 2000);
  const double expected = m.youngModulus * std::pow(eps, 1.5) / (3 * (1 - m.poissonRatio * m.poissonRatio));
  const Mat3& s = sim.contactStress();
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(s(k, k) / expected, 1.0, 0.005);
  EXPECT_NEAR(expected, 318e3, 1e3);  // ladder: SC at eps 5.520e-4 is 318 kPa for the paper's glass
  EXPECT_NEAR(std::abs(s(0, 1)) + std::abs(s(0, 2)) + std::abs(s(1, 2)), 0.0, 1e-6 * expected);
  // coordination 6, every particle has contacts across the boundary on its outer layer
  EXPECT_EQ(sim.contacts().activeCount(), 3u * sim.particles().size());
  // porosity of the touching lattice: 1 - pi/6 (evaluated on the unstrained geometry)
  const double V = std::pow(4 * 2 * R, 3);
  EXPECT_NEAR(1 - sim.particles().solidVolume() / V, 1 - kPi / 6, 1e-12);
}

TEST(Lattice, FaceCentredCubicIsotropicStrainMatchesClosedForm) {
  const Material m = Material::paperGlass();
  const double R = 0.4e-3;
  Simulation sim = touchingLattice(Lattice::FCC, 3, R, m);
  const double eps = 2.760e-4;
  strainCell(sim, Vec3(1, 1, 1), eps, 2000);
  const double expected =
      4.0 / 3.0 * m.youngModulus * std::pow(eps, 1.5) / (std::sqrt(2.0) * (1 - m.poissonRatio * m.poissonRatio));
  const Mat3& s = sim.contactStress();
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(s(k, k) / expected, 1.0, 0.005);
  EXPECT_NEAR(expected, 318e3, 1e3);
  EXPECT_EQ(sim.contacts().activeCount(), 6u * sim.particles().size());  // Z = 12
  const double a = 2 * std::sqrt(2.0) * R;
  EXPECT_NEAR(1 - sim.particles().solidVolume() / std::pow(3 * a, 3), 0.2595, 1e-4);
}

TEST(Lattice, UniaxialStrainOfSimpleCubicGivesNoLateralStress) {
  const Material m = Material::paperGlass();
  Simulation sim = touchingLattice(Lattice::SC, 4, 0.5e-3, m);
  strainCell(sim, Vec3(0, 0, 1), 1e-3, 1000);
  const Mat3& s = sim.contactStress();
  EXPECT_GT(s(2, 2), 1e5);
  EXPECT_LT(std::abs(s(0, 0)), 1e-9 * s(2, 2));
  EXPECT_LT(std::abs(s(1, 1)), 1e-9 * s(2, 2));
  EXPECT_EQ(sim.contacts().activeCount(), sim.particles().size());  // only the vertical contacts
}
