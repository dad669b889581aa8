// Per-axis control of the periodic cell (after YADE's PeriTriaxController and MercuryDPM's
// StressStrainControlBoundary). Each principal axis k is either
//   StrainRate: eps_dot_k prescribed [1/s] (compression positive), or
//   Stress:     sigma_kk driven to a target [Pa], or
//   MeanStress: the axis moves so that p' = tr(sigma)/3 reaches the target [Pa] (K0 loading to a p').
// Coupling: isochoric() makes eps_dot_x = eps_dot_y = -eps_dot_z / 2 (constant volume, the paper's
// 'idealised undrained' shearing); K0 is x, y at StrainRate 0 with z under Stress or MeanStress.
// Servo law (per step): d eps_k = gain * (target - sigma_kk) / K_k, with K_k the packing's tangent
// stiffness for that axis (Simulation::axisStiffness(), summed by the pass; for MeanStress K_k / 3), then
// eps_dot = d eps / dt clamped to +-maxStrainRate. With no contacts (a gas) the axis moves at the cap.
// Done: every stress-controlled axis within stressTolerance (relative to its target, or absolute
// tolerance below 1 Pa targets) and the unbalanced-force ratio below unbalancedTolerance.
#pragma once

#include <array>

#include "cell_controller.hpp"

namespace fl {

enum class AxisMode { StrainRate, Stress, MeanStress };

struct AxisControl {
  AxisMode mode = AxisMode::StrainRate;
  double value = 0.0;  // strain rate [1/s] (compression positive) or stress target [Pa]
};

struct ServoSettings {
  double gain = 0.2;                 // fraction of the stress error corrected per step [-], (0, 1]
  double maxStrainRate = 1.0;        // cap on |eps_dot| of stress-controlled axes [1/s]
  double stressTolerance = 1e-3;     // relative [-]
  double unbalancedTolerance = 1e-3; // unbalanced-force ratio [-]
  void validate() const;
};

class AxisServo final : public CellController {
 public:
  AxisServo(const std::array<AxisControl, 3>& axes, const ServoSettings& settings, bool isochoric = false);

  Mat3 update(const Simulation& sim) override;

  void setAxis(int k, const AxisControl& c) { m_axes[k] = c; }
  const AxisControl& axis(int k) const { return m_axes[k]; }
  bool isochoric() const { return m_isochoric; }
  const ServoSettings& settings() const { return m_settings; }
  // stress axes within tolerance
  bool stressConverged(const Mat3& sigma) const;
  bool done(const Simulation& sim) const;
  // strain rates applied at the last update (compression positive) [1/s]
  const Vec3& strainRate() const { return m_rate; }
  void setStrainRate(const Vec3& r) { m_rate = r; }

 private:
  std::array<AxisControl, 3> m_axes;
  ServoSettings m_settings;
  bool m_isochoric = false;
  Vec3 m_rate = Vec3::Zero();
};

}  // namespace fl
