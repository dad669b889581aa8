// The Mindlin–Deresiewicz tangential law (core/mindlin_deresiewicz.hpp, docs/contact-laws.md):
//  - the kernel alone against closed forms at constant N (Mindlin & Deresiewicz 1953; Johnson 1985 §7.4):
//    monotonic loading, Masing unloading/reloading branches, loop area per cycle, no-slip and sliding limits;
//  - energy never gained on random 3D paths with a varying normal force;
//  - oblique impacts of two spheres through the Simulation with both laws (Chung & Ooi 2011, test 4 shape);
//  - selection from the scene, checkpoint round trip (and reading state version 2), 1 vs 2 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include <nlohmann/json.hpp>

#include "core/binary_io.hpp"
#include "core/contact_kernels.hpp"
#include "core/errors.hpp"
#include "core/measurements.hpp"
#include "core/mindlin_deresiewicz.hpp"
#include "core/runner.hpp"
#include "core/scene.hpp"
#include "test_support.hpp"

using namespace fl;
using nlohmann::json;

namespace {

// One contact driven by prescribed tangential displacement increments (normal fixed along z). It starts
// as after a normal loading to N at zero tangential displacement: radius a, previous normal force N.
struct DrivenContact {
  double effShear, mu;
  Vec3 n = Vec3::UnitZ();
  ContactHistory h;
  MdHistory md;
  DrivenContact(double G, double friction, double a, double N) : effShear(G), mu(friction) {
    h.contactRadius = a;
    md.prevNormalForce = N;
  }
  // ds: increment in the force-direction convention (dF = +k ds); dt = 1 s so that v_t = -ds.
  kernels::MdResult step(const Vec3& ds, double a, double N) {
    return kernels::mindlinDeresiewicz(n, -ds, a, N, effShear, mu, 1.0, h, md);
  }
};

// Closed forms at constant N (Mindlin & Deresiewicz 1953; Johnson 1985 §7.4), with
// delta_s = 3 mu N / (16 G* a) the displacement at gross sliding.
double loadingCurve(double d, double muN, double ds) {
  return muN * (1.0 - std::pow(1.0 - std::min(d / ds, 1.0), 1.5));
}
// Masing branches of a cycle of amplitude d* (force T* at d*): unloading from d*, reloading from -d*.
double unloadingBranch(double d, double dStar, double tStar, double muN, double ds) {
  return tStar - 2.0 * muN * (1.0 - std::pow(1.0 - (dStar - d) / (2.0 * ds), 1.5));
}
double reloadingBranch(double d, double dStar, double tStar, double muN, double ds) {
  return -tStar + 2.0 * muN * (1.0 - std::pow(1.0 - (dStar + d) / (2.0 * ds), 1.5));
}
// Energy dissipated per cycle (loop area), Mindlin & Deresiewicz 1953 / Johnson 1985 eq. 7.60 written with
// the pair's 1/G* = (2-nu1)/G1 + (2-nu2)/G2: 9 (mu N)^2/(10 a G*) [1 - (1-q)^(5/3) - (5q/6)(1 + (1-q)^(2/3))],
// q = T*/(mu N).
double loopArea(double tStar, double muN, double a, double G) {
  const double q = tStar / muN;
  return 9.0 * muN * muN / (10.0 * a * G) *
         (1.0 - std::pow(1.0 - q, 5.0 / 3.0) - 5.0 * q / 6.0 * (1.0 + std::pow(1.0 - q, 2.0 / 3.0)));
}

// the kernel tests' contact: G* 8 GPa, a 0.1 mm, N 100 N, mu 0.3 -> k0 = 6.4 MN/m, delta_s = 7.03 um
constexpr double kG = 8e9, kA = 1e-4, kN = 100.0, kMu = 0.3;
double slipDisplacement() { return kernels::mdSlipDisplacement(kG, kA, kMu, kN); }

}  // namespace

TEST(MindlinDeresiewiczKernel, MonotonicLoadingConvergesToTheClosedForm) {
  const double ds = slipDisplacement(), muN = kMu * kN;
  EXPECT_NEAR(ds, 3 * muN / (16 * kG * kA), 1e-20);
  double err[2];
  int run = 0;
  for (int steps : {2000, 20000}) {  // increments of delta_s/2000 and delta_s/20000, up to 1.5 delta_s
    DrivenContact c(kG, kMu, kA, kN);
    const double dd = ds / steps;
    double maxErr = 0.0;
    for (int k = 1; k <= 3 * steps / 2; ++k) {
      const auto r = c.step(Vec3(dd, 0, 0), kA, kN);
      const double d = k * dd;
      ASSERT_EQ(r.force.y(), 0.0);
      if (k == 1) {
        EXPECT_EQ(r.tangentStiffness, 8 * kG * kA);  // the first increment is Mindlin's no-slip one
      }
      if (d <= ds) maxErr = std::max(maxErr, std::abs(r.force.x() - loadingCurve(d, muN, ds)) / muN);
      if (d >= 1.05 * ds) {
        EXPECT_NEAR(r.force.x(), muN, 1e-12 * muN) << "d/ds " << d / ds;
        EXPECT_TRUE(r.sliding);
      }
      EXPECT_FALSE(r.guarded);
    }
    err[run++] = maxErr;
  }
  std::printf("monotonic loading: max |T - T_closed|/(mu N) = %.2e (ds/2000), %.2e (ds/20000)\n", err[0], err[1]);
  EXPECT_LT(err[1], 5e-5);        // measured 1.4e-5
  EXPECT_LT(err[1], err[0] / 5);  // first order: 10x finer increments, ~10x smaller error
}

TEST(MindlinDeresiewiczKernel, CyclesFollowMasingBranchesAndDissipateTheLoopArea) {
  const double ds = slipDisplacement(), muN = kMu * kN;
  for (double amplitude : {0.3, 0.8}) {  // d*/delta_s
    DrivenContact c(kG, kMu, kA, kN);
    const int perDs = 20000;
    const double dd = ds / perDs, dStar = amplitude * ds;
    const int nHalf = static_cast<int>(std::lround(2 * dStar / dd));
    const double tStar = loadingCurve(dStar, muN, ds);
    double d = 0.0, branchErr = 0.0;
    for (int k = 0; k < nHalf / 2; ++k) {
      c.step(Vec3(dd, 0, 0), kA, kN);
      d += dd;
    }
    double area = 0.0, dissipated = 0.0, storedStart = 0.0, storedEnd = 0.0;
    for (int cycle = 0; cycle < 3; ++cycle) {
      if (cycle == 1) storedStart = c.h.tangentialForce.squaredNorm() / (16 * kG * kA) + c.md.locked;
      for (int half = 0; half < 2; ++half) {
        const double sign = half == 0 ? -1.0 : 1.0;
        for (int k = 0; k < nHalf; ++k) {
          const double before = c.h.tangentialForce.x();
          const auto r = c.step(Vec3(sign * dd, 0, 0), kA, kN);
          d += sign * dd;
          EXPECT_FALSE(r.guarded);
          EXPECT_GE(r.microSlipWork + r.slipWork, 0.0);
          const double expected = half == 0 ? unloadingBranch(d, dStar, tStar, muN, ds)
                                            : reloadingBranch(d, dStar, tStar, muN, ds);
          branchErr = std::max(branchErr, std::abs(r.force.x() - expected) / muN);
          if (cycle == 1) {
            area += 0.5 * (before + r.force.x()) * sign * dd;
            dissipated += r.microSlipWork + r.slipWork;
          }
        }
      }
      if (cycle == 1) storedEnd = c.h.tangentialForce.squaredNorm() / (16 * kG * kA) + c.md.locked;
    }
    const double closed = loopArea(tStar, muN, kA, kG);
    std::printf("cycle d*/ds = %.1f: branch error %.2e mu N; loop area %.6e J, closed form %.6e J (%.2e), "
                "ledger %.6e J (%.2e)\n",
                amplitude, branchErr, area, closed, area / closed - 1, dissipated, dissipated / area - 1);
    EXPECT_LT(branchErr, 1e-4);              // measured 5.6e-6 (0.3), 1.4e-5 (0.8)
    EXPECT_NEAR(area / closed, 1.0, 1e-4);   // measured 6e-7, 5e-6
    EXPECT_NEAR(dissipated / area, 1.0, 1e-9);  // the ledger's micro-slip work over a closed cycle
    EXPECT_NEAR(storedEnd / storedStart, 1.0, 1e-6);
  }
}

TEST(MindlinDeresiewiczKernel, LoopAreaClosedFormMatchesTheMasingBranchesIntegral) {
  // guards the formula used above: integrate the two closed-form branches (midpoint rule)
  const double ds = slipDisplacement(), muN = kMu * kN;
  for (double amplitude : {0.05, 0.5, 0.95}) {
    const double dStar = amplitude * ds, tStar = loadingCurve(dStar, muN, ds);
    const int n = 200000;
    const double h = 2 * dStar / n;
    double area = 0;
    for (int k = 0; k < n; ++k) {
      const double d = -dStar + (k + 0.5) * h;
      area += (reloadingBranch(d, dStar, tStar, muN, ds) - unloadingBranch(d, dStar, tStar, muN, ds)) * h;
    }
    EXPECT_NEAR(area / loopArea(tStar, muN, kA, kG), 1.0, 1e-8) << amplitude;
  }
}

TEST(MindlinDeresiewiczKernel, TinyDisplacementsMatchTheNoSlipLaw) {
  // delta << delta_s: theta -> 1, k_t -> 8 G* a; the micro-slip correction is of relative order delta/delta_s
  const double ds = slipDisplacement();
  DrivenContact c(kG, kMu, kA, kN);
  ContactHistory ns;
  ns.contactRadius = kA;
  const double dd = 1e-3 * ds / 1000;
  double maxRel = 0, peak = 0;
  for (int k = 0; k < 4000; ++k) {
    const double sign = (k < 1000 || k >= 3000) ? 1.0 : -1.0;  // up to 1e-3 ds, down to -1e-3 ds, back to 0
    const Vec3 inc(sign * dd, 0.3 * sign * dd, 0);             // a direction off the axes
    const auto r = c.step(inc, kA, kN);
    const auto q = kernels::mindlinNoSlip(c.n, -inc, kA, kMu * kN, kG, kMu, 1.0, ns);
    peak = std::max(peak, q.force.norm());
    maxRel = std::max(maxRel, (r.force - q.force).norm());
  }
  maxRel /= peak;
  std::printf("no-slip limit (|delta| <= 1e-3 delta_s): max |F_MD - F_noslip| / max|F| = %.2e\n", maxRel);
  // closed form: T = k0 d (1 - d/(4 ds) + ...) on loading, 2.5e-4 below the no-slip force at d = 1e-3 ds
  EXPECT_LT(maxRel, 5e-4);
  EXPECT_GT(maxRel, 1e-4);  // and not the same law: the micro-slip is there
}

TEST(MindlinDeresiewiczKernel, SlidingLimitHasForceMuNAndTheRightDissipation) {
  const double ds = slipDisplacement(), muN = kMu * kN, k0 = 8 * kG * kA;
  DrivenContact c(kG, kMu, kA, kN);
  const int perDs = 20000;
  const double dd = ds / perDs;
  double work = 0, workToDs = 0, dissipated = 0;
  for (int k = 1; k <= 3 * perDs; ++k) {
    const double before = c.h.tangentialForce.x();
    const auto r = c.step(Vec3(dd, 0, 0), kA, kN);
    work += 0.5 * (before + r.force.x()) * dd;
    if (k == perDs) workToDs = work;
    dissipated += r.microSlipWork + r.slipWork;
    if (k > 1.1 * perDs) {
      ASSERT_NEAR(r.force.x(), muN, 1e-12 * muN);
      ASSERT_TRUE(r.sliding);
      ASSERT_NEAR(r.slipWork, muN * dd, 1e-9 * muN * dd);  // gross sliding dissipates mu N per unit slip
    }
  }
  // work along the loading curve up to delta_s: int_0^ds mu N [1 - (1 - d/ds)^1.5] dd = (3/5) mu N ds
  EXPECT_NEAR(workToDs / (0.6 * muN * ds), 1.0, 1e-4);  // measured 1.4e-5
  // stored at gross sliding: (mu N)^2/(2 k0) elastic + (mu N)^2/(10 k0) locked (Iwan form, see the kernel)
  EXPECT_NEAR(c.md.locked / (muN * muN / (10 * k0)), 1.0, 1e-9);
  // dissipated: 0.2 mu N ds during loading (Iwan form) + mu N per unit of gross slip
  const double expected = 0.2 * muN * ds + muN * (3 * ds - ds);
  std::printf("sliding: work to ds %.6e J (closed 0.6 mu N ds = %.6e J); dissipated %.6e J (closed %.6e J)\n",
              workToDs, 0.6 * muN * ds, dissipated, expected);
  EXPECT_NEAR(dissipated / expected, 1.0, 1e-4);  // measured 3.9e-6
  EXPECT_NEAR(work, dissipated + 0.6 * muN * muN / k0, 1e-9 * work);  // nothing lost from the ledger
}

TEST(MindlinDeresiewiczKernel, EnergyIsNeverGainedOnRandomPathsWithVaryingNormalForce) {
  long guarded = 0, steps = 0, opened = 0;
  double maxCreatedRatio = 0;
  for (std::uint64_t seed : {1u, 2u, 3u, 4u}) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const bool rotate = seed % 2 == 0;  // half the paths also turn the contact normal
    double N = kN, a = kA;
    DrivenContact c(kG, kMu, a, N);
    double angle = 0, workIn = 0, dissipated = 0, created = 0, turnover = 0;
    const double e0 = 0.0;
    for (int k = 0; k < 20000; ++k, ++steps) {
      // normal force: random walk, occasionally dropping to zero (the contact opens) or jumping up
      const double x = U(rng);
      if (x < 0.002) N = 0.0;
      else if (N == 0.0) N = kN * (0.05 + U(rng));
      else N *= std::exp(0.08 * (U(rng) - 0.5));
      N = std::min(N, 5 * kN);
      a = kA * std::cbrt(N / kN);  // Hertz: N ~ a^3
      // tangential increment: a wandering direction with frequent reversals, up to 4 % of delta_s(N)
      angle += 0.3 * (U(rng) - 0.5);
      const double sign = U(rng) < 0.3 ? -1.0 : 1.0;
      const double mag = 0.04 * kernels::mdSlipDisplacement(kG, kA, kMu, std::max(N, 0.05 * kN)) * U(rng);
      if (rotate) {  // small rotation of the normal about a random axis
        const Vec3 axis = Vec3(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5).normalized();
        c.n = Eigen::AngleAxisd(2e-3 * U(rng), axis) * c.n;
        c.n.normalize();
      }
      Vec3 t1 = c.n.unitOrthogonal(), t2 = c.n.cross(t1);
      const Vec3 inc = sign * mag * (std::cos(angle) * t1 + std::sin(angle) * t2);
      Vec3 before = c.h.tangentialForce;
      before -= before.dot(c.n) * c.n;  // the force the particles felt, in the new tangent plane
      if (c.h.tangentialForce.squaredNorm() > 0 && before.squaredNorm() > 0)
        before *= c.h.tangentialForce.norm() / before.norm();
      if (N == 0.0) ++opened;
      const auto r = c.step(inc, a, N);
      const double W = 0.5 * (before + r.force).dot(inc);  // trapezoid, independent of the kernel's own
      // round-off relative to the two terms, not to W: they can nearly cancel (reversals), and the
      // kernel's own sum may be contracted into FMAs differently at another optimisation level
      const double scale = 0.5 * (std::abs(before.dot(inc)) + std::abs(r.force.dot(inc)));
      ASSERT_NEAR(W, r.work, 1e-12 * scale + 1e-300);
      workIn += W;
      turnover += std::abs(W);
      dissipated += r.slipWork + r.microSlipWork;
      created += r.createdEnergy;
      guarded += r.guarded;
      ASSERT_GE(r.slipWork, 0.0);
      ASSERT_GE(r.microSlipWork, 0.0);
      ASSERT_GE(c.md.locked, 0.0);
      ASSERT_LE(r.force.norm(), kMu * N * (1 + 1e-12) + 1e-300);
      const double stored = r.storedEnergy;
      const double elastic = a > 0 ? r.force.squaredNorm() / (16 * kG * a) : 0.0;
      EXPECT_NEAR(stored, elastic + c.md.locked, 1e-12 * stored + 1e-300);
      // energy never gained: what was put in covers what is stored (up to the reported deficit)
      ASSERT_GE(workIn + created + 1e-12 * turnover, stored - e0) << "step " << k << " seed " << seed;
      // and the ledger is closed: work in = stored + dissipated - created
      ASSERT_NEAR(workIn, stored - e0 + dissipated - created, 1e-9 * turnover) << "step " << k;
    }
    maxCreatedRatio = std::max(maxCreatedRatio, created / turnover);
  }
  std::printf("random paths: %ld steps, %ld with N = 0, guard engaged in %ld, max created/turnover %.2e\n", steps,
              opened, guarded, maxCreatedRatio);
  EXPECT_GT(guarded, 0) << "the paths should exercise the energy guard";
  EXPECT_LT(maxCreatedRatio, 1e-9);
}

// ---- oblique impacts through the Simulation (Chung & Ooi 2011, test 4 shape) ------------------------
namespace {
struct Rebound {
  double vtRatio = 0;     // contact-point tangential velocity after / before [-]
  double spin = 0;        // rebound spin of sphere 1 about z, times R / v_n [-]
  double en = 0;          // normal restitution [-]
  double keRatio = 0;     // kinetic energy after / before [-]
};

// Two identical spheres, relative normal speed vn along x (sphere 2 to 1), relative tangential speed vt along y.
Rebound obliqueImpact(TangentialModel model, double tanTheta, const Material& m, double R, double vn, double dt) {
  NumericsSettings num;
  num.timeStep = dt;
  num.tangentialModel = model;
  const double vt = tanTheta * vn;
  const Vec3 x1(0.5, 0.5, 0.5), x2 = x1 + Vec3(2 * R + 1e-7, 0, 0);
  Simulation sim = test::twoSpheres(R, R, x1, x2, Vec3(vn / 2, -vt / 2, 0), Vec3(-vn / 2, vt / 2, 0), m, num);
  const double ke0 = sim.energy().kinetic;
  bool touched = false;
  double maxOverlap = 0;
  Vec3 n = Vec3::UnitX();  // the line of centres at maximum compression (it turns by ~1e-3 rad during contact)
  for (long k = 0; k < 10'000'000; ++k) {
    sim.step();
    const ContactStore& c = sim.contacts();
    bool active = false;
    for (std::size_t q = 0; q < c.size(); ++q)
      if (c.active(q)) {
        active = true;
        if (c.result[q].overlap > maxOverlap) {
          maxOverlap = c.result[q].overlap;
          n = c.normal(q, sim.particles(), sim.cell());
        }
      }
    if (active) touched = true;
    else if (touched) break;
  }
  const auto& p = sim.particles();
  const Vec3 t = (Vec3::UnitY() - n.y() * n).normalized();
  const Vec3 before = Vec3(-vn, vt, 0);  // v2 - v1, no spin
  const Vec3 vc = p.vel[1] - p.vel[0] - (R * p.angVel[1] + R * p.angVel[0]).cross(n);  // contact point, 2 vs 1
  Rebound r;
  r.vtRatio = vc.dot(t) / before.dot(t);
  r.spin = p.angVel[0].z() * R / vn;
  r.en = (p.vel[1] - p.vel[0]).dot(n) / -before.dot(n);
  r.keRatio = sim.energy().kinetic / ke0;
  return r;
}
}  // namespace

TEST(MindlinDeresiewiczImpact, ObliqueImpactsMatchRigidSlidingAndShowTangentialCompliance) {
  // glass spheres; Chung & Ooi (2011) test 4 impacts a sphere on a flat, here two identical spheres meet.
  // Rigid-body theory (identical spheres, no initial spin): the contact slip changes by 3.5 mu (1 + e) vn
  // while sliding, so the contact slides throughout when tan(theta) > 3.5 mu (1 + e); then the contact-point
  // tangential velocity ratio is 1 - 3.5 mu (1 + e)/tan(theta) and each sphere spins up by 1.25 mu (1 + e) vn/R.
  // Below that, a rigid contact would stick (ratio 0); an elastic one rebounds tangentially (Maw, Barber &
  // Fawcett 1976): the ratio swings positive at small angles and negative (reversal) in between.
  const Material m{"glass", 70e9, 0.22, 2500, 0.3};
  const double R = 0.005, vn = 0.01, dt = 2e-8;
  const double e = 1.0;                                 // elastic Hertz
  const double threshold = 3.5 * m.friction * (1 + e);  // tan(theta) beyond which the contact slides throughout
  std::printf("tan(theta)/thr  vt'/vt(no-slip)  vt'/vt(MD)   rigid  |  w R/vn(no-slip)  w R/vn(MD)  rigid\n");
  for (double f : {0.002, 0.01, 0.05, 0.2, 0.5, 0.8, 1.0, 1.3, 2.0}) {
    const double tanTheta = f * threshold;
    const Rebound ns = obliqueImpact(TangentialModel::MindlinNoSlip, tanTheta, m, R, vn, dt);
    const Rebound md = obliqueImpact(TangentialModel::MindlinDeresiewicz, tanTheta, m, R, vn, dt);
    // rigid body: sliding throughout (f >= 1), or sticking (contact slip 0, spin tan(theta)/2.8)
    const double rigidVt = f >= 1 ? 1.0 - threshold / tanTheta : 0.0;
    const double rigidSpin = f >= 1 ? 1.25 * m.friction * (1 + e) : tanTheta / 2.8;
    std::printf("%14.3f  %15.4f  %10.4f  %6.3f  |  %15.4f  %10.4f  %5.3f\n", f, ns.vtRatio, md.vtRatio, rigidVt,
                ns.spin, md.spin, rigidSpin);
    for (const Rebound* r : {&ns, &md}) {
      EXPECT_NEAR(r->en, 1.0, 2e-3);
      EXPECT_LE(r->keRatio, 1.0 + 1e-6) << "energy gained at tan(theta) = " << tanTheta;
      // angular momentum about the contact: each sphere's spin is (1 - ratio) tan(theta)/2.8 (any tangential law)
      EXPECT_NEAR(r->spin, (1 - r->vtRatio) * tanTheta / 2.8, 0.01 * (1 - r->vtRatio) * tanTheta / 2.8 + 1e-6) << f;
      if (f >= 1.3) {  // sliding throughout: both laws follow the rigid-body closed form
        EXPECT_NEAR(r->vtRatio, rigidVt, 0.01) << f;
        EXPECT_NEAR(r->spin / rigidSpin, 1.0, 0.01) << f;
      }
      if (f <= 0.01) {  // tangential compliance: elastic tangential rebound, not the rigid stick (ratio 0)
        EXPECT_GT(r->vtRatio, 0.4) << f;
      }
      if (f == 0.5) {  // ... and a reversal of the contact slip at intermediate angles
        EXPECT_LT(r->vtRatio, -0.1) << f;
      }
    }
    if (f >= 1.3) {
      EXPECT_NEAR(md.vtRatio, ns.vtRatio, 0.005);
    }
  }
}

// ---- selection, restart, determinism --------------------------------------------------------------------
TEST(MindlinDeresiewiczScene, SelectedByNameRunsAndRejectsUnknownNames) {
  json j = json::parse(R"({
    "name": "md scene",
    "specimen": {"count": 150, "solid_fraction": 0.3, "seed": 4},
    "numerics": {"time_step_factor": 0.3, "local_damping": 0.1, "density_scale": 100, "threads": 1,
                 "tangential_model": "mindlin_deresiewicz"},
    "servo": {"max_strain_rate": 20, "max_inertial_number": 0.02, "unbalanced_tolerance": 0.02},
    "stages": [{"type": "isotropic_compression", "pressure": 50000, "max_steps": 200000}]
  })");
  const Scene s = parseScene(j, "md.json");
  EXPECT_EQ(s.numerics.tangentialModel, TangentialModel::MindlinDeresiewicz);
  EXPECT_EQ(parseScene(json::parse(sceneToJson(s)), "again.json").numerics.tangentialModel,
            TangentialModel::MindlinDeresiewicz);
  EXPECT_EQ(parseScene(json::parse(R"({"stages": []})"), "d.json").numerics.tangentialModel,
            TangentialModel::MindlinNoSlip);
  Runner r(s);
  while (r.advance(5000)) {
  }
  const Simulation& sim = r.simulation();
  EXPECT_EQ(sim.numerics().tangentialModel, TangentialModel::MindlinDeresiewicz);
  EXPECT_EQ(sim.contacts().mdHistory.size(), sim.contacts().size());
  EXPECT_GT(sim.contacts().activeCount(), 100u);
  EXPECT_NEAR(stressMeasures(sim.contactStress()).p / 50000, 1.0, 2e-3);
  // an unknown name is an input error naming the field and the allowed values
  j["numerics"]["tangential_model"] = "mindlin";
  try {
    parseScene(j, "md.json");
    ADD_FAILURE() << "accepted an unknown tangential model";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const char* f :
         {"md.json", "numerics.tangential_model", "\"mindlin\"", "mindlin_no_slip", "mindlin_deresiewicz"})
      EXPECT_NE(msg.find(f), std::string::npos) << "missing '" << f << "' in: " << msg;
  }
}

namespace {
// The shared compressing gas with the given tangential law, threads and restitution.
Simulation compressedGas(int count, TangentialModel model, int threads, double restitution) {
  NumericsSettings num;
  num.threads = threads;
  num.restitution = restitution;
  num.localDamping = 0.05;
  num.tangentialModel = model;
  return test::compressingGasWith(count, num);
}
}  // namespace

TEST(MindlinDeresiewiczSimulation, OneAndTwoThreadsGiveIdenticalBits) {
  Simulation a = compressedGas(1200, TangentialModel::MindlinDeresiewicz, 1, 0.5);
  Simulation b = compressedGas(1200, TangentialModel::MindlinDeresiewicz, 2, 0.5);
  a.run(4000);
  b.run(4000);
  ASSERT_GT(a.contacts().activeCount(), 800u);
  ASSERT_GT(a.profile().rebuilds, 2);
  EXPECT_TRUE(test::sameBits(a.particles().pos, b.particles().pos));
  EXPECT_TRUE(test::sameBits(a.particles().vel, b.particles().vel));
  EXPECT_TRUE(test::sameBits(a.particles().angVel, b.particles().angVel));
  EXPECT_TRUE(test::sameBits(a.contacts().history, b.contacts().history));
  EXPECT_TRUE(test::sameBits(a.contacts().mdHistory, b.contacts().mdHistory));
  EXPECT_EQ(a.energy().frictionWork, b.energy().frictionWork);
  EXPECT_EQ(a.energy().elasticTangential, b.energy().elasticTangential);
}

TEST(MindlinDeresiewiczSimulation, SaveReloadRunIsBitIdenticalToAnUnbrokenRun) {
  Simulation a = compressedGas(800, TangentialModel::MindlinDeresiewicz, 1, 0.6);
  a.setFriction(0.1);
  a.run(3000);
  BinaryWriter w;
  a.saveState(w);
  a.run(2000);
  BinaryReader r(w.bytes(), "memory");
  Simulation b = Simulation::restoreState(r);
  EXPECT_TRUE(r.atEnd());
  EXPECT_EQ(b.numerics().tangentialModel, TangentialModel::MindlinDeresiewicz);
  b.run(2000);
  ASSERT_GT(a.contacts().activeCount(), 500u);
  ASSERT_GT(a.profile().rebuilds, 0);
  EXPECT_TRUE(test::sameBits(a.particles().pos, b.particles().pos));
  EXPECT_TRUE(test::sameBits(a.particles().vel, b.particles().vel));
  EXPECT_TRUE(test::sameBits(a.particles().angVel, b.particles().angVel));
  EXPECT_TRUE(test::sameBits(a.contacts().history, b.contacts().history));
  EXPECT_TRUE(test::sameBits(a.contacts().mdHistory, b.contacts().mdHistory));
  EXPECT_EQ(a.energy().balance(), b.energy().balance());
}

TEST(MindlinDeresiewiczSimulation, StateVersion2IsStillRead) {
  // build the version-2 layout of a default-law state from today's bytes: version 2, numerics without the
  // tangential model (its first 56 bytes), no Mindlin–Deresiewicz history vector
  Simulation a = compressedGas(400, TangentialModel::MindlinNoSlip, 1, 1.0);
  a.run(1500);
  BinaryWriter w;
  a.saveState(w);
  std::string v3 = w.bytes();
  // version 5 added the steps since the last rebuild before the stresses, the ledger and the diagnostics; a
  // version-2 state restarts that clock at 0, so the newer state compared with it is given 0 too
  const std::size_t listStepsAt =
      v3.size() - 2 * sizeof(Mat3) - sizeof(EnergyLedger) - sizeof(ContactDiagnostics) - sizeof(long);
  const long zero = 0;
  std::memcpy(v3.data() + listStepsAt, &zero, sizeof zero);
  const ParticleStore& p = a.particles();
  const ContactStore& c = a.contacts();
  std::size_t off = 4 + 8;  // version, material count
  for (const Material& m : a.materials()) off += 8 + m.name.size() + 4 * sizeof(double);
  const std::size_t numericsAt = off;
  off += sizeof(NumericsSettings);
  const std::size_t n = p.size(), np = c.size();
  off += 5 * (8 + n * sizeof(Vec3)) + 3 * (8 + n * sizeof(double)) + (8 + n * sizeof(std::int32_t)) +
         (8 + n * sizeof(std::uint16_t)) + (8 + n * sizeof(Vec3i));  // particles
  off += 3 * sizeof(Mat3) + 2 * sizeof(Vec3);                              // cell
  off += 2 * (8 + np * sizeof(std::int32_t)) + (8 + np * sizeof(Image)) + (8 + np * sizeof(ContactHistory));
  std::uint64_t mdCount;
  std::memcpy(&mdCount, v3.data() + off, 8);
  ASSERT_EQ(mdCount, 0u) << "layout arithmetic";
  std::string v2 = v3.substr(0, numericsAt) + v3.substr(numericsAt, 56) +
                   v3.substr(numericsAt + sizeof(NumericsSettings), off - numericsAt - sizeof(NumericsSettings)) +
                   v3.substr(off + 8, listStepsAt - off - 8) + v3.substr(listStepsAt + sizeof(long));
  const std::uint32_t two = 2;
  std::memcpy(v2.data(), &two, 4);
  BinaryReader r2(v2, "v2"), r3(v3, "v3");
  Simulation b = Simulation::restoreState(r2), d = Simulation::restoreState(r3);
  EXPECT_TRUE(r2.atEnd());
  EXPECT_EQ(b.numerics().tangentialModel, TangentialModel::MindlinNoSlip);
  b.run(500);
  d.run(500);
  EXPECT_TRUE(test::sameBits(b.particles().pos, d.particles().pos));
  EXPECT_TRUE(test::sameBits(b.contacts().history, d.contacts().history));
}

TEST(MindlinDeresiewiczSimulation, DefaultLawKeepsNoExtraHistory) {
  Simulation a = compressedGas(400, TangentialModel::MindlinNoSlip, 1, 1.0);
  a.run(1500);
  ASSERT_GT(a.contacts().activeCount(), 0u);
  EXPECT_TRUE(a.contacts().mdHistory.empty());
  // switching law on a restored specimen (reconfigure) allocates it; switching back frees it and books the
  // locked micro-slip energy as dissipated
  NumericsSettings num = a.numerics();
  num.tangentialModel = TangentialModel::MindlinDeresiewicz;
  a.reconfigure(a.materials()[0], num);
  EXPECT_EQ(a.contacts().mdHistory.size(), a.contacts().size());
  a.run(300);
  ASSERT_GT(a.contacts().activeCount(), 0u);
  double locked = 0;
  for (const MdHistory& h : a.contacts().mdHistory) locked += h.locked;
  EXPECT_GT(locked, 0.0);
  const double friction = a.energy().frictionWork;
  num.tangentialModel = TangentialModel::MindlinNoSlip;
  a.reconfigure(a.materials()[0], num);
  EXPECT_TRUE(a.contacts().mdHistory.empty());
  EXPECT_NEAR(a.energy().frictionWork, friction + locked, 1e-12 * friction);
}
