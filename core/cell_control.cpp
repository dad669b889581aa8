#include "cell_control.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "errors.hpp"
#include "simulation.hpp"

namespace fl {

void ServoSettings::validate() const {
  auto bad = [](const std::string& f, double v, const char* range) {
    throw InputError("servo." + f + " = " + std::to_string(v) + " is outside the allowed range " + range);
  };
  if (!(gain > 0.0 && gain <= 1.0)) bad("gain", gain, "(0, 1]");
  if (!(maxStrainRate > 0.0)) bad("maxStrainRate", maxStrainRate, "(0, inf) 1/s");
  if (!(stressTolerance > 0.0 && stressTolerance < 1.0)) bad("stressTolerance", stressTolerance, "(0, 1)");
  if (!(unbalancedTolerance > 0.0)) bad("unbalancedTolerance", unbalancedTolerance, "(0, inf)");
}

AxisServo::AxisServo(const std::array<AxisControl, 3>& axes, const ServoSettings& settings, bool isochoric)
    : m_axes(axes), m_settings(settings), m_isochoric(isochoric) {
  m_settings.validate();
  if (isochoric && axes[2].mode == AxisMode::MeanStress)
    throw InputError("constant-volume control needs the axial axis under strain-rate or stress control");
}

Mat3 AxisServo::update(const Simulation& sim) {
  const Mat3& s = sim.contactStress();
  const Vec3& K = sim.axisStiffness();  // the pass's sum: nothing is measured per step
  const double dt = sim.timeStep();
  const double cap = m_settings.maxStrainRate;
  for (int k = 0; k < 3; ++k) {
    const AxisControl& a = m_axes[k];
    if (a.mode == AxisMode::StrainRate) {
      m_rate[k] = a.value;
      continue;
    }
    const double err = a.mode == AxisMode::Stress ? a.value - s(k, k) : a.value - s.trace() / 3.0;
    const double stiff = a.mode == AxisMode::Stress ? K[k] : K[k] / 3.0;
    double rate = stiff > 0.0 ? m_settings.gain * err / stiff / dt : (err > 0 ? cap : -cap);
    m_rate[k] = std::clamp(rate, -cap, cap);
  }
  if (m_isochoric) m_rate.x() = m_rate.y() = -0.5 * m_rate.z();
  Mat3 L = Mat3::Zero();
  L.diagonal() = -m_rate;  // compression-positive rate shortens the cell
  return L;
}

bool AxisServo::stressConverged(const Mat3& s) const {
  for (int k = 0; k < 3; ++k) {
    const AxisControl& a = m_axes[k];
    if (a.mode == AxisMode::StrainRate) continue;
    const double v = a.mode == AxisMode::Stress ? s(k, k) : s.trace() / 3.0;
    const double tol = std::max(std::abs(a.value) * m_settings.stressTolerance, 1.0);
    if (std::abs(v - a.value) > tol) return false;
  }
  return true;
}

bool AxisServo::done(const Simulation& sim) const {
  return stressConverged(sim.contactStress()) && sim.unbalancedForceRatio() < m_settings.unbalancedTolerance;
}

}  // namespace fl
