// Output for ParaView: VTK XML UnstructuredGrid (.vtu) files and .pvd time-series collections.
//
// Why our own writer instead of VTK: core is built for cluster nodes where VTK is not installed
// (libvtk9-dev drags in a JDK, MPI, HDF5 and GDAL), and the house rule is that core never sees a VTK
// include path, so a stray VTK include fails to build. The .vtu format is a small, stable XML text, so
// writing it directly costs ~200 lines. ASCII data with %.9g (float precision, enough to look at)
// keeps the files diffable and trivially checked in tests; switch to appended binary only if output
// size becomes the bottleneck.
//
// Invariants: every file is written with writeFileAtomically, so ParaView never opens a half-written
// file; a PvdCollection rewrites its .pvd after every add(), so a killed run leaves a valid .pvd that
// lists exactly the outputs that were completed.
// Geometry is as stored: particle centres are not re-wrapped (between neighbour rebuilds they may sit
// slightly outside the cell), and a contact line runs from i's centre along the branch vector to j's
// periodic image, so lines across the boundary keep their true length.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "periodic_cell.hpp"
#include "simulation.hpp"

namespace fl {

// One VTK_VERTEX per particle; point data radius [m], velocity (fluctuating v') [m/s],
// angular_velocity [rad/s], contact_count (touching pairs), id.
void writeParticlesVtu(const std::string& path, const Simulation& sim);
// One VTK_LINE per touching pair, from x_i to x_i + branch; cell data normal_force [N],
// force (on j) [N], overlap [m].
void writeContactsVtu(const std::string& path, const Simulation& sim);
// The cell parallelepiped spanned by the columns of H, as one VTK_HEXAHEDRON.
void writeCellVtu(const std::string& path, const PeriodicCell& cell);

// One time series (e.g. particles_*.vtu) as a ParaView .pvd collection. Use one per series.
class PvdCollection {
 public:
  explicit PvdCollection(std::string path) : m_path(std::move(path)) {}
  // Records <relativeFile> (relative to the .pvd's directory) at <time> [s] and rewrites the .pvd
  // atomically. On IoError the entry is not kept. Throws InputError for a non-finite time.
  void add(double time, const std::string& relativeFile);
  const std::string& path() const { return m_path; }
  std::size_t size() const { return m_entries.size(); }

 private:
  std::string m_path;
  std::vector<std::string> m_entries;  // formatted <DataSet .../> lines
};

}  // namespace fl
