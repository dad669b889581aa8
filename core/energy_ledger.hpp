// Energy bookkeeping: what is stored, what was dissipated, what the cell boundary put in.
// Balance: kinetic + elastic + dissipated - boundaryWork = constant (its initial value).
// Accuracy: elastic and cell work close to round-off/second order; the work of velocity-dependent forces
// (contact and local damping) is taken with the velocity at the force evaluation, i.e. to first order in
// dt, so the balance error grows with the damping work times dt / (contact duration).
#pragma once

namespace fl {

struct EnergyLedger {
  double kinetic = 0.0;          // translational + rotational, fluctuating velocities [J]
  double elasticNormal = 0.0;    // sum (2/5) F_n delta [J]
  double elasticTangential = 0.0;// sum |F_t|^2 / (2 k_t) [J]
  double frictionWork = 0.0;     // Coulomb sliding + micro-slip of the tangential spring, cumulative [J]
  double contactDampingWork = 0.0;  // viscous contact damping, cumulative [J]
  double localDampingWork = 0.0; // Cundall local damping, cumulative [J]
  double boundaryWork = 0.0;     // work done on the assembly by the cell deformation, cumulative [J]

  double stored() const { return kinetic + elasticNormal + elasticTangential; }
  double dissipated() const { return frictionWork + contactDampingWork + localDampingWork; }
  // stored + dissipated - input; constant in exact arithmetic
  double balance() const { return stored() + dissipated() - boundaryWork; }
};

}  // namespace fl
