// The contact diagnostics and the elastic energies, which the default law's pass leaves to be read off the
// stored contacts when asked for (Simulation::measureContacts): against Hertz–Mindlin closed forms for one
// pressed pair, and the same bits whether they are read every step or once at the end (reading them never
// changes the run) or after a restart.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "core/binary_io.hpp"
#include "core/simulation.hpp"
#include "test_support.hpp"

using namespace fl;

namespace {

// Two glass spheres of radii r1 < r2 overlapping by delta, the second sliding past the first at vt (along y).
struct PressedPair {
  double r1 = 5e-4, r2 = 7e-4, delta = 2e-6, vt = 1e-3;
  Material m = Material::paperGlass();
  TangentialModel model = TangentialModel::MindlinNoSlip;
  Simulation make() const {
    NumericsSettings num;
    num.timeStep = 1e-8;  // short enough that the pair barely moves in a step
    num.tangentialModel = model;
    const Vec3 x1(0.005, 0.005, 0.005), x2 = x1 + Vec3(r1 + r2 - delta, 0, 0);
    return test::twoSpheres(r1, r2, x1, x2, Vec3::Zero(), Vec3(0, vt, 0), m, num, 0.01);
  }
};

TEST(Diagnostics, PressedPairAgainstClosedForms) {
  // both tangential laws: the default law's measures are read off the stored contacts, the
  // Mindlin–Deresiewicz pass sums its own (at this tiny tangential displacement the two laws agree)
  for (const TangentialModel model : {TangentialModel::MindlinNoSlip, TangentialModel::MindlinDeresiewicz}) {
    SCOPED_TRACE(static_cast<int>(model));
    PressedPair pp;
    pp.model = model;
    Simulation sim = pp.make();
    sim.step();  // the construction's pass and one step load the tangential spring: |F_t| = 2 k_t v_t dt
    ASSERT_EQ(sim.contacts().activeCount(), 1u);
    const PairResult& q = sim.contacts().result[0];
    const double delta = q.overlap;  // after the step's drift (moves it by ~1e-22 m)
    ASSERT_NEAR(delta, pp.delta, 1e-12);
    const double Es = test::effYoung(pp.m, pp.m);
    const double Gs = 1.0 / (2.0 * (2.0 - pp.m.poissonRatio) / pp.m.shearModulus());
    const double Rs = pp.r1 * pp.r2 / (pp.r1 + pp.r2);
    const double a = std::sqrt(Rs * delta);
    const double fn = 4.0 / 3.0 * Es * std::sqrt(Rs) * std::pow(delta, 1.5);  // Hertz
    const double kn = 2.0 * Es * a, kt = 8.0 * Gs * a;                          // Hertz, Mindlin
    const double m1 = pp.m.density * 4.0 / 3.0 * kPi * std::pow(pp.r1, 3);
    const double m2 = pp.m.density * 4.0 / 3.0 * kPi * std::pow(pp.r2, 3);
    const double ft = 2.0 * kt * pp.vt * sim.timeStep();  // two increments of the spring (barely rotated)
    const ContactDiagnostics& d = sim.diagnostics();
    EXPECT_EQ(d.contacts, 1u);
    EXPECT_EQ(d.sliding, 0u);
    EXPECT_NEAR(d.maxOverlapRatio, delta / pp.r1, 1e-12 * delta / pp.r1);
    EXPECT_NEAR(d.maxStiffnessOverMass, std::max(kn, 3.5 * kt) * (1 / m1 + 1 / m2), 1e-9 * kt / m1);
    EXPECT_NEAR(d.meanContactForce, std::hypot(fn, ft), 1e-9 * fn);
    EXPECT_NEAR(sim.stiffnessTimeStep(), 2.0 / std::sqrt(std::max(kn, 3.5 * kt) * (1 / m1 + 1 / m2)), 1e-9 * 1e-7);
    const EnergyLedger& e = sim.energy();
    EXPECT_NEAR(e.elasticNormal, 8.0 / 15.0 * Es * std::sqrt(Rs) * std::pow(delta, 2.5), 1e-9 * fn * delta);
    // the Mindlin–Deresiewicz law adds the micro-slip energy locked at |F_t| / (mu N) ~ 1e-4 (its pass sums the
    // measures itself: kernels::mdBlockMeasures)
    const double tol = pp.model == TangentialModel::MindlinNoSlip ? 1e-6 : 1e-3;
    EXPECT_NEAR(e.elasticTangential, ft * ft / (2.0 * kt), tol * ft * ft / kt);
  }
}

Simulation compressedGas() {
  Packing pk = test::stirredGas(800, 0.4, 5, 9);
  NumericsSettings num;
  num.restitution = 0.7;
  Simulation sim(std::move(pk.particles), pk.cell, {Material::paperGlass()}, num);
  Mat3 L = Mat3::Zero();
  L.diagonal() = Vec3(-300, -300, -400);
  sim.setVelocityGradient(L);
  return sim;
}

bool sameBits(const ContactDiagnostics& a, const ContactDiagnostics& b) {
  return a.maxOverlapRatio == b.maxOverlapRatio && a.maxStiffnessOverMass == b.maxStiffnessOverMass &&
         a.meanContactForce == b.meanContactForce && a.contacts == b.contacts && a.sliding == b.sliding &&
         std::memcmp(a.axisStiffness.data(), b.axisStiffness.data(), sizeof(Vec3)) == 0;
}

TEST(Diagnostics, ReadingThemEveryStepChangesNothing) {
  Simulation every = compressedGas(), once = compressedGas();
  double maxOverlap = 0.0;
  for (int k = 0; k < 3000; ++k) {
    every.step();
    maxOverlap = std::max(maxOverlap, every.diagnostics().maxOverlapRatio);
    (void)every.energy();
    (void)every.unbalancedForceRatio();
  }
  once.run(3000);
  ASSERT_GT(once.contacts().activeCount(), 300u) << "the test must exercise many contacts";
  EXPECT_GT(maxOverlap, 0.0);
  EXPECT_TRUE(test::sameBits(every.particles().pos, once.particles().pos));
  EXPECT_TRUE(test::sameBits(every.particles().vel, once.particles().vel));
  EXPECT_TRUE(test::sameBits(every.contacts().history, once.contacts().history));
  EXPECT_TRUE(sameBits(every.diagnostics(), once.diagnostics()));
  EXPECT_EQ(every.energy().balance(), once.energy().balance());
  EXPECT_GT(once.energy().elasticNormal, 0.0);
  EXPECT_GT(once.energy().elasticTangential, 0.0);
}

TEST(Diagnostics, SurviveACheckpoint) {
  Simulation sim = compressedGas();
  sim.run(2000);
  BinaryWriter w;
  sim.saveState(w);  // without a read since the last step: the state holds them measured
  BinaryReader r(w.bytes(), "test");
  Simulation back = Simulation::restoreState(r);
  EXPECT_TRUE(sameBits(sim.diagnostics(), back.diagnostics()));
  EXPECT_EQ(sim.energy().elasticNormal, back.energy().elasticNormal);
  EXPECT_EQ(sim.energy().elasticTangential, back.energy().elasticTangential);
}

}  // namespace
