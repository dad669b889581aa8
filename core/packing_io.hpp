// Import and export of packings (particles + periodic cell) as CSV and as LAMMPS data files.
//
// CSV (ours, bit-exact with %.17g):
//   # fabriclab packing v1
//   # cell H00 H01 H02 H10 H11 H12 H20 H21 H22      (H row by row, columns are the cell vectors) [m]
//   x,y,z,r                                          [m]
//   one row per particle
// Other '#' lines and blank lines are ignored; the version line is optional (files from other tools
// lack it) but must say v1 when present. Without a '# cell' line the caller must pass the cell.
//
// LAMMPS data file, atom_style sphere, orthorhombic box only (a non-zero 'xy xz yz' tilt is rejected):
// header 'N atoms', 'N atom types', 'xlo xhi', 'ylo yhi', 'zlo zhi'; section 'Atoms # sphere' with
// "atom-ID atom-type diameter density x y z [ix iy iz]" (image flags accepted and ignored: positions
// are wrapped); optional 'Velocities' "atom-ID vx vy vz wx wy wz". Positions are written relative to
// xlo = 0 and wrapped into the box (LAMMPS refuses atoms outside it). Written velocities are the full
// lab-frame velocities v' + L x; a data file carries no velocity gradient, so on reading they become
// the fluctuating velocities of a cell with L = 0.
//
// Readers' invariants (they face hand-edited and fuzzed files): every rejected input throws InputError
// "<file>:<line>: field '<name>' ... got '<text>' (byte <offset>)"; an unreadable file throws IoError.
// Numbers must be finite, radii and densities positive, at most 50 million particles, and every
// position within one cell length of the cell (reduced coordinates in [-1, 2)); positions are wrapped
// into the cell. Lines are limited to 4096 bytes and nothing is pre-allocated from a declared count,
// so garbage can neither hang a reader nor make it allocate without bound.
#pragma once

#include <string>
#include <vector>

#include "gas_generator.hpp"
#include "material.hpp"
#include "particle_store.hpp"
#include "periodic_cell.hpp"

namespace fl {

// Particles get the given density [kg/m^3] and material index. The file must have a '# cell' line.
Packing readPackingCsv(const std::string& path, double density, int material);
// As above with the cell given by the caller, for files without a '# cell' line (if the file has one
// it must equal <cell> exactly).
Packing readPackingCsv(const std::string& path, double density, int material, const PeriodicCell& cell);
// Written with writeFileAtomically; positions as stored (the reader wraps them).
void writePackingCsv(const std::string& path, const ParticleStore& particles, const PeriodicCell& cell);

// Each atom keeps its own density from the file; all get material index <material>.
Packing readLammpsData(const std::string& path, int material);
// Atom type = material index + 1; density = that material's density (not m / V: invMass may carry
// density scaling). Requires an orthorhombic cell. Written with writeFileAtomically.
void writeLammpsData(const std::string& path, const ParticleStore& particles, const PeriodicCell& cell,
                     const std::vector<Material>& materials);

}  // namespace fl
