// Numerical settings of a simulation and the critical time-step estimates.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "material.hpp"
#include "particle_store.hpp"

namespace fl {

// Tangential contact law (docs/contact-laws.md). The one name table below drives the scene field
// numerics.tangential_model, its validation message and the generated reference.
enum class TangentialModel : std::uint8_t {
  MindlinNoSlip = 0,       // k_t = 8 G* a, Coulomb cap, Thornton's unloading scaling (core/contact_kernels.hpp)
  MindlinDeresiewicz = 1,  // micro-slip, Thornton's loading/unloading/reloading rules (core/mindlin_deresiewicz.hpp)
};
struct TangentialModelName {
  TangentialModel model;
  const char* name;
};
inline constexpr std::array<TangentialModelName, 2> kTangentialModelNames{{
    {TangentialModel::MindlinNoSlip, "mindlin_no_slip"},
    {TangentialModel::MindlinDeresiewicz, "mindlin_deresiewicz"},
}};
inline const char* tangentialModelName(TangentialModel m) {
  for (const auto& e : kTangentialModelNames)
    if (e.model == m) return e.name;
  return "?";
}
inline std::optional<TangentialModel> tangentialModelFromName(std::string_view name) {
  for (const auto& e : kTangentialModelNames)
    if (name == e.name) return e.model;
  return std::nullopt;
}
inline std::vector<std::string> tangentialModelNames() {
  std::vector<std::string> v;
  for (const auto& e : kTangentialModelNames) v.emplace_back(e.name);
  return v;
}
// "mindlin_no_slip, mindlin_deresiewicz" (for messages)
inline std::string tangentialModelList() {
  std::string s;
  for (const auto& e : kTangentialModelNames) s += (s.empty() ? "" : ", ") + std::string(e.name);
  return s;
}
// True for a value of the enum (a corrupted checkpoint byte is not).
inline bool isTangentialModel(TangentialModel m) { return tangentialModelName(m)[0] != '?'; }

struct NumericsSettings {
  double timeStepFactor = 0.25;  // dt = factor x Rayleigh step (used when timeStep == 0) [-], (0, 1]
  double timeStep = 0.0;         // fixed dt [s]; 0 = from timeStepFactor
  double localDamping = 0.0;     // Cundall non-viscous damping alpha [-], [0, 1)
  double restitution = 1.0;      // contact restitution e setting viscous contact damping; 1 = none [-]
  double densityScale = 1.0;     // mass and inertia multiplier (>= 1), always reported [-]
  double skin = 0.0;             // Verlet skin [m]; 0 = automatic (core/verlet_skin.hpp)
  bool trackEnergy = true;       // accumulate elastic energy and dissipation every step
  int threads = 1;               // OpenMP threads; results are identical for any count
  TangentialModel tangentialModel = TangentialModel::MindlinNoSlip;  // last: checkpoints of state v2 end before it
  void validate() const;         // throws InputError
};

// Rayleigh time step (Li et al. 2005): pi r sqrt(rho/G) / (0.1631 nu + 0.8766), minimised over particles;
// rho includes density scaling. [s]
double rayleighTimeStep(const ParticleStore& p, const std::vector<Material>& materials, double densityScale);

}  // namespace fl
