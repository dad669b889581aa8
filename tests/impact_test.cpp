// Two-particle impacts (verification ladder §1): Chung & Ooi (2011) test 1 peak overlap, peak force and
// contact time against Hertz's closed forms; exit speed = entry speed without damping; oblique impact in
// gross sliding against the rigid-body limit; energy never gained; momentum conserved. Also: a sliding pair's
// force follows its own materials' E* and friction, and a friction changed during the run.
#include <gtest/gtest.h>

#include <cmath>

#include "test_support.hpp"

using namespace fl;

namespace {

struct ImpactResult {
  double maxOverlap = 0, maxForce = 0, contactTime = 0;
  Vec3 normalAtPeak = Vec3::UnitX();  // contact normal at maximum compression
  Vec3 v1, v2, w1, w2;
  double keBefore = 0, keAfter = 0;
  Vec3 pBefore, pAfter, angBefore, angAfter;
};

Vec3 angularMomentum(const ParticleStore& p) {
  Vec3 L = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) L += p.pos[i].cross(p.vel[i]) / p.invMass[i] + p.angVel[i] / p.invInertia[i];
  return L;
}

ImpactResult collide(const Material& m, double R, const Vec3& v1, const Vec3& v2, double dt, double restitution = 1.0) {
  NumericsSettings num;
  num.timeStep = dt;
  num.restitution = restitution;
  const Vec3 x1(0.5, 0.5, 0.5);
  const Vec3 x2 = x1 + Vec3(2 * R + 1e-6, 0, 0);
  Simulation sim = test::twoSpheres(R, R, x1, x2, v1, v2, m, num);
  ImpactResult r;
  r.keBefore = sim.energy().kinetic;
  r.pBefore = test::momentum(sim.particles());
  r.angBefore = angularMomentum(sim.particles());
  bool touched = false;
  for (long k = 0; k < 10'000'000; ++k) {
    sim.step();
    const auto& c = sim.contacts();
    double ov = 0;
    Vec3 n = Vec3::UnitX();
    for (std::size_t p = 0; p < c.size(); ++p)
      if (c.active(p)) {
        ov = c.result[p].overlap;
        n = c.normal(p, sim.particles(), sim.cell());
        r.maxForce = std::max(r.maxForce, c.result[p].normalForce);
      }
    if (ov > 0) {
      touched = true;
      r.contactTime += dt;
      if (ov > r.maxOverlap) r.normalAtPeak = n;
      r.maxOverlap = std::max(r.maxOverlap, ov);
    } else if (touched) {
      break;
    }
  }
  const auto& p = sim.particles();
  r.v1 = p.vel[0];
  r.v2 = p.vel[1];
  r.w1 = p.angVel[0];
  r.w2 = p.angVel[1];
  r.keAfter = sim.energy().kinetic;
  r.pAfter = test::momentum(p);
  r.angAfter = angularMomentum(p);
  return r;
}

void chungOoiTest1(const Material& m) {
  // two identical spheres R = 10 mm at +-10 m/s: relative approach speed v = 20 m/s
  const double R = 0.01, v = 20.0;
  const double Es = test::effYoung(m, m), Rs = R / 2;
  const double mass = m.density * 4.0 / 3.0 * kPi * R * R * R, ms = mass / 2;
  const double dmax = std::pow(15 * ms * v * v / (16 * Es * std::sqrt(Rs)), 0.4);
  const double fmax = 4.0 / 3.0 * Es * std::sqrt(Rs) * std::pow(dmax, 1.5);
  const double tc = 2.868 * std::pow(ms * ms / (Rs * Es * Es * v), 0.2);
  const ImpactResult r = collide(m, R, Vec3(10, 0, 0), Vec3(-10, 0, 0), tc / 4000);
  EXPECT_NEAR(r.maxOverlap / dmax, 1.0, 0.01);
  EXPECT_NEAR(r.maxForce / fmax, 1.0, 0.01);
  EXPECT_NEAR(r.contactTime / tc, 1.0, 0.01);
  // elastic: exit speed equals entry speed
  EXPECT_NEAR(r.v1.x(), -10.0, 1e-4);
  EXPECT_NEAR(r.v2.x(), 10.0, 1e-4);
  EXPECT_NEAR((r.pAfter - r.pBefore).norm(), 0.0, 1e-15);
}

}  // namespace

TEST(ChungOoiTest1, GlassSpheresMatchHertzWithinOnePercent) {
  // E 48 GPa, nu 0.20, rho 2800 (the ladder quotes delta 274.1 um, F 10.70 kN, tc 40.3 us)
  chungOoiTest1(Material{"glass", 48e9, 0.20, 2800, 0.0});
}

TEST(ChungOoiTest1, LimestoneSpheresMatchHertzWithinOnePercent) {
  // E 20 GPa, nu 0.25, rho 2500 (368.3 um, 7.11 kN, 54.2 us)
  chungOoiTest1(Material{"limestone", 20e9, 0.25, 2500, 0.0});
}

TEST(ChungOoiTest1, QuotedNumbersFollowFromTheFormulas) {
  // guards the formulas used above against the ladder's quoted values
  const Material m{"glass", 48e9, 0.20, 2800, 0.0};
  const double R = 0.01, v = 20.0, Es = test::effYoung(m, m), Rs = R / 2;
  const double ms = m.density * 4.0 / 3.0 * kPi * R * R * R / 2;
  const double dmax = std::pow(15 * ms * v * v / (16 * Es * std::sqrt(Rs)), 0.4);
  EXPECT_NEAR(dmax, 274.1e-6, 0.5e-6);
  EXPECT_NEAR(4.0 / 3.0 * Es * std::sqrt(Rs) * std::pow(dmax, 1.5), 10.70e3, 0.02e3);
  EXPECT_NEAR(2.868 * std::pow(ms * ms / (Rs * Es * Es * v), 0.2), 40.3e-6, 0.1e-6);
}

TEST(ObliqueImpact, GrossSlidingFollowsTheRigidBodyLimit) {
  // identical spheres, relative normal speed Vn, tangential Vt; sliding throughout when
  // tan(theta) = Vt/Vn > 3.5 mu (1 + e). Then Vt'/Vt = 1 - mu (1 + e) / tan(theta).
  const Material m{"glass", 70e9, 0.22, 2500, 0.3};
  const double R = 0.005, Vn = 0.01, tanTheta = 5.0, Vt = tanTheta * Vn;  // slow: the normal barely turns
  ASSERT_GT(tanTheta, 3.5 * m.friction * 2.0);
  const ImpactResult r = collide(m, R, Vec3(Vn / 2, -Vt / 2, 0), Vec3(-Vn / 2, Vt / 2, 0), 2e-8);
  // The line of centres turns by ~Vt tc / 2R (~0.015 rad) during contact; the rigid-body theory assumes a
  // fixed normal, so velocities are resolved in the frame of the normal at peak compression.
  const Vec3 n = r.normalAtPeak;
  const Vec3 t = (Vec3(0, 1, 0) - n.y() * n).normalized();
  const Vec3 before(-Vn, Vt, 0);
  const Vec3 after = r.v2 - r.v1;
  const double en = after.dot(n) / -before.dot(n);  // elastic Hertz: e = 1
  EXPECT_NEAR(en, 1.0, 1e-3);
  const double ratio = after.dot(t) / before.dot(t);
  EXPECT_NEAR(ratio, 1.0 - m.friction * (1.0 + en) / tanTheta, 2e-3);
  EXPECT_LE(r.keAfter, r.keBefore * (1 + 1e-9));
  EXPECT_NEAR((r.pAfter - r.pBefore).norm(), 0.0, 1e-15);
  EXPECT_NEAR((r.angAfter - r.angBefore).norm() / r.angBefore.norm(), 0.0, 1e-10);  // about the origin, 0.5 m away
}

TEST(ObliqueImpact, EnergyIsNeverGainedAtAnyAngle) {
  const Material m{"glass", 70e9, 0.22, 2500, 0.3};
  for (double restitution : {1.0, 0.7}) {
    for (int deg = 2; deg <= 88; deg += 6) {
      const double th = deg * kPi / 180.0;
      const Vec3 v(std::cos(th) / 2, -std::sin(th) / 2, 0.1);
      const ImpactResult r = collide(m, 0.005, v, -v, 2e-8, restitution);
      EXPECT_LE(r.keAfter, r.keBefore * (1 + 1e-6)) << "angle " << deg << " e " << restitution;
      EXPECT_NEAR((r.pAfter - r.pBefore).norm(), 0.0, 1e-15);
      EXPECT_NEAR((r.angAfter - r.angBefore).norm() / r.angBefore.norm(), 0.0, 1e-11);
    }
  }
}

TEST(ObliqueImpact, RestitutionSettingGivesThatNormalRestitution) {
  // the calibrated Tsuji damping gives the requested e, independent of speed, within 0.5 %
  const Material m{"glass", 70e9, 0.22, 2500, 0.0};
  for (double e : {0.9, 0.5, 0.2}) {
    for (double v : {0.1, 2.0}) {  // and independent of the impact speed
      const ImpactResult r = collide(m, 0.005, Vec3(v / 2, 0, 0), Vec3(-v / 2, 0, 0), 1e-8, e);
      EXPECT_NEAR((r.v2.x() - r.v1.x()) / v, e, 0.005 * e) << "e " << e << " v " << v;
    }
  }
}

// The force pass reads each pair's parameters from the pair table when the scene has several materials,
// and writes the one pair's parameters into its blocks once per pass when it has one (contact_pass.cpp):
// both must give Hertz with that pair's E* and cap F_t at that pair's current friction.
namespace {
// Spheres of radius R overlapping by delta along x, the second sliding along y at 10 m/s (gross sliding in
// the first pass: the spring's first increment is several times mu F_n).
Simulation slidingPair(const std::vector<Material>& materials, int matA, int matB, double R, double delta) {
  ParticleStore p;
  const Vec3 x1(0.5, 0.5, 0.5);
  p.add(x1, R, materials[matA].density, matA);
  p.add(x1 + Vec3(2 * R - delta, 0, 0), R, materials[matB].density, matB);
  p.vel[1] = Vec3(0, 10, 0);
  NumericsSettings num;
  num.timeStep = 1e-7;
  return Simulation(std::move(p), PeriodicCell::box(1, 1, 1), materials, num);
}
void expectHertzAtCap(const Simulation& sim, double effYoung, double R, double mu) {
  const PairResult& c = sim.contacts().result.at(0);
  ASSERT_GT(c.overlap, 0.0);
  const double a = std::sqrt(0.5 * R * c.overlap);
  EXPECT_NEAR(c.normalForce / (4.0 / 3.0 * effYoung * a * c.overlap), 1.0, 1e-12);
  const Vec3 ft = c.force - c.normalForce * sim.contacts().normal(0, sim.particles(), sim.cell());
  EXPECT_NEAR(ft.norm() / (mu * c.normalForce), 1.0, 1e-12);
}
}  // namespace

TEST(PairParameters, ForcePassUsesEachPairsMaterialsAndTheCurrentFriction) {
  const double R = 1e-3, delta = 1e-6;
  const Material a{"a", 70e9, 0.22, 2500, 0.3}, b{"b", 20e9, 0.25, 2500, 0.5};
  // two materials: the table's (a, b) entry, friction min(0.3, 0.5)
  Simulation ab = slidingPair({a, b}, 0, 1, R, delta);
  EXPECT_NEAR(ab.contacts().result.at(0).overlap, delta, 1e-15);
  expectHertzAtCap(ab, test::effYoung(a, b), R, 0.3);
  Simulation bb = slidingPair({a, b}, 1, 1, R, delta);
  expectHertzAtCap(bb, test::effYoung(b, b), R, 0.5);
  // one material, its friction changed during the run: the next pass caps at the new value
  Simulation one = slidingPair({b}, 0, 0, R, delta);
  expectHertzAtCap(one, test::effYoung(b, b), R, 0.5);
  one.setFriction(0.1);
  one.step();
  expectHertzAtCap(one, test::effYoung(b, b), R, 0.1);
}
