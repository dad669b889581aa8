// Contact-law kernels alone (verification ladder §1): Hertz force, Mindlin stiffness, stick -> slip at
// mu F_n with the spring rewritten, rotation of the spring into the tangent plane, unloading scaling.
#include <gtest/gtest.h>

#include <cmath>

#include "core/contact_kernels.hpp"
#include "core/errors.hpp"

using namespace fl;
using namespace fl::kernels;

TEST(HertzKernel, ForceStiffnessAndEnergyMatchClosedForm) {
  const double E = 3.0e10, R = 2e-3, delta = 1e-6;
  const double a = std::sqrt(R * delta);
  EXPECT_NEAR(hertzForce(E, a, delta), 4.0 / 3.0 * E * std::sqrt(R) * std::pow(delta, 1.5), 1e-9);
  // stiffness is dF/d delta: compare with a central difference
  const double h = 1e-12;
  const double fd = (hertzForce(E, std::sqrt(R * (delta + h)), delta + h) -
                     hertzForce(E, std::sqrt(R * (delta - h)), delta - h)) / (2 * h);
  EXPECT_NEAR(hertzStiffness(E, a) / fd, 1.0, 1e-6);
  // energy is the integral of the force: (8/15) E sqrt(R) delta^(5/2)
  EXPECT_NEAR(hertzEnergy(hertzForce(E, a, delta), delta), 8.0 / 15.0 * E * std::sqrt(R) * std::pow(delta, 2.5),
              1e-15);
}

TEST(MindlinKernel, SticksWithSlope8GaThenSlidesAtMuFn) {
  const double G = 1.2e10, mu = 0.3, a = 5e-5, Fn = 10.0, dt = 1e-6;
  const Vec3 n(0, 0, 1);
  const Vec3 vt(1e-3, 0, 0);  // tangential displacement 1e-9 m per step
  ContactHistory h;
  h.contactRadius = a;
  const double kt = 8 * G * a;
  int stepsToSlip = -1;
  for (int k = 1; k <= 2000; ++k) {
    auto r = mindlinNoSlip(n, vt, a, Fn, G, mu, dt, h);
    const double s = k * 1e-9;
    if (!r.sliding) {
      EXPECT_NEAR(r.force.x(), -kt * s, 1e-9 * kt * s);  // linear stick branch, k_t = 8 G* a
    } else {
      if (stepsToSlip < 0) stepsToSlip = k;
      EXPECT_NEAR(r.force.norm(), mu * Fn, 1e-12);  // capped at mu F_n
      EXPECT_NEAR(h.tangentialForce.norm(), mu * Fn, 1e-12);  // spring rewritten
      EXPECT_GT(r.slipWork, 0.0);
    }
  }
  // onset where kt s = mu Fn
  EXPECT_NEAR(stepsToSlip, std::ceil(mu * Fn / (kt * 1e-9)), 1.0);
}

TEST(MindlinKernel, SpringIsRotatedIntoTheNewTangentPlaneKeepingItsMagnitude) {
  ContactHistory h;
  h.tangentialForce = Vec3(2.0, 0, 0);
  h.contactRadius = 1e-5;
  const Vec3 n = Vec3(0.1, 0, 1).normalized();  // the contact normal has turned
  auto r = mindlinNoSlip(n, Vec3::Zero(), 1e-5, 100.0, 1e10, 0.5, 1e-7, h);
  EXPECT_NEAR(r.force.dot(n), 0.0, 1e-14);
  EXPECT_NEAR(r.force.norm(), 2.0, 1e-14);
}

TEST(MindlinKernel, UnloadingScalesTheSpringByTheContactRadiusRatio) {
  ContactHistory h;
  h.tangentialForce = Vec3(1.0, 0, 0);
  h.contactRadius = 2e-5;
  auto r = mindlinNoSlip(Vec3(0, 0, 1), Vec3::Zero(), 1e-5, 100.0, 1e10, 0.5, 1e-7, h);
  EXPECT_NEAR(r.force.x(), 0.5, 1e-15);
  // loading does not scale
  h.tangentialForce = Vec3(1.0, 0, 0);
  h.contactRadius = 1e-5;
  r = mindlinNoSlip(Vec3(0, 0, 1), Vec3::Zero(), 2e-5, 100.0, 1e10, 0.5, 1e-7, h);
  EXPECT_NEAR(r.force.x(), 1.0, 1e-15);
}

TEST(PairMixing, EffectiveModuliFollowTheHarmonicRules) {
  Material a{"a", 70e9, 0.22, 2500, 0.3}, b{"b", 20e9, 0.25, 2500, 0.5};
  PairTable t({a, b}, 1.0);
  EXPECT_NEAR(t(0, 1).effYoung, 1.0 / ((1 - 0.22 * 0.22) / 70e9 + (1 - 0.25 * 0.25) / 20e9), 1.0);
  EXPECT_NEAR(t(0, 1).effShear, 1.0 / ((2 - 0.22) / a.shearModulus() + (2 - 0.25) / b.shearModulus()), 1.0);
  EXPECT_DOUBLE_EQ(t(0, 1).friction, 0.3);
  EXPECT_DOUBLE_EQ(t(0, 0).dampingRatio, 0.0);
  // paper glass: E = 2 G (1 + nu) = 70.0 GPa
  EXPECT_NEAR(Material::paperGlass().youngModulus, 69.99872e9, 1e5);
  // damping ratio from restitution: zero for e = 1, growing as e falls (the e it gives is checked by
  // the impact tests); near the linear-spring value -ln e / sqrt(ln^2 e + pi^2) but not equal to it
  EXPECT_EQ(dampingRatioFromRestitution(1.0), 0.0);
  EXPECT_GT(dampingRatioFromRestitution(0.5), dampingRatioFromRestitution(0.9));
  const double linear = -std::log(0.5) / std::sqrt(std::pow(std::log(0.5), 2) + kPi * kPi);
  EXPECT_NEAR(dampingRatioFromRestitution(0.5) / linear, 1.0, 0.25);
  // the accepted range ends at kMinRestitution (a fuzzed checkpoint with e ~ 1e-300 searched for minutes)
  EXPECT_NEAR(dampingRatioFromRestitution(kMinRestitution), 4.807, 0.01);
  for (double e : {0.0099, 1e-300, 0.0, -0.5, 1.0001, std::nan("")})
    EXPECT_THROW(dampingRatioFromRestitution(e), InputError) << e;
}
