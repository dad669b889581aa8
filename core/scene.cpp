#include "scene.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "errors.hpp"

namespace fl {

using nlohmann::json;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

SchemaField num(std::string section, std::string key, std::string unit, std::string def, double lo, double hi,
                bool loOpen, bool hiOpen, std::string help) {
  SchemaField f;
  f.section = std::move(section);
  f.key = std::move(key);
  f.kind = "number";
  f.unit = std::move(unit);
  f.defaultValue = std::move(def);
  f.min = lo;
  f.max = hi;
  f.minOpen = loOpen;
  f.maxOpen = hiOpen;
  f.help = std::move(help);
  return f;
}
SchemaField integer(std::string section, std::string key, std::string def, double lo, double hi, std::string help) {
  SchemaField f = num(std::move(section), std::move(key), "", std::move(def), lo, hi, false, false, std::move(help));
  f.kind = "integer";
  return f;
}
SchemaField boolean(std::string section, std::string key, std::string def, std::string help) {
  SchemaField f;
  f.section = std::move(section);
  f.key = std::move(key);
  f.kind = "bool";
  f.defaultValue = std::move(def);
  f.help = std::move(help);
  return f;
}
SchemaField text(std::string section, std::string key, std::string def, std::string help) {
  SchemaField f;
  f.section = std::move(section);
  f.key = std::move(key);
  f.kind = "string";
  f.defaultValue = std::move(def);
  f.help = std::move(help);
  return f;
}
SchemaField choice(std::string section, std::string key, std::string def, std::vector<std::string> choices,
                   std::string help) {
  SchemaField f;
  f.section = std::move(section);
  f.key = std::move(key);
  f.kind = "choice";
  f.defaultValue = std::move(def);
  f.choices = std::move(choices);
  f.help = std::move(help);
  return f;
}
SchemaField list(std::string section, std::string key, std::string unit, std::string def, double lo, double hi,
                 std::string help) {
  SchemaField f = num(std::move(section), std::move(key), std::move(unit), std::move(def), lo, hi, true, false,
                      std::move(help));
  f.kind = "number list";
  return f;
}

const std::vector<std::string> kStageTypes = {"isotropic_compression", "hold", "triaxial", "k0", "cyclic",
                                               "prestrain"};

std::vector<SchemaField> makeSchema() {
  std::vector<SchemaField> s;
  s.push_back(text("scene", "name", "scene", "Name shown in the GUI and in outputs."));
  // material
  s.push_back(text("material", "name", "glass", "Material name."));
  s.push_back(num("material", "shear_modulus", "Pa", "28.688e9", 0, 1e13, true, false,
                  "Particle shear modulus G (paper Table 1: 28.688 GPa)."));
  s.push_back(num("material", "poisson_ratio", "-", "0.22", 0, 0.5, false, true, "Poisson's ratio nu (paper: 0.22)."));
  s.push_back(num("material", "density", "kg/m^3", "2570", 0, 1e5, true, false, "Particle density rho (paper: 2570)."));
  s.push_back(num("material", "friction", "-", "0.235", 0, 10, false, false,
                  "Interparticle friction mu used for shearing (paper: 0.235)."));
  // specimen
  s.push_back(choice("specimen", "source", "gas", {"gas", "checkpoint", "csv", "lammps"},
                     "Where the specimen comes from: a random gas, a FabricLab checkpoint, or a packing file."));
  s.push_back(integer("specimen", "count", "4000", 1, 5e7, "Number of particles (gas)."));
  s.push_back(num("specimen", "solid_fraction", "-", "0.3", 0, 0.4, true, false,
                  "Solid fraction of the initial random gas (no overlaps)."));
  s.push_back(integer("specimen", "seed", "1", 0, 9007199254740992.0, "Random seed of the gas."));
  s.push_back(list("specimen", "diameters", "m", "[0.8e-3, 0.9e-3, 1.0e-3, 1.1e-3, 1.2e-3, 1.3e-3, 1.4e-3]", 0, 1,
                   "Particle diameters of the size distribution (paper: seven sizes, mean 1.1 mm)."));
  s.push_back(list("specimen", "fractions", "-", "[1, 1, 1, 1, 1, 1, 1]", 0, kInf,
                   "Weights of the diameters (normalised); number or mass fractions per 'basis'."));
  s.push_back(choice("specimen", "basis", "number", {"number", "mass"}, "Whether 'fractions' count particles or mass."));
  s.push_back(text("specimen", "path", "", "File for source checkpoint/csv/lammps, relative to the scene file. A csv/lammps packing is put in Z-order for speed; each particle keeps its file row (from 0) as id."));
  // numerics
  s.push_back(num("numerics", "time_step_factor", "-", "0.25", 0, 1, true, false,
                  "Time step as a fraction of the Rayleigh time step (used when time_step = 0)."));
  s.push_back(num("numerics", "time_step", "s", "0", 0, 1, false, false, "Fixed time step; 0 = from time_step_factor."));
  s.push_back(num("numerics", "local_damping", "-", "0", 0, 1, false, true, "Cundall local non-viscous damping alpha."));
  s.push_back(num("numerics", "restitution", "-", "1", kMinRestitution, 1, false, false,
                  "Restitution coefficient setting viscous contact damping (1 = none; at least 0.01, where the "
                  "damping is already ~4 times critical)."));
  s.push_back(num("numerics", "density_scale", "-", "1", 1, 1e12, false, false,
                  "Mass scaling factor (>= 1) to enlarge the time step in quasi-static runs; always reported."));
  s.push_back(num("numerics", "skin", "m", "0", 0, 1, false, false, "Verlet skin; 0 = automatic: 0.1 x mean diameter at first, then adapted at rebuilds to how fast the particles move (0.002-0.1 x mean diameter)."));
  s.push_back(integer("numerics", "threads", "0", 0, 1024, "OpenMP threads; 0 = all cores. Results do not depend on it."));
  s.push_back(boolean("numerics", "track_energy", "true", "Accumulate the energy ledger every step."));
  s.push_back(choice("numerics", "tangential_model", tangentialModelName(TangentialModel::MindlinNoSlip),
                     tangentialModelNames(),
                     "Tangential contact law: mindlin_no_slip (k_t = 8 G* a, Coulomb cap) or mindlin_deresiewicz "
                     "(micro-slip, Thornton's loading/unloading/reloading rules); see docs/contact-laws.md."));
  // servo
  s.push_back(num("servo", "gain", "-", "0.2", 0, 1, true, false, "Fraction of the stress error corrected per step."));
  s.push_back(num("servo", "max_strain_rate", "1/s", "1", 0, 1e6, true, false, "Cap on servo strain rates."));
  s.push_back(num("servo", "max_inertial_number", "-", "1e-3", 0, 1, true, false,
                  "Also caps servo strain rates at I sqrt(p_target/rho)/d (quasi-static)."));
  s.push_back(num("servo", "stress_tolerance", "-", "1e-3", 0, 1, true, true, "Relative stress tolerance of 'done'."));
  s.push_back(num("servo", "unbalanced_tolerance", "-", "1e-3", 0, 10, true, false,
                  "Unbalanced-force ratio below which a stress-controlled stage is done."));
  // output
  s.push_back(text("output", "directory", "", "Output folder, relative to the scene file (empty: none)."));
  s.push_back(integer("output", "sample_interval", "1000", 1, 1e12, "Steps between time-series samples outside cycles."));
  s.push_back(integer("output", "vtk_interval", "0", 0, 1e12, "Steps between ParaView snapshots (0: off)."));
  s.push_back(integer("output", "checkpoint_interval", "0", 0, 1e12, "Steps between checkpoints (0: off)."));
  s.push_back(boolean("output", "checkpoint_at_stage_end", "true", "Write a checkpoint at the end of every stage."));
  s.push_back(integer("output", "check_interval", "100", 1, 1e9, "Steps between completion checks."));
  // failure
  s.push_back(num("failure", "min_pressure_fraction", "-", "0.2", 0, 1, false, false,
                  "A cycle fails when its minimum p' < this x p' at the start of cycling."));
  s.push_back(num("failure", "min_stiffness_fraction", "-", "0.2", 0, 1, false, false,
                  "A cycle fails when its G_sec < this x G_sec of cycle 1."));
  // guards
  s.push_back(boolean("guards", "adaptive_time_step", "true",
                      "Shrink the time step when contacts stiffen (Hertz) so that dt <= stiffness_safety x 2 sqrt(m*/k)."));
  s.push_back(num("guards", "stiffness_safety", "-", "0.35", 0, 1, true, false,
                  "Fraction of the stiffness-based critical step allowed for dt."));
  s.push_back(num("guards", "max_overlap_ratio", "-", "0.05", 0, 1, true, false,
                  "Stop (with a diagnostic checkpoint) when an overlap exceeds this fraction of the smaller radius "
                  "(checked every output.check_interval steps)."));
  s.push_back(num("guards", "max_energy_error", "-", "0.25", 0, 1e6, true, false,
                  "Stop when the energy balance error exceeds this (energy created: the integration is unstable)."));
  s.push_back(num("guards", "warn_inertial_number", "-", "1e-3", 0, 1e6, true, false,
                  "Warn when a loading stage runs above this inertial number (no longer quasi-static)."));
  s.push_back(num("guards", "warn_energy_error", "-", "0.01", 0, 1e6, true, false,
                  "Warn when the energy balance error exceeds this."));
  // stages: 'type' and 'name' for all; the rest per type
  for (const auto& t : kStageTypes) {
    const std::string sec = "stage:" + t;
    s.push_back(text(sec, "name", t, "Stage name shown in logs and outputs."));
    s.push_back(integer(sec, "max_steps", "0", 0, 1e15, "Abort the run if the stage takes more steps (0: no limit)."));
    if (t == "isotropic_compression" || t == "k0" || t == "prestrain") {
      s.push_back(num(sec, "friction", "-", "", 0, 10, false, false,
                      "Friction during the stage, e.g. the compression friction mu_c (absent: unchanged)."));
      s.push_back(num(sec, "friction_after", "-", "", 0, 10, false, false,
                      "Friction set when the stage ends (absent: unchanged)."));
    }
    if (t == "isotropic_compression")
      s.push_back(num(sec, "pressure", "Pa", "", 0, 1e11, true, false, "Target mean effective stress p'. Required."));
    if (t == "hold") s.push_back(integer(sec, "steps", "0", 0, 1e15, "Steps to hold (0: until balanced)."));
    if (t == "k0") {
      s.push_back(num(sec, "pressure", "Pa", "", 0, 1e11, true, false, "Target p' (one of pressure, axial_stress, until_isotropic)."));
      s.push_back(num(sec, "axial_stress", "Pa", "", 0, 1e11, true, false, "Target vertical stress sigma'_v."));
      s.push_back(boolean(sec, "until_isotropic", "false", "Unload sigma'_v until it equals sigma'_h."));
    }
    if (t == "triaxial" || t == "cyclic" || t == "prestrain") {
      s.push_back(choice(sec, "drainage", "drained", {"drained", "undrained"},
                         "drained: lateral stresses held; undrained: constant volume."));
      s.push_back(num(sec, "strain_rate", "1/s", "0", 0, 1e6, false, false, "Axial strain rate; 0 = from inertial_number."));
      s.push_back(num(sec, "inertial_number", "-", "1e-4", 0, 1, true, false, "Target inertial number I when strain_rate = 0."));
    }
    if (t == "triaxial" || t == "prestrain")
      s.push_back(num(sec, "axial_strain", "-", "", -1, 1, false, false,
                      "Axial strain to apply (compression positive; negative = extension). Required."));
    if (t == "prestrain")
      s.push_back(num(sec, "pressure", "Pa", "", 0, 1e11, true, false, "p' to re-consolidate to after the pre-strain. Required."));
    if (t == "cyclic") {
      s.push_back(num(sec, "amplitude", "-", "", 0, 0.5, true, false, "Single amplitude of axial strain (paper: 2.3e-4). Required."));
      s.push_back(integer(sec, "cycles", "", 1, 1e7, "Number of cycles. Required."));
      s.push_back(integer(sec, "samples_per_cycle", "40", 8, 1e6, "Samples per cycle, evenly spaced in strain."));
    }
  }
  return s;
}

std::string rangeText(const SchemaField& f) {
  std::ostringstream o;
  if (f.kind == "choice") {
    o << "one of {";
    for (std::size_t k = 0; k < f.choices.size(); ++k) o << (k ? ", " : "") << f.choices[k];
    o << "}";
    return o.str();
  }
  if (f.kind == "bool") return "true or false";
  if (f.kind == "string") return "text";
  o << (f.minOpen ? "(" : "[") << f.min << ", ";
  if (std::isinf(f.max)) o << "inf)";
  else o << f.max << (f.maxOpen ? ")" : "]");
  return o.str();
}

// Validates one object against the fields of `section`, fills defaults; returns the completed object.
json completeSection(const json& in, const std::string& section, const std::string& where,
                     const std::string& file) {
  if (!in.is_object()) throw InputError(file + ": '" + where + "' must be an object");
  std::map<std::string, const SchemaField*> fields;
  for (const auto& f : sceneSchema())
    if (f.section == section) fields[f.key] = &f;
  json out = json::object();
  for (auto it = in.begin(); it != in.end(); ++it) {
    if (where.rfind("stages[", 0) == 0 && it.key() == "type") continue;
    auto f = fields.find(it.key());
    if (f == fields.end()) {
      std::string allowed;
      for (auto& [k, _] : fields) allowed += (allowed.empty() ? "" : ", ") + k;
      throw InputError(file + ": unknown field '" + where + "." + it.key() + "'; allowed: " + allowed);
    }
  }
  for (auto& [key, fp] : fields) {
    const SchemaField& f = *fp;
    const std::string name = where + "." + key;
    json v;
    if (in.contains(key)) {
      v = in.at(key);
    } else if (!f.defaultValue.empty() || f.kind == "string") {
      if (f.kind == "string" || f.kind == "choice") v = f.defaultValue;
      else v = json::parse(f.defaultValue);
    } else {
      continue;  // optional or required-without-default: checked by the caller
    }
    auto bad = [&](const std::string& got) {
      throw InputError(file + ": " + name + " = " + got + " is not allowed; expected " + f.kind + " " + rangeText(f) +
                       (f.unit.empty() || f.unit == "-" ? "" : " " + f.unit));
    };
    auto checkNumber = [&](const json& x) {
      if (!x.is_number()) bad(x.dump());
      const double d = x.get<double>();
      if (!std::isfinite(d)) bad(x.dump());
      if (d < f.min || d > f.max || (f.minOpen && d == f.min) || (f.maxOpen && d == f.max)) bad(x.dump());
      if (f.kind == "integer" && std::floor(d) != d) bad(x.dump());
    };
    if (f.kind == "number" || f.kind == "integer") checkNumber(v);
    else if (f.kind == "number list") {
      if (!v.is_array() || v.empty()) bad(v.dump());
      for (const auto& x : v) checkNumber(x);
    } else if (f.kind == "bool") {
      if (!v.is_boolean()) bad(v.dump());
    } else if (f.kind == "string") {
      if (!v.is_string()) bad(v.dump());
    } else if (f.kind == "choice") {
      if (!v.is_string()) bad(v.dump());
      bool ok = false;
      for (auto& c : f.choices) ok |= v.get<std::string>() == c;
      if (!ok) bad(v.dump());
    }
    out[key] = v;
  }
  return out;
}

double optNumber(const json& j, const char* key) { return j.contains(key) ? j.at(key).get<double>() : -1.0; }

void require(const json& j, const char* key, const std::string& where, const std::string& file) {
  if (!j.contains(key)) throw InputError(file + ": " + where + "." + key + " is required");
}

std::string resolvePath(const std::string& baseDir, const std::string& p) {
  if (p.empty() || baseDir.empty() || std::filesystem::path(p).is_absolute()) return p;
  return (std::filesystem::path(baseDir) / p).lexically_normal().string();
}

}  // namespace

const char* stageTypeName(StageType t) {
  switch (t) {
    case StageType::IsotropicCompression: return "isotropic_compression";
    case StageType::Hold: return "hold";
    case StageType::Triaxial: return "triaxial";
    case StageType::K0: return "k0";
    case StageType::Cyclic: return "cyclic";
  }
  return "?";
}
const char* drainageName(Drainage d) { return d == Drainage::Drained ? "drained" : "undrained"; }

const std::vector<SchemaField>& sceneSchema() {
  static const std::vector<SchemaField> s = makeSchema();
  return s;
}

Scene parseScene(const json& j, const std::string& file, const std::string& baseDir) {
  if (!j.is_object()) throw InputError(file + ": the scene must be a JSON object");
  static const std::set<std::string> sections = {"name",   "material", "specimen", "numerics", "servo",
                                                 "output", "failure",  "guards",   "stages"};
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!sections.count(it.key()))
      throw InputError(file + ": unknown section '" + it.key() +
                       "'; allowed: name, material, specimen, numerics, servo, stages, output, failure, guards");
  Scene s;
  s.file = file;
  {
    json top = json::object();
    if (j.contains("name")) top["name"] = j.at("name");
    s.name = completeSection(top, "scene", "scene", file).at("name").get<std::string>();
  }
  auto section = [&](const char* name) { return completeSection(j.value(name, json::object()), name, name, file); };
  const json m = section("material");
  s.material = Material::fromShearModulus(m.at("name"), m.at("shear_modulus"), m.at("poisson_ratio"),
                                          m.at("density"), m.at("friction"));
  const json sp = section("specimen");
  const std::string src = sp.at("source");
  s.specimen.source = src == "gas"          ? SpecimenSpec::Source::Gas
                      : src == "checkpoint" ? SpecimenSpec::Source::Checkpoint
                      : src == "csv"        ? SpecimenSpec::Source::Csv
                                            : SpecimenSpec::Source::Lammps;
  s.specimen.gas.count = sp.at("count").get<int>();
  s.specimen.gas.solidFraction = sp.at("solid_fraction");
  s.specimen.gas.seed = sp.at("seed").get<std::uint64_t>();
  s.specimen.gas.density = s.material.density;
  s.specimen.gas.sizes.diameters = sp.at("diameters").get<std::vector<double>>();
  s.specimen.gas.sizes.fractions = sp.at("fractions").get<std::vector<double>>();
  s.specimen.gas.sizes.basis =
      sp.at("basis") == "mass" ? SizeDistribution::Basis::Mass : SizeDistribution::Basis::Number;
  try {
    s.specimen.gas.sizes.validate();
  } catch (const InputError& e) {
    throw InputError(file + ": specimen: " + e.what());
  }
  s.specimen.path = resolvePath(baseDir, sp.at("path"));
  if (s.specimen.source != SpecimenSpec::Source::Gas && s.specimen.path.empty())
    throw InputError(file + ": specimen.path is required when specimen.source is '" + src + "'");
  const json nu = section("numerics");
  s.numerics.timeStepFactor = nu.at("time_step_factor");
  s.numerics.timeStep = nu.at("time_step");
  s.numerics.localDamping = nu.at("local_damping");
  s.numerics.restitution = nu.at("restitution");
  s.numerics.densityScale = nu.at("density_scale");
  s.numerics.skin = nu.at("skin");
  s.numerics.threads = nu.at("threads").get<int>();
  s.numerics.trackEnergy = nu.at("track_energy");
  {  // the schema has checked the name against the same table
    const auto model = tangentialModelFromName(nu.at("tangential_model").get<std::string>());
    if (!model)
      throw InputError(file + ": numerics.tangential_model = " + nu.at("tangential_model").dump() +
                       " is not allowed; expected one of {" + tangentialModelList() + "}");
    s.numerics.tangentialModel = *model;
  }
  const json sv = section("servo");
  s.servo.gain = sv.at("gain");
  s.servo.maxStrainRate = sv.at("max_strain_rate");
  s.servo.stressTolerance = sv.at("stress_tolerance");
  s.servo.unbalancedTolerance = sv.at("unbalanced_tolerance");
  s.maxInertialNumber = sv.at("max_inertial_number");
  const json out = section("output");
  s.output.directory = resolvePath(baseDir, out.at("directory"));
  s.output.sampleInterval = out.at("sample_interval").get<long>();
  s.output.vtkInterval = out.at("vtk_interval").get<long>();
  s.output.checkpointInterval = out.at("checkpoint_interval").get<long>();
  s.output.checkpointAtStageEnd = out.at("checkpoint_at_stage_end");
  s.output.checkInterval = out.at("check_interval").get<long>();
  const json fa = section("failure");
  s.failure.minPressureFraction = fa.at("min_pressure_fraction");
  s.failure.minStiffnessFraction = fa.at("min_stiffness_fraction");
  const json gu = section("guards");
  s.guards.adaptiveTimeStep = gu.at("adaptive_time_step");
  s.guards.stiffnessSafety = gu.at("stiffness_safety");
  s.guards.maxOverlapRatio = gu.at("max_overlap_ratio");
  s.guards.maxEnergyError = gu.at("max_energy_error");
  s.guards.warnInertialNumber = gu.at("warn_inertial_number");
  s.guards.warnEnergyError = gu.at("warn_energy_error");
  // stages
  const json stages = j.value("stages", json::array());
  if (!stages.is_array()) throw InputError(file + ": 'stages' must be a list");
  for (std::size_t k = 0; k < stages.size(); ++k) {
    const std::string where = "stages[" + std::to_string(k) + "]";
    const json& raw = stages[k];
    if (!raw.is_object() || !raw.contains("type") || !raw.at("type").is_string())
      throw InputError(file + ": " + where + ".type is required: one of isotropic_compression, hold, triaxial, k0, "
                                             "cyclic, prestrain");
    const std::string type = raw.at("type");
    bool known = false;
    for (auto& t : kStageTypes) known |= t == type;
    if (!known)
      throw InputError(file + ": " + where + ".type = \"" + type +
                       "\" is not allowed; expected one of isotropic_compression, hold, triaxial, k0, cyclic, prestrain");
    const json st = completeSection(raw, "stage:" + type, where, file);
    StageSpec g;
    g.name = st.at("name");
    g.maxSteps = st.at("max_steps").get<long>();
    g.friction = optNumber(st, "friction");
    g.frictionAfter = optNumber(st, "friction_after");
    if (st.contains("drainage")) {
      g.drainage = st.at("drainage") == "undrained" ? Drainage::Undrained : Drainage::Drained;
      g.strainRate = st.at("strain_rate");
      g.inertialNumber = st.at("inertial_number");
    }
    if (type == "isotropic_compression") {
      require(st, "pressure", where, file);
      g.type = StageType::IsotropicCompression;
      g.pressure = st.at("pressure");
    } else if (type == "hold") {
      g.type = StageType::Hold;
      g.steps = st.at("steps").get<long>();
    } else if (type == "triaxial") {
      require(st, "axial_strain", where, file);
      g.type = StageType::Triaxial;
      g.axialStrain = st.at("axial_strain");
      if (g.axialStrain == 0.0) throw InputError(file + ": " + where + ".axial_strain must not be 0");
    } else if (type == "k0") {
      g.type = StageType::K0;
      g.pressure = optNumber(st, "pressure");
      g.axialStress = optNumber(st, "axial_stress");
      g.untilIsotropic = st.at("until_isotropic");
      const int given = (g.pressure > 0) + (g.axialStress > 0) + g.untilIsotropic;
      if (given != 1)
        throw InputError(file + ": " + where + " needs exactly one of pressure, axial_stress, until_isotropic = true");
      if (g.pressure < 0) g.pressure = 0;
      if (g.axialStress < 0) g.axialStress = 0;
    } else if (type == "cyclic") {
      require(st, "amplitude", where, file);
      require(st, "cycles", where, file);
      g.type = StageType::Cyclic;
      g.amplitude = st.at("amplitude");
      g.cycles = st.at("cycles").get<int>();
      g.samplesPerCycle = st.at("samples_per_cycle").get<int>();
    } else if (type == "prestrain") {
      // pre-straining then re-consolidation (the paper's anisotropic fabric): two stages
      require(st, "axial_strain", where, file);
      require(st, "pressure", where, file);
      StageSpec shear = g;
      shear.type = StageType::Triaxial;
      shear.name = g.name + ": pre-strain";
      shear.axialStrain = st.at("axial_strain");
      shear.frictionAfter = -1;
      StageSpec back;
      back.type = StageType::IsotropicCompression;
      back.name = g.name + ": re-consolidation";
      back.pressure = st.at("pressure");
      back.frictionAfter = g.frictionAfter;
      back.maxSteps = g.maxSteps;
      s.stages.push_back(shear);
      s.stages.push_back(back);
      continue;
    }
    s.stages.push_back(g);
  }
  try {
    NumericsSettings check = s.numerics;
    if (check.threads == 0) check.threads = 1;  // 0 = all cores, resolved by the runner
    check.validate();
    s.servo.validate();
  } catch (const InputError& e) {
    throw InputError(file + ": " + e.what());
  }
  return s;
}

Scene loadScene(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw IoError(path + ": cannot open scene file");
  json j;
  try {
    j = json::parse(in, nullptr, true, /*ignore_comments=*/true);
  } catch (const json::exception& e) {  // parse_error, or out_of_range for a number like 1e999
    throw InputError(path + ": not valid JSON: " + e.what());
  }
  return parseScene(j, path, std::filesystem::path(path).parent_path().string());
}

std::string sceneToJson(const Scene& s) {
  json j;
  j["name"] = s.name;
  j["material"] = {{"name", s.material.name},
                   {"shear_modulus", s.material.shearModulus()},
                   {"poisson_ratio", s.material.poissonRatio},
                   {"density", s.material.density},
                   {"friction", s.material.friction}};
  static const char* sources[] = {"gas", "checkpoint", "csv", "lammps"};
  j["specimen"] = {{"source", sources[static_cast<int>(s.specimen.source)]},
                   {"count", s.specimen.gas.count},
                   {"solid_fraction", s.specimen.gas.solidFraction},
                   {"seed", s.specimen.gas.seed},
                   {"diameters", s.specimen.gas.sizes.diameters},
                   {"fractions", s.specimen.gas.sizes.fractions},
                   {"basis", s.specimen.gas.sizes.basis == SizeDistribution::Basis::Mass ? "mass" : "number"},
                   {"path", s.specimen.path}};
  j["numerics"] = {{"time_step_factor", s.numerics.timeStepFactor}, {"time_step", s.numerics.timeStep},
                   {"local_damping", s.numerics.localDamping},     {"restitution", s.numerics.restitution},
                   {"density_scale", s.numerics.densityScale},     {"skin", s.numerics.skin},
                   {"threads", s.numerics.threads},                {"track_energy", s.numerics.trackEnergy},
                   {"tangential_model", tangentialModelName(s.numerics.tangentialModel)}};
  j["servo"] = {{"gain", s.servo.gain},
                {"max_strain_rate", s.servo.maxStrainRate},
                {"max_inertial_number", s.maxInertialNumber},
                {"stress_tolerance", s.servo.stressTolerance},
                {"unbalanced_tolerance", s.servo.unbalancedTolerance}};
  j["output"] = {{"directory", s.output.directory},
                 {"sample_interval", s.output.sampleInterval},
                 {"vtk_interval", s.output.vtkInterval},
                 {"checkpoint_interval", s.output.checkpointInterval},
                 {"checkpoint_at_stage_end", s.output.checkpointAtStageEnd},
                 {"check_interval", s.output.checkInterval}};
  j["failure"] = {{"min_pressure_fraction", s.failure.minPressureFraction},
                  {"min_stiffness_fraction", s.failure.minStiffnessFraction}};
  j["guards"] = {{"adaptive_time_step", s.guards.adaptiveTimeStep},
                 {"stiffness_safety", s.guards.stiffnessSafety},
                 {"max_overlap_ratio", s.guards.maxOverlapRatio},
                 {"max_energy_error", s.guards.maxEnergyError},
                 {"warn_inertial_number", s.guards.warnInertialNumber},
                 {"warn_energy_error", s.guards.warnEnergyError}};
  json st = json::array();
  for (const StageSpec& g : s.stages) {
    json o = {{"type", stageTypeName(g.type)}, {"name", g.name}, {"max_steps", g.maxSteps}};
    const bool frictionStage = g.type == StageType::IsotropicCompression || g.type == StageType::K0;
    if (frictionStage && g.friction >= 0) o["friction"] = g.friction;
    if (frictionStage && g.frictionAfter >= 0) o["friction_after"] = g.frictionAfter;
    switch (g.type) {
      case StageType::IsotropicCompression: o["pressure"] = g.pressure; break;
      case StageType::Hold: o["steps"] = g.steps; break;
      case StageType::K0:
        if (g.untilIsotropic) o["until_isotropic"] = true;
        else if (g.axialStress > 0) o["axial_stress"] = g.axialStress;
        else o["pressure"] = g.pressure;
        break;
      case StageType::Triaxial:
      case StageType::Cyclic:
        o["drainage"] = drainageName(g.drainage);
        o["strain_rate"] = g.strainRate;
        o["inertial_number"] = g.inertialNumber;
        if (g.type == StageType::Triaxial) o["axial_strain"] = g.axialStrain;
        else {
          o["amplitude"] = g.amplitude;
          o["cycles"] = g.cycles;
          o["samples_per_cycle"] = g.samplesPerCycle;
        }
        break;
    }
    st.push_back(o);
  }
  j["stages"] = st;
  return j.dump(2);
}

std::string sceneReferenceMarkdown() {
  std::ostringstream o;
  o << "# Scene file reference\n\n"
    << "Generated from the schema in `core/scene.cpp` by `fabriclab-run --schema-doc`; the same schema validates\n"
    << "scene files and builds the GUI's parameter forms. Scene files are JSON (comments allowed). Units are SI;\n"
    << "stresses are compression-positive; the axial direction is z. A field with no default is required or,\n"
    << "where the help says so, optional.\n";
  std::string current;
  for (const auto& f : sceneSchema()) {
    if (f.section != current) {
      current = f.section;
      const std::string title = current.rfind("stage:", 0) == 0 ? "stages[]: type \"" + current.substr(6) + "\""
                                                                   : current == "scene" ? "top level" : current;
      o << "\n## " << title << "\n\n| field | kind | unit | default | allowed | meaning |\n|---|---|---|---|---|---|\n";
    }
    o << "| `" << f.key << "` | " << f.kind << " | " << (f.unit.empty() ? "" : f.unit) << " | "
      << (f.defaultValue.empty() ? "—" : "`" + f.defaultValue + "`") << " | " << rangeText(f) << " | " << f.help
      << " |\n";
  }
  return o.str();
}

}  // namespace fl
