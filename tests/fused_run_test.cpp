// Simulation::run(n) fuses each step's closing kick with the next step's drift (one sweep over the particles
// instead of two), stores the forces and torques only at the last step and keeps x and v in the contact pass's
// copy alone until then (a rebuild brings the store up to date first): it must give the bits of n calls of
// step(), with local damping and the energy ledger, a moving cell, neighbour rebuilds, a controller, either
// tangential law and any thread count, and however the steps are split into runs.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>

#include "core/cell_control.hpp"
#include "core/simulation.hpp"
#include "test_support.hpp"

using namespace fl;

// qualified names (test::): in the unity builds of CI's reliability pass this file shares one translation unit
// with others that declare their own helpers of the same names

namespace {
// Everything run() and step() touch beyond expectSameBits: the pass copy, the clock, the cell, the rebuilds
// and the energy ledger.
void expectSameRun(Simulation& a, Simulation& b) {
  test::expectSameBits(a, b);
  EXPECT_TRUE(test::sameBits(a.passParticles(), b.passParticles()));
  EXPECT_EQ(a.stepCount(), b.stepCount());
  EXPECT_EQ(a.time(), b.time());
  EXPECT_EQ(std::memcmp(a.cell().matrix().data(), b.cell().matrix().data(), sizeof(Mat3)), 0);
  EXPECT_EQ(a.profile().rebuilds, b.profile().rebuilds);
  EXPECT_EQ(a.profile().steps, b.profile().steps);
  test::expectSameEnergy(a, b);
}

void stepByStep(Simulation& sim, long steps) {
  for (long k = 0; k < steps; ++k) sim.step();
}
}  // namespace

// Local damping (whose sign the drift reads off the kicked velocity), energy tracking, a compressing cell and
// rebuilds; one thread, and three threads against one thread's steps.
TEST(FusedRun, RunGivesTheBitsOfStepByStep) {
  for (int threads : {1, 3}) {
    SCOPED_TRACE(threads);
    Simulation a = test::compressingGas(threads), b = test::compressingGas(1);
    a.run(3000);
    stepByStep(b, 3000);
    ASSERT_GT(a.contacts().activeCount(), 1000u) << "the test must exercise many contacts";
    ASSERT_GT(a.profile().rebuilds, 2) << "the test must exercise rebuilds between fused steps";
    ASSERT_GT(a.energy().localDampingWork, 0.0) << "the test must exercise the local damping";
    expectSameRun(a, b);
  }
}

// The steps split into runs of any length (one step, a run of two) give the same bits as one run.
TEST(FusedRun, HowTheStepsAreSplitIntoRunsChangesNoBit) {
  Simulation a = test::compressingGas(2, 0.0, 1.0, false), b = test::compressingGas(2, 0.0, 1.0, false);
  a.run(2500);
  b.run(1000);
  b.run(1);
  b.run(2);
  b.step();
  b.run(1496);
  b.run(0);
  ASSERT_GT(a.profile().rebuilds, 2);
  expectSameRun(a, b);
}

// A servo reads the pass's stress and stiffness before the kick (cell_controller.hpp), so its commands reach the
// next drift alike whether that drift is fused with the kick or not.
TEST(FusedRun, AControlledRunGivesTheBitsOfStepByStep) {
  auto controlled = [](int threads) {
    Simulation sim = test::compressingGas(threads);
    ServoSettings s;
    s.maxStrainRate = 1000.0;  // the gas must reach contact within the test's steps
    sim.setController(std::make_shared<AxisServo>(
        std::array<AxisControl, 3>{AxisControl{AxisMode::Stress, 2e5}, {AxisMode::StrainRate, 0.0},
                                   {AxisMode::MeanStress, 2e5}},
        s));
    return sim;
  };
  Simulation a = controlled(2), b = controlled(1);
  a.run(4000);
  stepByStep(b, 4000);
  ASSERT_GT(a.contacts().activeCount(), 500u);
  ASSERT_NE(a.cell().velocityGradient()(0, 0), 0.0) << "the servo must be moving the cell";
  expectSameRun(a, b);
}

// The Mindlin–Deresiewicz law's pass (no seeds) with contact damping.
TEST(FusedRun, MindlinDeresiewiczRunGivesTheBitsOfStepByStep) {
  NumericsSettings num;
  num.threads = 2;
  num.restitution = 0.5;
  num.localDamping = 0.05;
  num.tangentialModel = TangentialModel::MindlinDeresiewicz;
  Simulation a = test::compressingGasWith(1500, num);
  num.threads = 1;
  Simulation b = test::compressingGasWith(1500, num);
  a.run(3000);
  stepByStep(b, 3000);
  ASSERT_GT(a.contacts().activeCount(), 500u);
  expectSameRun(a, b);
  EXPECT_TRUE(test::sameBits(a.contacts().mdHistory, b.contacts().mdHistory));
}
