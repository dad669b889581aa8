// Dense-packing throughput benchmark (issue 6): particle-steps per second of the step pipeline on the
// scene the peers measured — 4000 of the paper's glass beads (Material::paperGlass(), seven diameters
// 0.8–1.4 mm) in a periodic cell, isotropically compressed to p' = 318 kPa, Hertz–Mindlin contacts,
// dt = 1e-7 s, no density scaling, no damping of any kind, L = 0.
//
// The packing is prepared once (gas at solid fraction 0.3, seed 1; 3-axis stress servo with density
// scaling, local damping and zero friction, until done()) and cached as a Simulation state file. Every
// measured run rebuilds a fresh Simulation from the cached radii, positions and velocities (so the
// preparation's density scale and damping cannot leak into the numbers, and tangential history starts
// at zero, as in the LAMMPS run of bench/lammps_side_by_side.sh that reads the same packing).
//
// Not a test: it prints numbers and asserts nothing about time. It does check that the final state is
// bit-identical across the thread counts it measured (house style §12).
//
//   bench_dense [--threads 1,2] [--steps 20000] [--repeats 5] [--cache FILE] [--export-lammps FILE]
//               [--no-energy] [--skin METRES|settled] [--order file|morton|shuffled] [--tile NX,NY,NZ]
//               [--shares measured|even]
// --shares even keeps the threads' shares equal instead of following their measured speeds (share_balance.hpp).
// --skin settled fixes the skin at the one the automatic skin settles to on the untiled packing (settledSkin):
// every size of bench/scaling.sh then runs on the same list, whatever its number of steps.
// --tile replicates the periodic packing NX x NY x NZ times (same density, stress and contacts per particle:
// the scaling measurement of issue 6 uses 1,1,1 / 2,2,2 / 4,4,4 / 6,6,7 = 4k, 32k, 256k, 1M spheres).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/atomic_file.hpp"
#include "core/binary_io.hpp"
#include "core/cell_control.hpp"
#include "core/gas_generator.hpp"
#include "core/measurements.hpp"
#include "core/packing_io.hpp"
#include "core/rng.hpp"
#include "core/simulation.hpp"
#include "core/spatial_order.hpp"

using namespace fl;

namespace {

constexpr double kTargetPressure = 318e3;  // [Pa]
constexpr double kDt = 1e-7;               // [s]

struct Options {
  std::vector<int> threads{1, 2};
  long steps = 20000;
  int repeats = 5;
  std::string cache = "build/bench-cache/dense4000_318kPa.state";
  std::string exportLammps;
  bool trackEnergy = true;
  double skin = 0.0;  // 0: the engine's automatic skin (core/verlet_skin.hpp)
  bool settledSkin = false;  // --skin settled: fixed at the automatic skin's settled value (settledSkin below)
  std::array<int, 3> tile{1, 1, 1};  // periodic replicas of the packing per axis
  bool evenShares = false;  // --shares even: equal shares, not measured ones (core/share_balance.hpp)
  // --interleave B: one simulation per thread count, run in turn for --steps steps each, B times (interleaved)
  int bursts = 0;
  // particle order: Z-order (core/spatial_order.hpp), the cached packing's, or a seeded random permutation
  // (what a packing imported in arbitrary order would run at, were it not sorted)
  enum class Order { Morton, File, Shuffled } order = Order::Morton;
};

[[noreturn]] void usage(const char* msg) {
  std::fprintf(stderr,
               "bench_dense: %s\nusage: bench_dense [--threads 1,2] [--steps N] [--repeats N] [--cache FILE]\n"
               "                   [--export-lammps FILE] [--no-energy] [--skin METRES|settled] [--order file|morton|shuffled]\n"
               "                   [--tile NX,NY,NZ] [--shares measured|even] [--interleave BURSTS]\n",
               msg);
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    auto value = [&]() -> std::string {
      if (k + 1 >= argc) usage(("missing value after " + a).c_str());
      return argv[++k];
    };
    if (a == "--threads") {
      o.threads.clear();
      std::stringstream s(value());
      std::string t;
      while (std::getline(s, t, ',')) o.threads.push_back(std::atoi(t.c_str()));
      for (int t2 : o.threads)
        if (t2 < 1) usage("thread counts must be >= 1");
    } else if (a == "--steps") {
      o.steps = std::atol(value().c_str());
    } else if (a == "--repeats") {
      o.repeats = std::atoi(value().c_str());
    } else if (a == "--cache") {
      o.cache = value();
    } else if (a == "--export-lammps") {
      o.exportLammps = value();
    } else if (a == "--no-energy") {
      o.trackEnergy = false;
    } else if (a == "--skin") {
      const std::string v = value();
      if (v == "settled") o.settledSkin = true;
      else o.skin = std::atof(v.c_str());
    } else if (a == "--tile") {
      std::stringstream s(value());
      std::string t;
      int k2 = 0;
      while (std::getline(s, t, ',') && k2 < 3) o.tile[k2++] = std::atoi(t.c_str());
      if (k2 != 3 || o.tile[0] < 1 || o.tile[1] < 1 || o.tile[2] < 1) usage("--tile takes three positive integers");
    } else if (a == "--order") {
      const std::string v = value();
      if (v != "file" && v != "morton" && v != "shuffled") usage("--order takes file, morton or shuffled");
      o.order = v == "morton" ? Options::Order::Morton : v == "file" ? Options::Order::File : Options::Order::Shuffled;
    } else if (a == "--shares") {
      const std::string v = value();
      if (v != "measured" && v != "even") usage("--shares takes measured or even");
      o.evenShares = v == "even";
    } else if (a == "--interleave") {
      o.bursts = std::atoi(value().c_str());
      if (o.bursts < 2) usage("--interleave takes a number of bursts >= 2");
    } else if (a == "-h" || a == "--help") {
      usage("help");
    } else {
      usage(("unknown option " + a).c_str());
    }
  }
  if (o.steps < 1 || o.repeats < 1 || o.threads.empty()) usage("steps, repeats and threads must be positive");
  return o;
}

std::string readFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Gas -> isotropic 318 kPa with the 3-axis servo (density scaling and local damping: preparation only).
Simulation prepare() {
  GasSpec g;
  g.count = 4000;
  g.sizes = SizeDistribution::paperGlassBeads();
  g.solidFraction = 0.3;
  g.seed = 1;
  g.density = Material::paperGlass().density;
  Packing pk = generateGas(g);
  NumericsSettings num;
  num.densityScale = 1e4;
  num.localDamping = 0.7;  // strong: a frictionless packing settles slowly
  num.threads = 2;
  num.trackEnergy = false;
  Simulation sim(std::move(pk.particles), pk.cell, {Material::paperGlass()}, num);
  // Frictionless compression: the packing is then in equilibrium without tangential forces, so the
  // measured run (and LAMMPS, which cannot import tangential history from a data file) can start with
  // zero history at mu = 0.235 and stay at 318 kPa instead of collapsing.
  sim.setFriction(0.0);
  ServoSettings s;
  s.maxStrainRate = 20.0;
  s.stressTolerance = 1e-3;
  // a frictionless packing creeps towards a small unbalanced force slowly; 1e-2 is a jammed, static
  // enough state for a throughput benchmark (friction in the measured run only stabilises it further)
  s.unbalancedTolerance = 1e-2;
  const AxisControl axis{AxisMode::Stress, kTargetPressure};
  auto servo = std::make_shared<AxisServo>(std::array<AxisControl, 3>{axis, axis, axis}, s);
  sim.setController(servo);
  const auto t0 = std::chrono::steady_clock::now();
  const long maxSteps = 200'000;
  long k = 0;
  for (; k < maxSteps; k += 200) {
    sim.run(200);
    if (servo->done(sim)) break;
    if (k % 5000 == 0)
      std::printf("  prepare: step %ld  p = %.1f kPa  unbalanced = %.2e\n", k, sim.contactStress().trace() / 3e3,
                  sim.unbalancedForceRatio());
  }
  if (k >= maxSteps) std::fprintf(stderr, "bench_dense: warning: servo not done after %ld steps\n", maxSteps);
  std::printf("  prepared in %ld steps, %.1f s: p = %.1f kPa, unbalanced = %.2e\n", k + 200, seconds(t0),
              sim.contactStress().trace() / 3e3, sim.unbalancedForceRatio());
  sim.setController(nullptr);
  sim.setVelocityGradient(Mat3::Zero());
  sim.setFriction(Material::paperGlass().friction);
  return sim;
}

Simulation loadOrPrepare(const std::string& cache) {
  if (std::filesystem::exists(cache)) {
    const std::string bytes = readFile(cache);
    BinaryReader r(bytes, cache);
    std::printf("packing: cached %s\n", cache.c_str());
    return Simulation::restoreState(r);
  }
  std::printf("packing: preparing (cached afterwards in %s)\n", cache.c_str());
  Simulation sim = prepare();
  const auto dir = std::filesystem::path(cache).parent_path();
  if (!dir.empty()) std::filesystem::create_directories(dir);
  BinaryWriter w;
  sim.saveState(w);
  writeFileAtomically(cache, w.bytes());
  return sim;
}

// A fresh simulation for the measured run: particles rebuilt from radius/position (so invMass carries no
// density scaling), velocities kept, no tangential history, the benchmark numerics.
Simulation measuredScene(const Simulation& prepared, int threads, const Options& o) {
  const ParticleStore& src = prepared.particles();
  const Material glass = prepared.materials().at(0);
  ParticleStore p;
  const Mat3& H = prepared.cell().matrix();
  for (int a = 0; a < o.tile[0]; ++a)
    for (int b = 0; b < o.tile[1]; ++b)
      for (int c = 0; c < o.tile[2]; ++c) {
        const Vec3 shift = H * Vec3(a, b, c);
        for (std::size_t i = 0; i < src.size(); ++i) {
          p.add(src.pos[i] + shift, src.radius[i], glass.density, src.material[i]);
          p.vel.back() = src.vel[i];
          p.angVel.back() = src.angVel[i];
        }
      }
  PeriodicCell cell(H * Vec3(o.tile[0], o.tile[1], o.tile[2]).asDiagonal().toDenseMatrix());
  // Z-order: pair partners and their pair data mostly share a thread's half of the arrays (the LAMMPS data
  // file is written from this scene, so LAMMPS reads the same order; it re-sorts by itself every 1000 steps)
  if (o.order == Options::Order::Morton) sortSpatially(p, cell);
  if (o.order == Options::Order::Shuffled) {
    std::vector<std::size_t> perm(p.size());
    for (std::size_t k = 0; k < perm.size(); ++k) perm[k] = k;
    Rng rng(12345);  // the same permutation in every run
    shuffle(perm, rng);
    reorderParticles(p, perm);
  }
  NumericsSettings num;
  num.timeStep = kDt;
  num.localDamping = 0.0;
  num.restitution = 1.0;
  num.densityScale = 1.0;
  num.skin = o.skin;
  num.trackEnergy = o.trackEnergy;
  num.threads = threads;
  Simulation sim(std::move(p), cell, prepared.materials(), num);
  if (o.evenShares) sim.setFixedShares({});
  return sim;
}

// Resident set size of this process [bytes] (Linux /proc/self/statm; 0 elsewhere).
double residentBytes() {
  std::ifstream f("/proc/self/statm");
  double pages = 0.0, resident = 0.0;
  if (!(f >> pages >> resident)) return 0.0;
  return resident * static_cast<double>(sysconf(_SC_PAGESIZE));
}

// The checkpoint checksum (fnv1a64) over the final particle state, contact history, forces and stress: two
// builds that agree on it computed the same run bit for bit.
std::uint64_t stateFingerprint(const Simulation& sim) {
  const ParticleStore& p = sim.particles();
  BinaryWriter w;
  w.putVector(p.pos);
  w.putVector(p.vel);
  w.putVector(p.angVel);
  w.putVector(p.force);
  w.putVector(p.torque);
  w.putVector(sim.contacts().history);
  w.put(sim.contactStress());
  return fnv1a64(w.bytes());
}

// The skin the run settles to: the fixed one, or the automatic skin after 4096 untimed steps of the untiled
// packing on one thread (the tiles replicate it: the same displacements, the same skin).
double settledSkin(const Simulation& prepared, const Options& o) {
  if (o.skin > 0.0) return o.skin;
  Options one = o;
  one.tile = {1, 1, 1};
  Simulation s = measuredScene(prepared, 1, one);
  s.run(4096);
  return s.skin();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

// --interleave: the speed-up of each thread count over the first, burst by burst. One simulation per thread count
// runs --steps steps in turn with the others (the order alternating between bursts), so every burst compares the
// same state (the runs keep the same bits) within a second of host time: the shared VMs' speed drifts by 20-40 %
// within minutes, which separate runs (bench/two_cores.sh, bench/scaling.sh) see as spread. The median of the
// bursts' ratios is printed, with its quartiles.
int interleaved(const Simulation& prepared, const Options& o, std::size_t n) {
  std::vector<Simulation> sims;
  for (int t : o.threads) sims.push_back(measuredScene(prepared, t, o));
  const std::size_t nt = sims.size();
  std::vector<std::vector<double>> rates(nt), ratios(nt);
  std::printf("interleaved: %d bursts of %ld steps per thread count\n", o.bursts, o.steps);
  for (int b = 0; b < o.bursts; ++b) {
    std::vector<double> rate(nt);
    for (std::size_t q = 0; q < nt; ++q) {
      const std::size_t k = b % 2 == 0 ? q : nt - 1 - q;
      const auto t0 = std::chrono::steady_clock::now();
      sims[k].run(o.steps);
      rate[k] = static_cast<double>(n) * static_cast<double>(o.steps) / seconds(t0);
    }
    std::printf("burst %3d:", b + 1);
    for (std::size_t k = 0; k < nt; ++k) {
      rates[k].push_back(rate[k]);
      ratios[k].push_back(rate[k] / rate[0]);
      std::printf("  %d thread(s) %.4e", o.threads[k], rate[k]);
    }
    if (nt > 1) std::printf("  speed-up %.3f", rate[nt - 1] / rate[0]);
    std::printf("\n");
  }
  bool same = true;
  for (std::size_t k = 1; k < nt; ++k)
    same = same && std::memcmp(sims[k].particles().pos.data(), sims[0].particles().pos.data(), n * sizeof(Vec3)) == 0;
  std::printf("final positions bit-identical across thread counts: %s\n", same ? "yes" : "NO");
  // the f-quantile of v, linear between ranks (median() is its f = 0.5)
  const auto quantile = [](std::vector<double> v, double f) {
    std::sort(v.begin(), v.end());
    const double x = f * static_cast<double>(v.size() - 1);
    const auto i = static_cast<std::size_t>(x);
    return i + 1 < v.size() ? v[i] + (x - static_cast<double>(i)) * (v[i + 1] - v[i]) : v[i];
  };
  for (std::size_t k = 0; k < nt; ++k) {
    std::printf("result-interleaved: threads=%d rate=%.6e", o.threads[k], median(rates[k]));
    if (k > 0)
      std::printf(" speedup_vs_%d=%.3f q1=%.3f q3=%.3f min=%.3f max=%.3f", o.threads[0], quantile(ratios[k], 0.5),
                  quantile(ratios[k], 0.25), quantile(ratios[k], 0.75), quantile(ratios[k], 0.0),
                  quantile(ratios[k], 1.0));
    std::printf(" bursts=%d steps=%ld N=%zu\n", o.bursts, o.steps, n);
  }
  return same ? 0 : 1;
}

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress lines appear at once when piped (tee)
  Options o = parse(argc, argv);
  Simulation prepared = loadOrPrepare(o.cache);
  if (o.settledSkin) o.skin = settledSkin(prepared, o);
  const std::size_t n = prepared.particles().size() * static_cast<std::size_t>(o.tile[0] * o.tile[1] * o.tile[2]);

  {
    Simulation s0 = measuredScene(prepared, 1, o);
    const auto counts = contactCounts(s0);
    const double p0 = s0.contactStress().trace() / 3.0;
    const Mat3& H = s0.cell().matrix();
    std::printf("scene: N = %zu, cell %.6g x %.6g x %.6g mm, solid fraction %.4f\n", n, H(0, 0) * 1e3,
                H(1, 1) * 1e3, H(2, 2) * 1e3, s0.particles().solidVolume() / s0.cell().volume());
    std::printf("step 0: p = %.6g Pa  Z = 2C/N = %.6f  (C = %zu, pairs in list %zu)\n", p0, counts.coordination,
                counts.contacts, s0.contacts().size());
    std::printf("numerics: dt = %.3g s, skin = %.6g m, energy tracking %s, steps %ld, repeats %d, order %s\n",
                s0.timeStep(), s0.skin(), o.trackEnergy ? "on" : "off", o.steps, o.repeats,
                o.order == Options::Order::Morton ? "morton" : o.order == Options::Order::File ? "file" : "shuffled");
    if (!o.exportLammps.empty()) {
      writeLammpsData(o.exportLammps, s0.particles(), s0.cell(), s0.materials());
      const Material& m = s0.materials().at(0);
      // machine-readable line for bench/lammps_side_by_side.sh
      // LAMMPS keeps one skin through its run: it gets the one FabricLab's automatic skin settles to on this
      // packing, from a short untimed run of the untiled packing; FabricLab starts from its widest skin and
      // narrows it within its own timed steps (it pays that rebuild, LAMMPS does not)
      std::printf("export: file=%s N=%zu E=%.17g nu=%.17g mu=%.17g rho=%.17g skin=%.17g dt=%.17g p0=%.17g "
                  "Z0=%.17g\n",
                  o.exportLammps.c_str(), n, m.youngModulus, m.poissonRatio, m.friction, m.density,
                  settledSkin(prepared, o), s0.timeStep(), p0, counts.coordination);
    }
  }

  if (o.bursts > 0) return interleaved(prepared, o, n);

  struct Result {
    int threads;
    double median, lo, hi;  // particle-steps/s
    StageProfile profile;
    std::vector<Vec3> finalPos;
    std::uint64_t fingerprint = 0;  // of the final state, to compare builds (bench/ab.sh)
    std::size_t pairsEnd = 0;
    double pEnd = 0, zEnd = 0, skinEnd = 0;  // skinEnd: the list's skin at the end (automatic: core/verlet_skin.hpp)
    std::vector<std::size_t> edges;  // where the threads' chunks began at the end (core/share_balance.hpp)
  };
  std::vector<Result> results;
  double memoryPerParticle = 0.0, peakResident = 0.0;
  for (int t : o.threads) {
    std::vector<double> rates;
    Result res{t, 0, 0, 0, {}, {}, 0, 0, 0, 0, 0, {}};
    std::vector<StageProfile> profiles;
    for (int r = 0; r < o.repeats; ++r) {
      Simulation sim = measuredScene(prepared, t, o);
      const auto t0 = std::chrono::steady_clock::now();
      sim.run(o.steps);
      const double s = seconds(t0);
      if (results.empty() && r == 0) {
        memoryPerParticle = static_cast<double>(sim.memoryBytes()) / static_cast<double>(n);
        peakResident = residentBytes();
      }
      rates.push_back(static_cast<double>(n) * static_cast<double>(o.steps) / s);
      profiles.push_back(sim.profile());
      if (r == 0) {
        res.finalPos.assign(sim.particles().pos.begin(), sim.particles().pos.end());
        res.fingerprint = stateFingerprint(sim);
        res.pEnd = sim.contactStress().trace() / 3.0;
        res.zEnd = contactCounts(sim).coordination;
        res.skinEnd = sim.skin();
        res.pairsEnd = sim.contacts().size();
        res.edges = sim.threadBoundary().chunkBegin;
      }
    }
    res.median = median(rates);
    res.lo = *std::min_element(rates.begin(), rates.end());
    res.hi = *std::max_element(rates.begin(), rates.end());
    // profile of the run closest to the median
    std::size_t best = 0;
    for (std::size_t r = 0; r < rates.size(); ++r)
      if (std::abs(rates[r] - res.median) < std::abs(rates[best] - res.median)) best = r;
    res.profile = profiles[best];
    results.push_back(std::move(res));
  }

  std::printf("\nmemory: %.0f bytes per particle in the engine's arrays (Simulation::memoryBytes); process "
              "resident %.0f MB after the first run (includes the cached packing and LAMMPS-export scene)\n",
              memoryPerParticle, peakResident / 1e6);
  std::printf("%-8s %14s %14s %14s %10s %14s\n", "threads", "median p-st/s", "min", "max", "rebuilds",
              "stolen/step");
  for (const Result& r : results)
    std::printf("%-8d %14.4e %14.4e %14.4e %10ld %14.2f\n", r.threads, r.median, r.lo, r.hi, r.profile.rebuilds,
                static_cast<double>(r.profile.stolenRuns) / static_cast<double>(std::max(1L, r.profile.steps)));
  for (const Result& r : results) {
    std::printf("profile, %d thread(s) [s, share]:", r.threads);
    const double tot = r.profile.total();
    for (int s = 0; s < static_cast<int>(Stage::Count); ++s)
      std::printf("  %s %.3f (%.0f%%)", stageName(static_cast<Stage>(s)), r.profile.seconds[s],
                  100.0 * r.profile.seconds[s] / tot);
    std::printf("  (the kick holds the next drift in %ld of %ld steps: Simulation::run)\n", r.profile.fusedKicks,
                r.profile.steps);
    if (r.threads > 1) {
      std::printf("shares, %d threads: %s, made again %ld times; last edges (pair chunks):", r.threads,
                  o.evenShares ? "equal (--shares even)" : "measured", r.profile.shareChanges);
      for (std::size_t e : r.edges) std::printf(" %zu", e);
      std::printf(" (first repeat)\n");
    }
  }
  for (const Result& r : results)
    std::printf("after %ld steps, %d thread(s): p = %.6g Pa, Z = %.6f, skin = %.6g m, pairs in list %zu\n", o.steps,
                r.threads, r.pEnd, r.zEnd, r.skinEnd, r.pairsEnd);
  if (results.size() > 1) {
    for (std::size_t k = 1; k < results.size(); ++k)
      std::printf("speed-up %d vs %d threads: %.3f\n", results[k].threads, results[0].threads,
                  results[k].median / results[0].median);
    bool same = true;
    for (std::size_t k = 1; k < results.size(); ++k)
      same = same && std::memcmp(results[k].finalPos.data(), results[0].finalPos.data(), n * sizeof(Vec3)) == 0;
    std::printf("final positions bit-identical across thread counts: %s\n", same ? "yes" : "NO");
    if (!same) return 1;
  }
  // same bits as another build? (bench/ab.sh compares this line between its two builds)
  std::printf("state fingerprint after %ld steps: %016llx\n", o.steps,
              static_cast<unsigned long long>(results[0].fingerprint));
  // machine-readable summary
  for (const Result& r : results)
    std::printf("result: threads=%d rate=%.6e ns_per_particle_step=%.3f N=%zu bytes_per_particle=%.0f\n", r.threads,
                r.median, 1e9 / r.median, n, memoryPerParticle);
  return 0;
}
