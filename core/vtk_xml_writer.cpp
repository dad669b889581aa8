#include "vtk_xml_writer.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <span>

#include "atomic_file.hpp"
#include "errors.hpp"

namespace fl {

namespace {

// VTK cell type ids (vtkCellType.h).
constexpr int kVtkVertex = 1;
constexpr int kVtkLine = 3;
constexpr int kVtkHexahedron = 12;

void put(std::string& s, double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g ", v);
  s += buf;
}
void put(std::string& s, long long v) {
  s += std::to_string(v);
  s += ' ';
}
void put(std::string& s, const Vec3& v) {
  put(s, v.x());
  put(s, v.y());
  put(s, v.z());
}

void beginArray(std::string& s, const char* type, const char* name, int components) {
  s += "        <DataArray type=\"";
  s += type;
  s += '"';
  if (name) {
    s += " Name=\"";
    s += name;
    s += '"';
  }
  if (components > 1) s += " NumberOfComponents=\"" + std::to_string(components) + '"';
  s += " format=\"ascii\">\n";
}
void endArray(std::string& s) {
  if (!s.empty() && s.back() == ' ') s.back() = '\n';
  s += "        </DataArray>\n";
}

void beginPiece(std::string& s, std::size_t points, std::size_t cells) {
  s += "<?xml version=\"1.0\"?>\n"
       "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
       "  <UnstructuredGrid>\n";
  s += "    <Piece NumberOfPoints=\"" + std::to_string(points) + "\" NumberOfCells=\"" + std::to_string(cells) +
       "\">\n";
}

void writePoints(std::string& s, std::span<const Vec3> pts) {
  s += "      <Points>\n";
  beginArray(s, "Float64", nullptr, 3);
  for (const Vec3& x : pts) put(s, x);
  endArray(s);
  s += "      </Points>\n";
}

// Cells that all have <nodes> consecutive points of one type.
void writeCells(std::string& s, std::size_t cells, int nodes, int type) {
  s += "      <Cells>\n";
  beginArray(s, "Int64", "connectivity", 1);
  for (std::size_t k = 0; k < cells * static_cast<std::size_t>(nodes); ++k) put(s, static_cast<long long>(k));
  endArray(s);
  beginArray(s, "Int64", "offsets", 1);
  for (std::size_t c = 1; c <= cells; ++c) put(s, static_cast<long long>(c * static_cast<std::size_t>(nodes)));
  endArray(s);
  beginArray(s, "UInt8", "types", 1);
  for (std::size_t c = 0; c < cells; ++c) put(s, static_cast<long long>(type));
  endArray(s);
  s += "      </Cells>\n";
}

void endPiece(std::string& s) {
  s += "    </Piece>\n"
       "  </UnstructuredGrid>\n"
       "</VTKFile>\n";
}

std::string xmlEscape(const std::string& in) {
  std::string out;
  for (char c : in) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

void writeParticlesVtu(const std::string& path, const Simulation& sim) {
  const ParticleStore& p = sim.particles();
  const ContactStore& c = sim.contacts();
  const std::size_t n = p.size();
  std::string s;
  beginPiece(s, n, n);
  s += "      <PointData Scalars=\"radius\" Vectors=\"velocity\">\n";
  beginArray(s, "Float64", "radius", 1);
  for (double r : p.radius) put(s, r);
  endArray(s);
  beginArray(s, "Float64", "velocity", 3);
  for (const Vec3& v : p.vel) put(s, v);
  endArray(s);
  beginArray(s, "Float64", "angular_velocity", 3);
  for (const Vec3& w : p.angVel) put(s, w);
  endArray(s);
  beginArray(s, "Int32", "contact_count", 1);
  const bool haveAdjacency = c.adjStart.size() == n + 1;  // absent before the first neighbour pass
  for (std::size_t k = 0; k < n; ++k) {
    long long count = 0;
    if (haveAdjacency)
      for (std::int32_t e = c.adjStart[k]; e < c.adjStart[k + 1]; ++e)
        count += c.active(static_cast<std::size_t>(c.adjEntry[e] >> 1));
    put(s, count);
  }
  endArray(s);
  beginArray(s, "Int32", "id", 1);
  for (std::int32_t id : p.id) put(s, static_cast<long long>(id));
  endArray(s);
  s += "      </PointData>\n";
  writePoints(s, p.pos);
  writeCells(s, n, 1, kVtkVertex);
  endPiece(s);
  writeFileAtomically(path, s);
}

void writeContactsVtu(const std::string& path, const Simulation& sim) {
  const ParticleStore& p = sim.particles();
  const ContactStore& c = sim.contacts();
  std::vector<std::size_t> active;
  for (std::size_t k = 0; k < c.size(); ++k)
    if (c.active(k)) active.push_back(k);
  std::vector<Vec3> pts;
  pts.reserve(2 * active.size());
  for (std::size_t k : active) {
    const Vec3& xi = p.pos[static_cast<std::size_t>(c.first[k])];
    pts.push_back(xi);
    pts.push_back(xi + c.branch(k, p, sim.cell()));  // towards j's image: lines across the boundary keep their length
  }
  std::string s;
  beginPiece(s, pts.size(), active.size());
  s += "      <CellData Scalars=\"normal_force\" Vectors=\"force\">\n";
  beginArray(s, "Float64", "normal_force", 1);
  for (std::size_t k : active) put(s, c.result[k].normalForce);
  endArray(s);
  beginArray(s, "Float64", "force", 3);
  for (std::size_t k : active) put(s, c.result[k].force);
  endArray(s);
  beginArray(s, "Float64", "overlap", 1);
  for (std::size_t k : active) put(s, c.result[k].overlap);
  endArray(s);
  s += "      </CellData>\n";
  writePoints(s, pts);
  writeCells(s, active.size(), 2, kVtkLine);
  endPiece(s);
  writeFileAtomically(path, s);
}

void writeCellVtu(const std::string& path, const PeriodicCell& cell) {
  // VTK hexahedron order: bottom face counter-clockwise, then the top face above it.
  static constexpr int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                        {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  std::vector<Vec3> pts;
  for (const auto& k : kCorner) pts.push_back(cell.matrix() * Vec3(k[0], k[1], k[2]));
  std::string s;
  beginPiece(s, 8, 1);
  writePoints(s, pts);
  writeCells(s, 1, 8, kVtkHexahedron);
  endPiece(s);
  writeFileAtomically(path, s);
}

void PvdCollection::add(double time, const std::string& relativeFile) {
  if (!std::isfinite(time))
    throw InputError("PvdCollection '" + m_path + "': time must be finite for '" + relativeFile + "'");
  // Shortest text that reads back as the same double: close output times stay distinct.
  char t[32];
  const auto end = std::to_chars(t, t + sizeof t, time).ptr;
  m_entries.push_back("    <DataSet timestep=\"" + std::string(t, end) + "\" group=\"\" part=\"0\" file=\"" +
                      xmlEscape(relativeFile) + "\"/>\n");
  std::string s =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n";
  for (const std::string& e : m_entries) s += e;
  s += "  </Collection>\n</VTKFile>\n";
  try {
    writeFileAtomically(m_path, s);
  } catch (...) {
    m_entries.pop_back();  // the file on disk still lists the previous entries
    throw;
  }
}

}  // namespace fl
