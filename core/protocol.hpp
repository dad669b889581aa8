// Loading protocols as data: an ordered list of stages, each with its targets and completion criterion
// (after HOOMD's Variant/Trigger idea: no script code, just values). The runner (runner.hpp) executes them.
// Axial = z, compression positive, stresses in Pa, strains logarithmic, measured from the stage start.
#pragma once

#include <string>
#include <vector>

namespace fl {

enum class StageType {
  IsotropicCompression,  // all three axes servo-controlled to `pressure`
  Hold,                  // hold the stress of the stage start for `steps` (or until balanced)
  Triaxial,              // monotonic to `axialStrain`: drained (lateral stresses held) or undrained (constant volume)
  K0,                    // eps_r = 0; axial servo to `axialStress` or `pressure`, or unloading until isotropic
  Cyclic,                // strain-controlled cycles of +-`amplitude` about the start, `cycles` times
};
enum class Drainage { Drained, Undrained };

const char* stageTypeName(StageType t);
const char* drainageName(Drainage d);

struct StageSpec {
  std::string name;
  StageType type = StageType::IsotropicCompression;
  // stress targets
  double pressure = 0.0;         // p' target [Pa] (isotropic; K0 when axialStress == 0)
  double axialStress = 0.0;      // K0: sigma'_v target [Pa]
  bool untilIsotropic = false;   // K0: unload the axial stress until sigma'_v = sigma'_h
  // friction changes
  double friction = -1.0;        // friction during the stage (< 0: unchanged) [-]
  double frictionAfter = -1.0;   // friction set when the stage ends (< 0: unchanged) [-]
  // strain-controlled loading
  Drainage drainage = Drainage::Drained;
  double axialStrain = 0.0;      // triaxial: axial strain to apply, compression positive [-]
  double amplitude = 0.0;        // cyclic: single amplitude of eps_a [-]
  int cycles = 0;                // cyclic: number of cycles
  double strainRate = 0.0;       // axial strain rate [1/s]; 0 = from inertialNumber
  double inertialNumber = 1e-4;  // target I when strainRate == 0 [-]
  int samplesPerCycle = 40;      // cyclic: samples per cycle (evenly spaced in strain)
  // hold
  long steps = 0;                // hold: number of steps (0 = until balanced)
  // completion
  long maxSteps = 0;             // stop with an error after this many steps (0 = no limit)
};

}  // namespace fl
