// Writes valid seed inputs for the fuzz corpus into <dir>/{checkpoint,csv,lammps}/: checkpoints of a tiny
// scene (before the run, in the first stage, in a cyclic stage with the servo and cycle state present),
// each both raw (mode byte 0) and as a bare payload (mode byte 1, see fuzz_checkpoint.cpp), and the CSV
// and LAMMPS exports of the same packing (CSV with mode byte 0 and 1, see fuzz_packing_csv.cpp).
// Usage: fuzz_make_seeds DIR
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/packing_io.hpp"
#include "core/runner.hpp"

namespace fs = std::filesystem;

namespace {
std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}
void spit(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }

constexpr std::size_t kHead = sizeof("FABRICLAB-CHECKPOINT") + 4 + 8;  // magic, version, payload size

void checkpointSeeds(const fl::Runner& r, const fs::path& dir, const std::string& tag) {
  const fs::path tmp = dir / (tag + ".ckpt");
  r.writeCheckpoint(tmp.string());
  const std::string file = slurp(tmp);
  fs::remove(tmp);
  spit(dir / ("raw-" + tag), std::string(1, '\0') + file);
  spit(dir / ("payload-" + tag), std::string(1, '\1') + file.substr(kHead, file.size() - kHead - 8));
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: fuzz_make_seeds DIR\n";
    return 2;
  }
  const fs::path root = argv[1];
  for (const char* d : {"checkpoint", "csv", "lammps"}) fs::create_directories(root / d);
  const auto scene = nlohmann::json::parse(R"({
    "name": "fuzz seed",
    "specimen": {"count": 40, "solid_fraction": 0.3, "seed": 3},
    "numerics": {"time_step_factor": 0.3, "local_damping": 0.1, "density_scale": 100, "threads": 1},
    "servo": {"max_strain_rate": 20, "max_inertial_number": 0.02, "unbalanced_tolerance": 0.02},
    "output": {"sample_interval": 200, "check_interval": 50},
    "stages": [
      {"type": "isotropic_compression", "pressure": 50000, "friction": 0.1, "friction_after": 0.235},
      {"type": "cyclic", "drainage": "undrained", "amplitude": 2e-4, "cycles": 2, "samples_per_cycle": 8,
       "strain_rate": 0.5}
    ]
  })");
  fl::Runner r(fl::parseScene(scene, "fuzz-seed.json"));
  checkpointSeeds(r, root / "checkpoint", "start");
  r.advance(300);
  checkpointSeeds(r, root / "checkpoint", "compressing");
  long guard = 0;
  while (!r.finished() && r.stageIndex() == 0 && guard++ < 400) r.advance(500);
  r.advance(400);  // inside the cyclic stage: servo, cycle state
  checkpointSeeds(r, root / "checkpoint", "cyclic");
  while (!r.finished() && r.cycles().empty() && guard++ < 800) r.advance(500);
  checkpointSeeds(r, root / "checkpoint", "cycles");

  const auto& sim = r.simulation();
  const fs::path csv = root / "csv" / "packing.csv", lmp = root / "lammps" / "packing.data";
  fl::writePackingCsv(csv.string(), sim.particles(), sim.cell());
  fl::writeLammpsData(lmp.string(), sim.particles(), sim.cell(), sim.materials());
  const std::string c = slurp(csv);
  spit(root / "csv" / "seed-own-cell", std::string(1, '\0') + c);
  // The same rows without the '# cell' line, read with a caller-given cell (mode byte 1).
  std::string noCell;
  std::istringstream lines(c);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("# cell", 0) != 0) noCell += line + "\n";
  spit(root / "csv" / "seed-given-cell", std::string(1, '\1') + noCell.substr(0, 4000));
  fs::remove(csv);
  std::cout << "seeds in " << root << ": stage " << r.stageIndex() << ", " << r.cycles().size() << " cycles, "
            << sim.stepCount() << " steps\n";
  return 0;
}
