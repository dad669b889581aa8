#include "numerics.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "errors.hpp"

namespace fl {

void NumericsSettings::validate() const {
  auto bad = [](const std::string& field, double v, const std::string& range) {
    throw InputError("numerics." + field + " = " + std::to_string(v) + " is outside the allowed range " + range);
  };
  if (!(timeStepFactor > 0.0 && timeStepFactor <= 1.0)) bad("timeStepFactor", timeStepFactor, "(0, 1]");
  if (!(timeStep >= 0.0)) bad("timeStep", timeStep, "[0, inf) s");
  if (!(localDamping >= 0.0 && localDamping < 1.0)) bad("localDamping", localDamping, "[0, 1)");
  if (!(restitution >= kMinRestitution && restitution <= 1.0)) bad("restitution", restitution, "[0.01, 1]");
  if (!(densityScale >= 1.0)) bad("densityScale", densityScale, "[1, inf)");
  if (!(skin >= 0.0)) bad("skin", skin, "[0, inf) m");
  if (threads < 1 || threads > 1024) bad("threads", threads, "[1, 1024]");
}

double rayleighTimeStep(const ParticleStore& p, const std::vector<Material>& materials, double densityScale) {
  double dt = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Material& m = materials[p.material[i]];
    const double t = kPi * p.radius[i] * std::sqrt(m.density * densityScale / m.shearModulus()) /
                     (0.1631 * m.poissonRatio + 0.8766);
    dt = std::min(dt, t);
  }
  return dt;
}

}  // namespace fl
