// Scene files (JSON, nlohmann-json): material, specimen, numerics, servo, stages, outputs, failure.
// One schema in code (sceneSchema(): name, unit, default, range, help) drives validation, defaults and the
// generated reference document (docs/scene-reference.md, `fabriclab-run --schema-doc`).
// Errors name the file, the field and what is allowed:
//   "scenes/x.json: numerics.time_step_factor = 2 is outside the allowed range (0, 1]".
// Relative paths in a scene (specimen.path, output.directory) are relative to the scene file.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "cell_control.hpp"
#include "cycle_analysis.hpp"
#include "gas_generator.hpp"
#include "material.hpp"
#include "numerics.hpp"
#include "protocol.hpp"

namespace fl {

struct SpecimenSpec {
  enum class Source { Gas, Checkpoint, Csv, Lammps };
  Source source = Source::Gas;
  GasSpec gas;       // Source::Gas
  std::string path;  // other sources (resolved to an absolute or scene-relative path)
};

struct OutputSpec {
  std::string directory;            // empty: no files (GUI, tests)
  long sampleInterval = 1000;       // steps between time-series samples outside cyclic stages
  long vtkInterval = 0;             // steps between ParaView snapshots (0: off)
  long checkpointInterval = 0;      // steps between checkpoints (0: off)
  bool checkpointAtStageEnd = true; // a checkpoint after every stage, named after it
  long checkInterval = 100;         // steps between completion checks (unbalanced force is O(N))
};

// Numerical guards (runner): the time step follows the contact stiffness, blow-ups stop the run with a
// diagnostic checkpoint, and leaving the quasi-static regime or drifting energy is warned about.
struct GuardSettings {
  bool adaptiveTimeStep = true;    // keep dt <= stiffnessSafety x 2 sqrt(m*/k_max)
  double stiffnessSafety = 0.35;   // [-]
  double maxOverlapRatio = 0.05;   // stop when delta / r exceeds this [-]
  double maxEnergyError = 0.25;    // stop when the energy balance error exceeds this (energy created) [-]
  double warnInertialNumber = 1e-3;  // warn above this inertial number in loading stages [-]
  double warnEnergyError = 0.01;     // warn above this energy balance error [-]
};

struct Scene {
  std::string name;
  std::string file;  // the file it came from ("" if built in code)
  Material material = Material::paperGlass();
  SpecimenSpec specimen;
  NumericsSettings numerics;
  ServoSettings servo;
  double maxInertialNumber = 1e-3;  // caps servo strain rates at I_max sqrt(p_target/rho)/d [-]
  std::vector<StageSpec> stages;
  OutputSpec output;
  FailureCriteria failure;
  GuardSettings guards;
};

// One schema entry.
struct SchemaField {
  std::string section;  // "material", "specimen", "numerics", ..., or "stage:<type>"
  std::string key;
  std::string kind;     // "number", "integer", "bool", "string", "choice", "number list"
  std::string unit;
  std::string defaultValue;  // as text ("" = required)
  double min = 0, max = 0;   // numeric range
  bool minOpen = false, maxOpen = false;  // open interval ends
  std::vector<std::string> choices;       // for "choice"
  std::string help;
};
const std::vector<SchemaField>& sceneSchema();
std::string sceneReferenceMarkdown();

Scene loadScene(const std::string& path);                                   // throws InputError/IoError
Scene parseScene(const nlohmann::json& j, const std::string& sourceName, const std::string& baseDir = "");
std::string sceneToJson(const Scene& s);  // resolved scene (all defaults filled), re-loadable

}  // namespace fl
