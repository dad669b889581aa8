// The runner on reduced scenes: every stage type completes with its criterion met, K0 keeps eps_r = 0,
// undrained cycles keep the volume, drained cycles hold the lateral stress, load reversals make no
// stress spike, the failure cycle is reported, and a checkpoint restart is bit-identical.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/gas_generator.hpp"
#include "core/material.hpp"
#include "core/measurements.hpp"
#include "core/packing_io.hpp"
#include "core/runner.hpp"
#include "core/spatial_order.hpp"

using namespace fl;
using nlohmann::json;

namespace {
// A small, fast specimen: 300 spheres, density scaling for a large step (controller tests, not physics).
json smallScene() {
  return json::parse(R"({
    "name": "runner test",
    "specimen": {"count": 300, "solid_fraction": 0.3, "seed": 2},
    "numerics": {"time_step_factor": 0.3, "local_damping": 0.1, "density_scale": 100, "threads": 1},
    "servo": {"max_strain_rate": 20, "max_inertial_number": 0.02, "unbalanced_tolerance": 0.01},
    "output": {"sample_interval": 500},
    "stages": [
      {"type": "isotropic_compression", "pressure": 50000, "friction": 0.1, "friction_after": 0.235}
    ]
  })");
}

Runner run(const json& j) {
  Runner r(parseScene(j, "test.json"));
  while (r.advance(5000)) {
  }
  return r;
}
}  // namespace

TEST(RunnerStages, IsotropicCompressionReachesTargetAndSetsFrictionAfter) {
  Runner r = run(smallScene());
  ASSERT_EQ(r.summaries().size(), 1u);
  const Sample& end = r.summaries()[0].end;
  EXPECT_NEAR(end.p / 50000, 1.0, 2e-3);
  EXPECT_LT(end.unbalanced, 0.01);
  EXPECT_EQ(r.simulation().materials()[0].friction, 0.235);
  EXPECT_GT(end.Z, 3.5);
  EXPECT_GT(end.voidRatio, 0.4);
  EXPECT_LT(end.voidRatio, 0.9);
}

TEST(RunnerStages, K0LoadingUnloadingAndOcr) {
  json j = smallScene();
  j["stages"].push_back({{"type", "k0"}, {"axial_stress", 200000}});
  j["stages"].push_back({{"type", "k0"}, {"until_isotropic", true}});
  Runner r = run(j);
  ASSERT_EQ(r.summaries().size(), 3u);
  const StageSummary& load = r.summaries()[1];
  const StageSummary& unload = r.summaries()[2];
  EXPECT_NEAR(load.end.stress.z() / 200000, 1.0, 2e-3);
  EXPECT_EQ(load.end.epsR, 0.0);  // lateral strain exactly zero
  EXPECT_GT(load.K0, 0.2);
  EXPECT_LT(load.K0, 0.9);
  EXPECT_EQ(unload.end.epsR, 0.0);
  EXPECT_NEAR(unload.end.q / unload.end.p, 0.0, 2e-3);  // isotropic at the end
  EXPECT_NEAR(unload.K0, 1.0, 3e-3);
  EXPECT_GT(unload.ocr, 1.5);  // over-consolidated: sigma'_v,max / sigma'_v
}

TEST(RunnerStages, DrainedAndUndrainedTriaxial) {
  for (const char* drainage : {"drained", "undrained"}) {
    json j = smallScene();
    j["stages"].push_back({{"type", "triaxial"}, {"drainage", drainage}, {"axial_strain", 0.01}, {"strain_rate", 0.5}});
    Runner r = run(j);
    const StageSummary& t = r.summaries().back();
    EXPECT_GE(t.end.epsA, 0.01);
    EXPECT_LT(t.end.epsA, 0.0101);
    EXPECT_GT(t.end.q, 1000) << drainage;
    if (std::string(drainage) == "undrained") {  // constant volume
      EXPECT_NEAR(t.end.epsV, 0.0, 1e-13);
      // du = sigma'_3,0 - sigma'_3 (constant cell pressure)
      EXPECT_NEAR(t.end.du, r.summaries()[0].end.stress.x() * 0.5 + r.summaries()[0].end.stress.y() * 0.5 -
                                0.5 * (t.end.stress.x() + t.end.stress.y()),
                  1e-6 * t.end.p);
    } else {  // lateral stresses held by the servo
      const Vec3& s0 = r.summaries()[0].end.stress;
      EXPECT_NEAR((t.end.stress.x() + t.end.stress.y()) / (s0.x() + s0.y()), 1.0, 0.02);
    }
  }
}

TEST(RunnerStages, CyclicUndrainedKeepsVolumeCountsCyclesAndHasNoReversalSpikes) {
  json j = smallScene();
  j["stages"].push_back({{"type", "cyclic"}, {"drainage", "undrained"}, {"amplitude", 2.3e-4}, {"cycles", 3},
                         {"strain_rate", 0.5}, {"samples_per_cycle", 40}});
  Runner r = run(j);
  ASSERT_EQ(r.cycles().size(), 3u);
  for (const CycleRecord& c : r.cycles()) {
    EXPECT_GT(c.Gsec, 20e6);
    EXPECT_LT(c.Gsec, 2e9);
    EXPECT_NEAR(c.gammaMax, 1.5 * 2.3e-4, 0.05 * 2.3e-4);  // gamma = 1.5 eps_a at constant volume
    EXPECT_NEAR(c.end.epsV, 0.0, 1e-13);
  }
  // Load reversals without stress spikes: after every strain reversal q follows the new strain direction
  // monotonically (a spike or ringing would make q double back). The first sample after a reversal may
  // jump more than the mean: elastic unloading is stiffer than the preceding loading (expected physics).
  const auto& s = r.samples();
  std::vector<std::size_t> idx;
  for (std::size_t k = 0; k < s.size(); ++k)
    if (s[k].cycle > 0) idx.push_back(k);
  EXPECT_GT(idx.size(), 3u * 40 - 5);
  int reversals = 0;
  for (std::size_t m = 1; m + 4 < idx.size(); ++m) {
    const double d0 = s[idx[m]].epsA - s[idx[m - 1]].epsA, d1 = s[idx[m + 1]].epsA - s[idx[m]].epsA;
    if (d0 * d1 >= 0) continue;  // not a strain reversal at sample m
    ++reversals;
    const double dir = d1 > 0 ? 1.0 : -1.0;
    for (std::size_t k = m; k < m + 3; ++k)
      EXPECT_GT(dir * (s[idx[k + 1]].q - s[idx[k]].q), 0.0) << "q doubles back after the reversal at step " << s[idx[m]].step;
  }
  EXPECT_GE(reversals, 5);
}

TEST(RunnerStages, CyclicDrainedHoldsLateralStress) {
  json j = smallScene();
  j["stages"].push_back({{"type", "cyclic"}, {"drainage", "drained"}, {"amplitude", 2.3e-4}, {"cycles", 2},
                         {"strain_rate", 0.5}});
  Runner r = run(j);
  ASSERT_EQ(r.cycles().size(), 2u);
  const double lat0 = r.summaries()[0].end.stress.x();
  for (const Sample& s : r.samples())
    if (s.cycle > 0) {
      EXPECT_NEAR(s.stress.x() / lat0, 1.0, 0.05);
    }
}

// advance() hands the engine batches of steps that need nothing of the runner in between (Runner::quietSteps),
// which the engine runs with each kick fused with the next drift. Batched or one step per call, a run through
// compression, a K0 unloading that follows the lateral stress every step, a triaxial stage and drained and
// undrained cycles (reversals and samples on the strain) gives the same samples, cycles and state, bit for bit.
TEST(RunnerBatches, BatchedStepsGiveTheBitsOfSingleSteps) {
  json j = smallScene();
  j["stages"].push_back({{"type", "k0"}, {"pressure", 80000}});
  j["stages"].push_back({{"type", "k0"}, {"until_isotropic", true}, {"max_steps", 3000}});
  j["stages"].push_back({{"type", "triaxial"}, {"drainage", "drained"}, {"axial_strain", 0.0005}, {"strain_rate", 0.5}});
  j["stages"].push_back({{"type", "cyclic"}, {"drainage", "undrained"}, {"amplitude", 2.3e-4}, {"cycles", 2},
                         {"strain_rate", 0.5}, {"samples_per_cycle", 40}});
  j["stages"].push_back({{"type", "cyclic"}, {"drainage", "drained"}, {"amplitude", 1.1e-4}, {"cycles", 1},
                         {"strain_rate", 0.5}, {"samples_per_cycle", 24}});
  j["output"]["check_interval"] = 700;
  Runner a(parseScene(j, "test.json")), b(parseScene(j, "test.json"));
  while (a.advance(100000)) {
  }
  while (b.advance(1)) {
  }
  const Simulation& sa = a.simulation();
  const Simulation& sb = b.simulation();
  EXPECT_GT(sa.profile().fusedKicks, sa.profile().steps / 2) << "most steps must run in batches";
  EXPECT_EQ(sb.profile().fusedKicks, 0);
  EXPECT_EQ(sa.stepCount(), sb.stepCount());
  EXPECT_EQ(std::memcmp(sa.particles().pos.data(), sb.particles().pos.data(), sa.particles().size() * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(sa.particles().vel.data(), sb.particles().vel.data(), sa.particles().size() * sizeof(Vec3)), 0);
  ASSERT_EQ(a.samples().size(), b.samples().size());
  for (std::size_t k = 0; k < a.samples().size(); ++k) {
    const Sample& x = a.samples()[k];
    const Sample& y = b.samples()[k];
    ASSERT_EQ(x.step, y.step) << "sample " << k;
    EXPECT_EQ(x.epsA, y.epsA) << "sample " << k;
    EXPECT_EQ(x.q, y.q) << "sample " << k;
    EXPECT_EQ(x.p, y.p) << "sample " << k;
  }
  ASSERT_EQ(a.cycles().size(), 3u);
  ASSERT_EQ(b.cycles().size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(a.cycles()[k].Gsec, b.cycles()[k].Gsec);
  ASSERT_EQ(a.summaries().size(), b.summaries().size());
  for (std::size_t k = 0; k < a.summaries().size(); ++k) EXPECT_EQ(a.summaries()[k].steps, b.summaries()[k].steps);
}

TEST(RunnerStages, MaxStepsGivesAClearError) {
  json j = smallScene();
  j["stages"][0]["max_steps"] = 50;
  Runner r(parseScene(j, "test.json"));
  try {
    while (r.advance(1000)) {
    }
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("max_steps"), std::string::npos);
  }
}

TEST(RunnerCheckpoint, RestartMidCycleIsBitIdentical) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("fl-runner-ckpt-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  json j = smallScene();
  j["stages"].push_back({{"type", "cyclic"}, {"drainage", "undrained"}, {"amplitude", 2.3e-4}, {"cycles", 2},
                         {"strain_rate", 0.5}});
  Runner a(parseScene(j, "test.json"));
  while (a.stageIndex() < 1 || a.currentCycle() < 1) a.advance(100);
  a.advance(777);  // somewhere inside cycle 1
  const std::string ck = (dir / "mid.ckpt").string();
  a.writeCheckpoint(ck);
  Runner b = Runner::fromCheckpoint(ck);
  while (a.advance(1000)) {
  }
  while (b.advance(1000)) {
  }
  const auto& pa = a.simulation().particles();
  const auto& pb = b.simulation().particles();
  EXPECT_EQ(a.simulation().stepCount(), b.simulation().stepCount());
  EXPECT_EQ(std::memcmp(pa.pos.data(), pb.pos.data(), pa.pos.size() * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(pa.vel.data(), pb.vel.data(), pa.vel.size() * sizeof(Vec3)), 0);
  ASSERT_EQ(a.cycles().size(), b.cycles().size());
  EXPECT_EQ(a.cycles().back().Gsec, b.cycles().back().Gsec);
  // corrupted and truncated checkpoints are rejected with a clear message
  std::string bytes;
  {
    std::ifstream in(ck, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto expectRejected = [&](const std::string& content, const std::string& fragment) {
    const std::string bad = (dir / "bad.ckpt").string();
    std::ofstream(bad, std::ios::binary) << content;
    try {
      (void)Runner::fromCheckpoint(bad);
      ADD_FAILURE() << "accepted: " << fragment;
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x5A;
  expectRejected(flipped, "checksum");
  expectRejected(bytes.substr(0, bytes.size() - 100), "truncated");
  expectRejected("hello", "not a FabricLab checkpoint");
  std::string version = bytes;
  version[sizeof("FABRICLAB-CHECKPOINT")] = 99;
  expectRejected(version, "version");
  fs::remove_all(dir);
}

TEST(RunnerSpecimen, AStageCanStartFromAnotherRunsCheckpoint) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("fl-runner-branch-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  json j = smallScene();
  j["output"]["directory"] = dir.string();
  Runner a = run(j);
  ASSERT_EQ(a.summaries().size(), 1u);
  const std::string ck = a.summaries()[0].checkpoint;
  ASSERT_TRUE(fs::exists(ck));
  // branch: the same specimen, another history, other numerics
  json k = smallScene();
  k["specimen"] = {{"source", "checkpoint"}, {"path", ck}};
  k["numerics"]["density_scale"] = 50;
  k["stages"] = json::array({{{"type", "k0"}, {"axial_stress", 100000}}});
  Runner b(parseScene(k, "branch.json"));
  EXPECT_NEAR(stressMeasures(b.simulation().contactStress()).p / 50000, 1.0, 2e-3);
  EXPECT_EQ(b.simulation().numerics().densityScale, 50);
  while (b.advance(5000)) {
  }
  EXPECT_NEAR(b.summaries()[0].end.stress.z() / 100000, 1.0, 2e-3);
  fs::remove_all(dir);
}

TEST(RunnerOutputs, ParaViewSnapshotsOnTheirOwnSchedule) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("fl-runner-vtk-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  json j = smallScene();
  j["output"]["directory"] = dir.string();
  j["output"]["vtk_interval"] = 5000;
  Runner r = run(j);
  const long expected = r.simulation().stepCount() / 5000;
  ASSERT_GT(expected, 0);
  long vtu = 0;
  for (const auto& e : fs::directory_iterator(dir / "paraview")) vtu += e.path().extension() == ".vtu";
  EXPECT_EQ(vtu, 3 * expected);  // particles, contacts and cell per snapshot
  for (const char* series : {"particles.pvd", "contacts.pvd", "cell.pvd"}) {
    std::ifstream in(dir / "paraview" / series);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    long entries = 0;
    for (std::size_t p = text.find("<DataSet"); p != std::string::npos; p = text.find("<DataSet", p + 1)) ++entries;
    EXPECT_EQ(entries, expected) << series;
  }
  fs::remove_all(dir);
}

TEST(RunnerStages, K0LoadingToAMeanStressTarget) {
  // the paper's K0 consolidation "up to p' = 318 kPa": the axial servo drives p', lateral strain stays 0
  json j = smallScene();
  j["stages"].push_back({{"type", "k0"}, {"pressure", 150000}});
  Runner r = run(j);
  const StageSummary& k0 = r.summaries().back();
  EXPECT_NEAR(k0.end.p / 150000, 1.0, 2e-3);
  EXPECT_EQ(k0.end.epsR, 0.0);
  EXPECT_GT(k0.end.q, 0.0);  // vertical stress above the lateral one
  EXPECT_LT(k0.K0, 1.0);
}

// An imported packing (csv or LAMMPS data) in arbitrary order is put in Z-order, as a generated gas is
// (issue 6: in file order the step ran 2x slower at 256 000 spheres). Every particle keeps its file row as
// id, with its position and radius, and the pairs are the same: the stress of the sorted specimen equals
// that of the packing in file order to round-off.
TEST(RunnerSpecimen, ImportedPackingsAreZOrderedAndKeepTheirFileRowsAsIds) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("fl-runner-import-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  GasSpec g;
  g.count = 400;
  g.solidFraction = 0.3;
  g.seed = 7;
  Packing pk = generateGas(g);
  // squeeze the gas affinely to solid fraction ~0.6 so that many pairs touch, and reverse the order (far
  // from Z-order)
  const double s = std::cbrt(0.5);
  for (Vec3& x : pk.particles.pos) x *= s;
  pk.cell = PeriodicCell(pk.cell.matrix() * s);
  std::vector<std::size_t> reversed(pk.particles.size());
  for (std::size_t k = 0; k < reversed.size(); ++k) reversed[k] = reversed.size() - 1 - k;
  reorderParticles(pk.particles, reversed);
  for (std::size_t k = 0; k < pk.particles.size(); ++k) pk.particles.id[k] = static_cast<std::int32_t>(k);
  const Material glass = Material::paperGlass();
  writePackingCsv((dir / "p.csv").string(), pk.particles, pk.cell);
  writeLammpsData((dir / "p.data").string(), pk.particles, pk.cell, {glass});

  for (const char* source : {"csv", "lammps"}) {
    SCOPED_TRACE(source);
    json j = smallScene();
    j["specimen"] = {{"source", source}, {"path", (dir / (std::string(source) == "csv" ? "p.csv" : "p.data")).string()}};
    Runner r(parseScene(j, (dir / "scene.json").string()));
    const Simulation& sim = r.simulation();
    const ParticleStore& p = sim.particles();
    ASSERT_EQ(p.size(), pk.particles.size());
    // Z-ordered: sorting again changes nothing
    const std::vector<std::size_t> order = mortonOrder(p, sim.cell());
    std::size_t unsorted = 0;
    for (std::size_t k = 0; k < order.size(); ++k) unsorted += order[k] != k;
    EXPECT_EQ(unsorted, 0u);
    std::size_t kept = 0;  // particles still at their file row: few, since the import was reordered
    std::vector<int> seen(p.size(), 0);
    for (std::size_t k = 0; k < p.size(); ++k) {
      const auto row = static_cast<std::size_t>(p.id[k]);
      ASSERT_LT(row, p.size());
      ++seen[row];
      kept += row == k;
      EXPECT_EQ(p.radius[k], pk.particles.radius[row]);
      Vec3 red = pk.cell.reduced(p.pos[k] - pk.particles.pos[row]);  // the nearest periodic image
      for (int a = 0; a < 3; ++a) red[a] -= std::round(red[a]);
      const Vec3 d = pk.cell.matrix() * red;
      EXPECT_LE(d.norm(), 1e-15 * pk.cell.matrix().norm()) << "row " << row;
    }
    for (int c : seen) EXPECT_EQ(c, 1);
    EXPECT_LT(kept, p.size() / 10);
    // the same pairs: the stress equals that of the packing in file order
    Simulation fileOrder(pk.particles, pk.cell, sim.materials(), sim.numerics());
    EXPECT_GT(sim.contacts().activeCount(), p.size());
    EXPECT_EQ(sim.contacts().activeCount(), fileOrder.contacts().activeCount());
    const double scale = fileOrder.contactStress().norm();
    EXPECT_GT(scale, 0.0);
    EXPECT_LE((sim.contactStress() - fileOrder.contactStress()).norm(), 1e-12 * scale);
  }
  fs::remove_all(dir);
}
