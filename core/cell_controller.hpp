// Interface of the stage that sets the cell's velocity gradient L from the measured state after each
// force pass (servo control, strain-rate control, constant volume ...). Implementations live with the
// loading protocols; the engine only calls update() once per step, right after the force pass and before
// the kick, so commands take effect on the next step. update() may read only what the pass made (the contact
// stress, the axis stiffness, the diagnostics), the cell and the clock: not the particles' forces or
// velocities, which the kick has not yet written (Simulation::run fuses the kick with the next drift).
#pragma once

#include "types.hpp"

namespace fl {

class Simulation;

class CellController {
 public:
  virtual ~CellController() = default;
  // Returns the velocity gradient L [1/s] for the next step.
  virtual Mat3 update(const Simulation& sim) = 0;
};

}  // namespace fl
