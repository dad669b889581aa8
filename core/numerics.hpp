// Numerical settings of a simulation and the critical time-step estimates.
#pragma once

#include <vector>

#include "material.hpp"
#include "particle_store.hpp"

namespace fl {

struct NumericsSettings {
  double timeStepFactor = 0.25;  // dt = factor x Rayleigh step (used when timeStep == 0) [-], (0, 1]
  double timeStep = 0.0;         // fixed dt [s]; 0 = from timeStepFactor
  double localDamping = 0.0;     // Cundall non-viscous damping alpha [-], [0, 1)
  double restitution = 1.0;      // contact restitution e setting viscous contact damping; 1 = none [-]
  double densityScale = 1.0;     // mass and inertia multiplier (>= 1), always reported [-]
  double skin = 0.0;             // Verlet skin [m]; 0 = 0.1 x mean diameter
  bool trackEnergy = true;       // accumulate elastic energy and dissipation every step
  int threads = 1;               // OpenMP threads; results are identical for any count
  void validate() const;         // throws InputError
};

// Rayleigh time step (Li et al. 2005): pi r sqrt(rho/G) / (0.1631 nu + 0.8766), minimised over particles;
// rho includes density scaling. [s]
double rayleighTimeStep(const ParticleStore& p, const std::vector<Material>& materials, double densityScale);

}  // namespace fl
