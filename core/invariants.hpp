// Heavy invariant checks for validation builds (cmake -DFL_VALIDATION=ON runs them after every step from
// the runner; tests call them directly). Throws fl::Error naming the first violated invariant.
//  - every position, velocity and force is finite; the cell has a positive volume;
//  - the contact pass's particle copy (Simulation::passParticles) holds the store's positions, radii and
//    inverse masses bit for bit;
//  - pairs have 0 <= i < j < N and the CSR adjacency lists each pair once from each side;
//  - for touching pairs: unit normal, distance + overlap = r_i + r_j, the stored tangential force lies in
//    the tangent plane and obeys Coulomb, |F_t| <= mu F_n (up to round-off).
#pragma once

#include "simulation.hpp"

namespace fl {

void checkInvariants(const Simulation& sim);

}  // namespace fl
