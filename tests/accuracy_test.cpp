// The accuracy-against-cost study (app/accuracy_study.hpp): the error metric, the Pareto front, the
// convergence check and the "cheapest setting" on synthetic data with exact expected values, then the
// --quick study end to end in a temporary folder (a few seconds on one core).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "app/accuracy_study.hpp"
#include "app/stability_study.hpp"

using namespace fl::accuracy;
namespace fs = std::filesystem;

namespace {

int lineCount(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

// A synthetic study: one inertial-number ladder {1e-3, 3e-4, 1e-4} with given G_sec and du per rung
// (two cycles each: the second cycle's value is the first plus 1), wall times 1, 3, 10 s.
StudyResult synthetic(const std::vector<double>& g, const std::vector<double>& du) {
  StudyResult r;
  r.config.base.inertialNumber = 1e-4;
  r.config.cycles = 2;
  r.config.convergenceTolerance = 0.005;
  r.config.target = 0.01;
  r.config.ladders = {{Factor::InertialNumber, {1e-3, 3e-4, 1e-4}}};
  const double walls[3] = {1, 3, 10};
  int id = 0;
  for (Drainage d : {Drainage::Undrained, Drainage::Drained}) {
    for (int k = 0; k < 3; ++k) {
      RunResult run;
      run.id = id++;
      run.settings = rungSettings(r.config, Factor::InertialNumber, r.config.ladders[0].values[k], 0);
      run.drainage = d;
      run.ok = true;
      run.wallSeconds = walls[k];
      run.particleSteps = static_cast<long>(walls[k] * 1e6);
      run.metrics.Gsec = {g[k], g[k] + 1};
      run.metrics.pReversal = {300, 310, 300, 310};
      run.metrics.qReversal = {60, -60, 60, -60};
      run.metrics.du = {du[k], du[k]};
      run.metrics.epsV = {1e-4, 2e-4};
      run.metrics.Z = {5.5, 5.5};
      run.metrics.a = {0.04, 0.04};
      r.runs.push_back(run);
    }
  }
  evaluate(r, [&](Factor f, double v, Drainage d) { return findRun(r, f, v, d); });
  return r;
}

}  // namespace

TEST(AccuracyMetrics, RelativeErrorIsTheLargestDeviationOverTheLargestReference) {
  EXPECT_DOUBLE_EQ(relativeError({1, 2, 3}, {1, 2, 4}), 0.25);        // max |diff| 1 / max |ref| 4
  EXPECT_DOUBLE_EQ(relativeError({-2, 5}, {-4, 4}), 0.5);             // max(2, 1) / 4
  EXPECT_DOUBLE_EQ(relativeError({7, 7}, {7, 7}), 0.0);
  EXPECT_TRUE(std::isnan(relativeError({1, 2}, {1, 2, 3})));          // a missing cycle
  EXPECT_TRUE(std::isnan(relativeError({}, {})));
  EXPECT_TRUE(std::isnan(relativeError({1}, {0})));                   // no scale
  EXPECT_TRUE(std::isnan(relativeError({NAN}, {1})));
}

TEST(AccuracyMetrics, ParetoFrontKeepsOnlyUndominatedPointsSortedByCost) {
  // (cost, error): (1, .5) (2, .6) (3, .2) (4, .2) (5, .1): (2, .6) is beaten by (1, .5); (4, .2) by (3, .2)
  EXPECT_EQ(paretoFront({1, 2, 3, 4, 5}, {0.5, 0.6, 0.2, 0.2, 0.1}), (std::vector<std::size_t>{0, 2, 4}));
  // unsorted input, equal costs: the lower error wins; non-finite points are ignored
  EXPECT_EQ(paretoFront({5, 1, 1, 3, NAN}, {0.01, 0.3, 0.2, 0.05, 0.0}), (std::vector<std::size_t>{2, 3, 0}));
  EXPECT_TRUE(paretoFront({}, {}).empty());
}

TEST(AccuracyMetrics, ConvergedReferenceGivesTheCheapestSettingBelowTheTarget) {
  // G_sec 110, 100.5, 100: errors 10/101 = 9.9 %, 0.5/101 = 0.495 %, reference: converged (0.495 % <= 0.5 %);
  // du 25, 20.0625 vs 20: 25 %, 0.3125 % (values exact in binary, so the expected errors are exact)
  const StudyResult r = synthetic({110, 100.5, 100}, {25, 20.0625, 20});
  ASSERT_EQ(r.rows.size(), 6u);
  EXPECT_DOUBLE_EQ(r.rows[0].errors[int(Output::Gsec)], 10.0 / 101.0);
  EXPECT_DOUBLE_EQ(r.rows[1].errors[int(Output::Gsec)], 0.5 / 101.0);
  EXPECT_DOUBLE_EQ(r.rows[2].errors[int(Output::Gsec)], 0.0);
  EXPECT_DOUBLE_EQ(r.rows[1].errors[int(Output::Du)], 0.0625 / 20.0);
  EXPECT_TRUE(std::isnan(r.rows[1].errors[int(Output::EpsV)]));  // not measured in the undrained test
  EXPECT_TRUE(std::isnan(r.rows[4].errors[int(Output::Du)]));    // nor du in the drained one
  const Cheapest g = cheapestBelow(r, Output::Gsec, {Drainage::Undrained, Drainage::Drained});
  ASSERT_TRUE(g.found);
  EXPECT_EQ(g.factor, Factor::InertialNumber);
  EXPECT_DOUBLE_EQ(g.value, 3e-4);
  EXPECT_DOUBLE_EQ(g.wallSeconds, 6.0);            // 3 s in each test
  EXPECT_DOUBLE_EQ(g.referenceWallSeconds, 20.0);
  const Cheapest d = cheapestBelow(r, Output::Du, {Drainage::Undrained});
  ASSERT_TRUE(d.found);
  EXPECT_DOUBLE_EQ(d.value, 3e-4);  // 0.3125 % < 1 %
  const std::string md = reportMarkdown(r, "img", {}, "test");
  EXPECT_NE(md.find("Cheapest setting with < 1.00 % error on G_sec (undrained and drained)**: inertial number 0.0003,"),
            std::string::npos)
      << md;
  EXPECT_EQ(md.find("NOT converged"), std::string::npos);
}

TEST(AccuracyMetrics, UnconvergedReferenceIsReportedAndNothingIsCertified) {
  // the two finest rungs differ by 1/101 = 0.99 % > 0.5 %: not converged, even though 3e-4 is "within 1 %"
  const StudyResult r = synthetic({110, 101, 100}, {20, 21, 20});
  bool sawGsec = false;
  for (const Convergence& c : r.convergence) {
    if (c.output != Output::Gsec) continue;
    sawGsec = true;
    EXPECT_FALSE(c.converged);
    EXPECT_DOUBLE_EQ(c.disagreement, 1.0 / 101.0);
  }
  EXPECT_TRUE(sawGsec);
  EXPECT_FALSE(cheapestBelow(r, Output::Gsec, {Drainage::Undrained, Drainage::Drained}).found);
  EXPECT_FALSE(cheapestBelow(r, Output::Du, {Drainage::Undrained}).found);
  const std::string md = reportMarkdown(r, "img", {}, "test");
  EXPECT_NE(md.find("**NOT converged**"), std::string::npos);
  EXPECT_NE(md.find("Warning: at least one reference is NOT converged for G_sec or Δu"), std::string::npos);
  EXPECT_NE(md.find("error on G_sec (undrained and drained)**: none found — the reference of the inertial_number ladder is "
                    "not converged"),
            std::string::npos)
      << md;
  EXPECT_FALSE(cheapestCombination(r, Output::Gsec, {Drainage::Undrained, Drainage::Drained}).found);
}

TEST(AccuracyMetrics, CheapestCombinationSumsTheFactorsErrors) {
  // two ladders sharing the base (I 1e-4, time_step_factor 0.25); G_sec of each run (one cycle, both tests)
  // and its particle-steps:
  //   I 1e-5 (reference): 100, 100 steps   base: 100.25, 10 steps   I 1e-3: 100.75, 1 step
  //   tsf 0.1 (reference): 100.25, 25       tsf 0.5: 100.75, 5
  // errors: I: base 0.25 %, 1e-3 0.75 %; tsf: base 0, 0.5 -> 0.5/100.25 = 0.4988 %
  StudyResult r;
  r.config.base.inertialNumber = 1e-4;
  r.config.base.timeStepFactor = 0.25;
  r.config.cycles = 1;
  r.config.target = 0.01;
  r.config.ladders = {{Factor::InertialNumber, {1e-3, 1e-4, 1e-5}}, {Factor::TimeStepFactor, {0.5, 0.25, 0.1}}};
  struct Spec {
    Factor f;
    double v, g;
    long steps;
  };
  const Spec specs[] = {{Factor::InertialNumber, 1e-4, 100.25, 10}, {Factor::InertialNumber, 1e-5, 100, 100},
                        {Factor::InertialNumber, 1e-3, 100.75, 1},   {Factor::TimeStepFactor, 0.1, 100.25, 25},
                        {Factor::TimeStepFactor, 0.5, 100.75, 5}};
  for (Drainage d : {Drainage::Undrained, Drainage::Drained})
    for (const Spec& sp : specs) {
      RunResult run;
      run.id = static_cast<int>(r.runs.size());
      run.settings = rungSettings(r.config, sp.f, sp.v, 0);
      run.drainage = d;
      run.ok = true;
      run.particleSteps = sp.steps;
      run.wallSeconds = double(sp.steps);
      run.metrics.Gsec = {sp.g};
      run.metrics.du = {10.0};
      r.runs.push_back(run);
    }
  evaluate(r, [&](Factor f, double v, Drainage d) { return findRun(r, f, v, d); });
  // converged: I 1e-4 vs 1e-5 differ by 0.25 %, tsf 0.25 vs 0.1 by 0
  const std::vector<Drainage> both = {Drainage::Undrained, Drainage::Drained};
  Combination c = cheapestCombination(r, Output::Gsec, both);
  ASSERT_TRUE(c.found) << c.reason;
  EXPECT_DOUBLE_EQ(c.settings.inertialNumber, 1e-3);  // 0.75 % + 0: cost 1/10 of the base
  EXPECT_DOUBLE_EQ(c.settings.timeStepFactor, 0.25);
  EXPECT_NEAR(c.bound, 0.0075, 1e-15);
  EXPECT_NEAR(c.costRatio, 0.1, 1e-15);
  EXPECT_NEAR(c.baseBound, 0.0025, 1e-15);
  // with a 0.7 % target I 1e-3 is out, and so is (1e-4, tsf 0.5) at 0.25 % + 0.4988 %: the base is the cheapest
  r.config.target = 0.007;
  c = cheapestCombination(r, Output::Gsec, both);
  ASSERT_TRUE(c.found);
  EXPECT_DOUBLE_EQ(c.settings.inertialNumber, 1e-4);
  EXPECT_DOUBLE_EQ(c.settings.timeStepFactor, 0.25);
  EXPECT_NEAR(c.costRatio, 1.0, 1e-15);
  // x_conv = x_base - (x_base - x_ref,I) - (x_base - x_ref,tsf) = 100.25 - 0.25 - 0
  EXPECT_EQ(extrapolatedReference(r, Output::Gsec, Drainage::Drained), (std::vector<double>{100.0}));
  // the run of a combination is found by its settings
  EXPECT_EQ(runWithSettings(r, c.settings, Drainage::Undrained), baseRun(r, Drainage::Undrained));
}

TEST(AccuracyMetrics, ExactLimitLaddersNeedNoConvergenceCheck) {
  // 5 % between the two finest rungs would fail the check of a limit ladder, but local damping 0 is exact
  StudyResult r = synthetic({110, 105, 100}, {25, 21, 20});
  r.config.ladders = {{Factor::LocalDamping, {0.3, 0.05, 0.0}}};
  for (int k = 0; k < 6; ++k) r.runs[k].settings = rungSettings(r.config, Factor::LocalDamping, r.config.ladders[0].values[k % 3], 0);
  evaluate(r, [&](Factor f, double v, Drainage d) { return findRun(r, f, v, d); });
  ASSERT_FALSE(r.convergence.empty());
  for (const Convergence& c : r.convergence) {
    EXPECT_TRUE(c.exactLimit);
    EXPECT_TRUE(c.converged);
  }
  const Cheapest g = cheapestBelow(r, Output::Gsec, {Drainage::Undrained, Drainage::Drained});
  ASSERT_TRUE(g.found);
  EXPECT_DOUBLE_EQ(g.value, 0.0);  // only the undamped reference is within 1 %
  EXPECT_DOUBLE_EQ(g.wallSeconds, 20.0);
  EXPECT_NE(reportMarkdown(r, "img", {}, "test").find("(exact limit)"), std::string::npos);
  EXPECT_FALSE(isExactLimit(Factor::InertialNumber, 0.0));
  EXPECT_TRUE(isExactLimit(Factor::Restitution, 1.0));
  EXPECT_TRUE(isExactLimit(Factor::DensityScale, 1.0));
}

TEST(AccuracyMetrics, ParticleCountIsASizeEffectNotACandidate) {
  StudyResult r = synthetic({110, 100.5, 100}, {25, 20.0625, 20});
  // relabel the ladder as particle counts: never a "cheapest setting", reported as a size effect
  r.config.ladders = {{Factor::ParticleCount, {500, 1000, 2000}}};
  for (int k = 0; k < 6; ++k) r.runs[k].settings = rungSettings(r.config, Factor::ParticleCount, r.config.ladders[0].values[k % 3], 0);
  r.config.base.particles = 2000;
  evaluate(r, [&](Factor f, double v, Drainage d) { return findRun(r, f, v, d); });
  EXPECT_FALSE(cheapestBelow(r, Output::Gsec, {Drainage::Undrained, Drainage::Drained}).found);
  EXPECT_NE(reportMarkdown(r, "img", {}, "test").find("(size effect)"), std::string::npos);
}

TEST(AccuracyMetrics, StabilityVerdictFollowsTheContract) {
  using namespace fl::stability;
  CaseResult c;
  c.outcome.completed = true;
  c.outcome.maxOverlap = 0.01;
  c.outcome.maxEnergyError = 0.001;
  classify(c);
  EXPECT_EQ(c.verdict, "ran bounded");
  EXPECT_TRUE(c.contractHolds && c.asExpected);
  c.outcome.maxEnergyError = 0.2;  // completed but unbounded
  classify(c);
  EXPECT_FALSE(c.contractHolds);
  EXPECT_EQ(c.verdict.rfind("FAILED", 0), 0u);
  CaseResult s;
  s.outcome.error = "numerical instability at step 3 (...): an overlap reached 0.07. To fix: raise the modulus.";
  classify(s);
  EXPECT_TRUE(s.contractHolds);
  EXPECT_FALSE(s.asExpected);  // not marked "may stop"
  s.mayStop = true;
  classify(s);
  EXPECT_EQ(s.verdict, "stopped with a diagnostic");
  s.outcome.error = "NaN";  // a stop without a fix breaks the contract
  classify(s);
  EXPECT_FALSE(s.contractHolds);
}

TEST(AccuracyStudy, QuickStudyEndToEnd) {
  const fs::path dir = fs::temp_directory_path() / ("fl-accuracy-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  StudyConfig c = quickConfig();
  const StudyResult r = runStudy(c, dir.string(), nullptr);
  // every distinct run completed its cycle
  for (const RunResult& run : r.runs) {
    EXPECT_TRUE(run.ok) << run.error;
    ASSERT_EQ(run.metrics.Gsec.size(), 1u);
    EXPECT_GT(run.metrics.Gsec[0], 50e6);  // secant shear stiffness at 0.023 %: tens to hundreds of MPa
    EXPECT_LT(run.metrics.Gsec[0], 450e6);
    EXPECT_GT(run.wallSeconds, 0);
    EXPECT_GT(run.particleSteps, 0);
  }
  // one row per rung and drainage: (4 + 2 + 2) x 2, one per check of a combined setting, and a header
  ASSERT_EQ(r.rows.size(), 16u);
  int checks = 0;
  for (const RunResult& run : r.runs) {
    bool inLadder = false;
    for (const Row& row : r.rows) inLadder = inLadder || row.run == run.id;
    checks += !inLadder;
  }
  const std::string csv = csvText(r);
  EXPECT_EQ(lineCount(csv), 1 + 16 + checks);
  // the cheapest combination, when there is one, was run
  for (const auto& [out, ds] : {std::pair<Output, std::vector<Drainage>>{Output::Gsec, {Drainage::Undrained, Drainage::Drained}},
                                {Output::Du, {Drainage::Undrained}}}) {
    const Combination comb = cheapestCombination(r, out, ds);
    if (comb.found) {
      for (Drainage d : ds) EXPECT_GE(runWithSettings(r, comb.settings, d), 0) << outputKey(out);
    }
  }
  // loading faster moves G_sec further from the quasi-static reference (rate effect)
  for (Drainage d : {Drainage::Undrained, Drainage::Drained}) {
    double e1 = NAN, e2 = NAN;
    for (const Row& row : r.rows)
      if (row.factor == Factor::InertialNumber && row.drainage == d) {
        if (row.value == 1e-2) e1 = row.errors[int(Output::Gsec)];
        if (row.value == 1e-3) e2 = row.errors[int(Output::Gsec)];
      }
    EXPECT_GT(e1, e2) << drainageKey(d);
  }
  const std::string md = reportMarkdown(r, "accuracy-vs-cost", {}, "fabriclab-accuracy --quick");
  EXPECT_NE(md.find("**Cheapest setting with < 1.00 % error on G_sec"), std::string::npos);
  EXPECT_NE(md.find("**Cheapest setting with < 1.00 % error on Δu"), std::string::npos);
  EXPECT_NE(md.find("Is the reference converged?"), std::string::npos);
  // the saved results give the same table back
  const StudyResult again = resultFromJson(nlohmann::json::parse(resultJson(r).dump()));
  EXPECT_EQ(csvText(again), csv);
  // the plots: one per output and drainage that has points, plus the size effect
  EXPECT_GE(plots(r).size(), 2u);
  fs::remove_all(dir);
}

TEST(AccuracyStudy, ParallelJobsDoNotChangeTheResults) {
  // a tiny study run with one and with two jobs: every measured value is the same (only wall times differ)
  StudyConfig c = quickConfig();
  c.base.particles = 300;
  c.ladders = {{Factor::InertialNumber, {1e-2, 3e-3}}};
  c.base.inertialNumber = 3e-3;
  const fs::path dir = fs::temp_directory_path() / ("fl-accuracy-jobs-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  c.jobs = 1;
  const StudyResult one = runStudy(c, (dir / "one").string(), nullptr);
  c.jobs = 2;
  const StudyResult two = runStudy(c, (dir / "two").string(), nullptr);
  ASSERT_EQ(one.runs.size(), two.runs.size());
  for (std::size_t k = 0; k < one.runs.size(); ++k) {
    EXPECT_TRUE(one.runs[k].ok) << one.runs[k].error;
    EXPECT_EQ(one.runs[k].steps, two.runs[k].steps);
    for (int o = 0; o < kOutputCount; ++o) EXPECT_EQ(one.runs[k].metrics.of(Output(o)), two.runs[k].metrics.of(Output(o)));
  }
  fs::remove_all(dir);
}
