// A state of Simulation::kLargeStateFrom particles or more takes the step's large-state path: every partner
// and result line prefetched, and the contact pass's result lines written by streaming stores
// (core/streaming_store.hpp). The benchmark's scaling sizes run on it, the other tests' small scenes do not.
// Checked here: the stores write PairResult's fields, the path computes the small path's forces (a packing
// replicated 2 x 2 x 2 feels, particle by particle, what the packing itself feels), and it gives the same bits
// on 1 to 3 threads (the kick's threads read lines another thread streamed).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/simulation.hpp"
#include "core/streaming_store.hpp"
#include "test_support.hpp"

using namespace fl;

namespace {

struct Frozen {
  ParticleStore particles;
  Mat3 H;
};

// The determinism tests' compressed gas, frozen after 6000 steps: its particles and cell (the replicas are rebuilt
// from position, radius and velocities: plain masses, no history).
Frozen compressedPacking() {
  Simulation sim = test::compressingGas(1, 0.05, 1.0);
  sim.run(6000);
  return {sim.particles(), sim.cell().matrix()};
}

// The packing's particles copied k x k x k times along the cell's edges, replica by replica (particle i of
// replica r at index r n + i).
ParticleStore replicated(const Frozen& f, int k) {
  const ParticleStore& src = f.particles;
  const double density = Material::paperGlass().density;
  ParticleStore p;
  for (int a = 0; a < k; ++a)
    for (int b = 0; b < k; ++b)
      for (int c = 0; c < k; ++c) {
        const Vec3 shift = f.H * Vec3(a, b, c);
        for (std::size_t i = 0; i < src.size(); ++i) {
          p.add(src.pos[i] + shift, src.radius[i], density, src.material[i]);
          p.vel.back() = src.vel[i];
          p.angVel.back() = src.angVel[i];
        }
      }
  return p;
}

Simulation build(const Frozen& f, int k, int threads) {
  NumericsSettings num;
  num.threads = threads;
  num.timeStep = 2e-8;  // the same step for both sizes (the Rayleigh step is per particle anyway)
  return Simulation(replicated(f, k), PeriodicCell(f.H * static_cast<double>(k)), {Material::paperGlass()}, num);
}

}  // namespace

TEST(StreamingStore, WritesTheLineInPairResultsOrderAndNothingElse) {
  std::vector<PairResult> r(3);
  const double line[8] = {1.5, -2.5, 3.5, 4.25, -5.25, 6.25, 7e-6, 8.0};
  streamLine(&r[1], line);
  streamFence();
  EXPECT_EQ(r[1].force, Vec3(1.5, -2.5, 3.5));
  EXPECT_EQ(r[1].moment, Vec3(4.25, -5.25, 6.25));
  EXPECT_EQ(r[1].overlap, 7e-6);
  EXPECT_EQ(r[1].normalForce, 8.0);
  for (int k : {0, 2}) {
    EXPECT_EQ(r[k].force, Vec3::Zero());
    EXPECT_EQ(r[k].moment, Vec3::Zero());
    EXPECT_EQ(r[k].overlap, 0.0);
    EXPECT_EQ(r[k].normalForce, 0.0);
  }
}

// The large-state path computes the physics of the small one: each replica of a periodic packing, in a cell
// twice as large along each edge, feels the packing's own contact forces and torques (to rounding: positions
// shifted by a cell edge round differently), and the stress is the same.
TEST(LargeState, AReplicatedPackingFeelsThePackingsOwnForces) {
  const Frozen f = compressedPacking();
  Simulation small = build(f, 1, 1), large = build(f, 2, 1);
  const std::size_t n = small.particles().size();
  ASSERT_LT(n, Simulation::kLargeStateFrom) << "the small packing must take the small-state path";
  ASSERT_GE(large.particles().size(), Simulation::kLargeStateFrom) << "the replicas must take the large-state path";
  small.run(20);
  large.run(20);
  ASSERT_GT(small.contacts().activeCount(), 2 * n) << "the test must exercise many contacts";
  EXPECT_EQ(large.contacts().activeCount(), 8 * small.contacts().activeCount());
  const ParticleStore& s = small.particles();
  const ParticleStore& l = large.particles();
  double meanForce = 0.0, meanTorque = 0.0;
  for (std::size_t i = 0; i < n; ++i) meanForce += s.force[i].norm() / n, meanTorque += s.torque[i].norm() / n;
  ASSERT_GT(meanForce, 0.0);
  double worstF = 0.0, worstT = 0.0, worstV = 0.0;
  for (std::size_t r = 0; r < 8; ++r)
    for (std::size_t i = 0; i < n; ++i) {
      worstF = std::max(worstF, (l.force[r * n + i] - s.force[i]).norm() / meanForce);
      worstT = std::max(worstT, (l.torque[r * n + i] - s.torque[i]).norm() / meanTorque);
      worstV = std::max(worstV, (l.vel[r * n + i] - s.vel[i]).norm());
    }
  EXPECT_LT(worstF, 1e-10);  // 2.4e-12 seen
  EXPECT_LT(worstT, 1e-10);  // 3.3e-12 seen
  EXPECT_LT(worstV, 1e-9);    // [m/s], 4.9e-11 seen
  const double p = small.contactStress().trace() / 3.0;
  EXPECT_NEAR(large.contactStress().trace() / 3.0 / p, 1.0, 1e-9);
  EXPECT_LT((large.contactStress() - small.contactStress()).norm() / std::abs(p), 1e-9);
}

// The kick's threads read result lines that another thread streamed in the pass: the same bits on 1 to 3
// threads, as on the small path (determinism_test.cpp).
TEST(LargeState, OneToThreeThreadsGiveIdenticalBits) {
  const Frozen f = compressedPacking();
  Simulation a = build(f, 2, 1);
  a.run(100);
  ASSERT_GT(a.contacts().activeCount(), 16000u) << "the test must exercise many contacts";
  for (int threads : {2, 3}) {
    SCOPED_TRACE(threads);
    Simulation b = build(f, 2, threads);
    b.run(100);
    EXPECT_FALSE(b.threadBoundary().exchange) << "a large state reads every partner in place (no halo)";
    test::expectSameBits(a, b);
  }
}
