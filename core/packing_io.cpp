#include "packing_io.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string_view>
#include <tuple>

#include "atomic_file.hpp"
#include "errors.hpp"

namespace fl {

namespace {

constexpr std::size_t kMaxLine = 4096;             // bytes per line; longer is garbage, not a packing
constexpr std::size_t kMaxParticles = 50'000'000;  // beyond what one node simulates; guards allocation

// A value quoted in a message: short and printable, whatever bytes the file holds.
std::string quoted(std::string_view s) {
  std::string out = "'";
  const std::size_t n = std::min<std::size_t>(s.size(), 40);
  for (std::size_t k = 0; k < n; ++k) {
    const unsigned char c = static_cast<unsigned char>(s[k]);
    out += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  if (n < s.size()) out += "...";
  return out + "'";
}

std::string g17(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string_view trim(std::string_view s) {
  const auto ws = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (!s.empty() && ws(s.front())) s.remove_prefix(1);
  while (!s.empty() && ws(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> splitWhitespace(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t k = 0;
  while (k < s.size()) {
    while (k < s.size() && (s[k] == ' ' || s[k] == '\t' || s[k] == '\r')) ++k;
    const std::size_t b = k;
    while (k < s.size() && s[k] != ' ' && s[k] != '\t' && s[k] != '\r') ++k;
    if (k > b) out.push_back(s.substr(b, k - b));
  }
  return out;
}

std::vector<std::string_view> splitComma(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t b = 0;
  for (;;) {
    const std::size_t e = s.find(',', b);
    out.push_back(trim(s.substr(b, e == std::string_view::npos ? std::string_view::npos : e - b)));
    if (e == std::string_view::npos) return out;
    b = e + 1;
  }
}

std::optional<double> toDouble(std::string_view s) {
  if (!s.empty() && s.front() == '+') {  // from_chars rejects a leading '+', which people do write
    s.remove_prefix(1);
    if (!s.empty() && s.front() == '-') return std::nullopt;
  }
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

std::optional<long long> toInteger(std::string_view s) {
  long long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

// Buffered line reader that knows where it is (line number, byte offset) for error messages.
class LineReader {
 public:
  explicit LineReader(std::string path) : m_path(std::move(path)) {
    m_file = std::fopen(m_path.c_str(), "rb");
    if (!m_file) throw IoError("cannot open '" + m_path + "' for reading: " + std::strerror(errno));
  }
  ~LineReader() { std::fclose(m_file); }
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  // Next line without its '\n' (and '\r'); false at end of file.
  bool next() {
    m_line.clear();
    m_lineOffset = m_consumed;
    bool any = false;
    for (;;) {
      if (m_bufPos == m_bufLen) {
        m_bufLen = std::fread(m_buf.data(), 1, m_buf.size(), m_file);
        m_bufPos = 0;
        if (m_bufLen == 0) {
          if (std::ferror(m_file)) throw IoError("cannot read '" + m_path + "': " + std::strerror(errno));
          if (!any) return false;
          m_unterminated = true;
          break;
        }
      }
      const char* start = m_buf.data() + m_bufPos;
      const std::size_t avail = m_bufLen - m_bufPos;
      const char* nl = static_cast<const char*>(std::memchr(start, '\n', avail));
      const std::size_t take = nl ? static_cast<std::size_t>(nl - start) : avail;
      if (m_line.size() + take > kMaxLine) {
        ++m_lineNo;
        failAt(m_lineNo, m_lineOffset, "line is longer than " + std::to_string(kMaxLine) + " bytes");
      }
      m_line.append(start, take);
      any = true;
      const std::size_t used = take + (nl ? 1 : 0);
      m_bufPos += used;
      m_consumed += used;
      if (nl) break;
    }
    ++m_lineNo;
    if (!m_line.empty() && m_line.back() == '\r') m_line.pop_back();
    return true;
  }

  const std::string& line() const { return m_line; }
  long lineNumber() const { return m_lineNo; }
  std::size_t lineOffset() const { return m_lineOffset; }

  // Error at <at> (a view into line(), or empty for the whole line).
  [[noreturn]] void fail(std::string_view at, const std::string& what) const {
    std::size_t offset = m_lineOffset;
    if (!at.empty() && at.data() >= m_line.data() && at.data() <= m_line.data() + m_line.size())
      offset += static_cast<std::size_t>(at.data() - m_line.data());
    std::string msg = what;
    if (m_unterminated) msg += " [the file ends inside this line: truncated?]";
    failAt(m_lineNo, offset, msg);
  }
  [[noreturn]] void failAtEnd(const std::string& what) const {
    failAt(m_lineNo, m_consumed, what + " [at end of file]");
  }
  [[noreturn]] void failAt(long line, std::size_t offset, const std::string& what) const {
    throw InputError(m_path + ":" + std::to_string(line) + ": " + what + " (byte " + std::to_string(offset) + ")");
  }
  // "field 'x' must be a finite number, got 'nan'"
  double finite(std::string_view tok, std::string_view field) const {
    const auto v = toDouble(tok);
    if (!v || !std::isfinite(*v))
      fail(tok, "field '" + std::string(field) + "' must be a finite number, got " + quoted(tok));
    return *v;
  }
  double positive(std::string_view tok, std::string_view field) const {
    const auto v = toDouble(tok);
    if (!v || !std::isfinite(*v) || !(*v > 0.0))
      fail(tok, "field '" + std::string(field) + "' must be a positive number, got " + quoted(tok));
    return *v;
  }
  long long integer(std::string_view tok, std::string_view field, long long lo, long long hi) const {
    const auto v = toInteger(tok);
    if (!v || *v < lo || *v > hi)
      fail(tok, "field '" + std::string(field) + "' must be an integer in [" + std::to_string(lo) + ", " +
                    std::to_string(hi) + "], got " + quoted(tok));
    return *v;
  }

 private:
  std::string m_path;
  std::FILE* m_file = nullptr;
  std::array<char, 1 << 16> m_buf{};
  std::size_t m_bufPos = 0, m_bufLen = 0;
  std::string m_line;
  long m_lineNo = 0;
  std::size_t m_lineOffset = 0, m_consumed = 0;
  bool m_unterminated = false;
};

void checkArguments(const char* function, double density, int material) {
  if (!(std::isfinite(density) && density > 0.0))
    throw InputError(std::string(function) + ": density must be a positive number [kg/m^3], got " + g17(density));
  if (material < 0 || material > 65535)
    throw InputError(std::string(function) + ": material index must be in [0, 65535], got " +
                     std::to_string(material));
}

// Positions within one cell length of the cell are wrapped in; anything further is a units or
// format mistake, reported on the particle's line.
Vec3 wrapChecked(const LineReader& in, std::string_view at, const PeriodicCell& cell, Vec3 x) {
  static constexpr std::array<const char*, 3> kAxis{"x", "y", "z"};
  const Vec3 s = cell.reduced(x);
  for (int k = 0; k < 3; ++k)
    if (!(s[k] >= -1.0 && s[k] < 2.0))
      in.fail(at, std::string("field '") + kAxis[k] +
                      "': particle lies more than one cell length outside the cell " +
                      "(reduced coordinate along cell vector " + std::to_string(k + 1) + " is " + g17(s[k]) +
                      ", expected in [-1, 2)); wrong units or wrong cell?");
  cell.wrap(x);
  return x;
}

void checkCount(const LineReader& in, std::size_t count) {
  if (count >= kMaxParticles)
    in.fail({}, "more than " + std::to_string(kMaxParticles) + " particles: not supported");
}

Packing readCsv(const std::string& path, double density, int material, const PeriodicCell* given) {
  checkArguments("readPackingCsv", density, material);
  LineReader in(path);
  std::optional<Mat3> fileCell;
  bool header = false;
  while (!header && in.next()) {
    const std::string_view t = trim(in.line());
    if (t.empty()) continue;
    if (t.front() == '#') {
      const auto tok = splitWhitespace(t.substr(1));
      if (tok.empty()) continue;
      if (tok[0] == "fabriclab") {
        if (tok.size() != 3 || tok[1] != "packing")
          in.fail(tok[0], "field 'version': expected '# fabriclab packing v1', got " + quoted(t));
        if (tok[2] != "v1")
          in.fail(tok[2], "field 'version': this build reads packing format v1, got " + quoted(tok[2]));
      } else if (tok[0] == "cell") {
        if (fileCell) in.fail(tok[0], "field 'cell': a second '# cell' line");
        static constexpr std::array<const char*, 9> kH{"H00", "H01", "H02", "H10", "H11",
                                                       "H12", "H20", "H21", "H22"};
        if (tok.size() != 10)
          in.fail(tok[0], "field 'cell': expected 9 numbers H00 H01 H02 H10 H11 H12 H20 H21 H22, got " +
                              std::to_string(tok.size() - 1));
        Mat3 H;
        for (int k = 0; k < 9; ++k) H(k / 3, k % 3) = in.finite(tok[k + 1], kH[k]);
        if (!(H.determinant() > 0.0))
          in.fail(tok[0],
                  "field 'cell': the cell matrix must have a positive determinant, got " + g17(H.determinant()));
        fileCell = H;
      }
      continue;  // any other comment
    }
    const auto f = splitComma(t);
    if (f.size() != 4 || f[0] != "x" || f[1] != "y" || f[2] != "z" || f[3] != "r")
      in.fail(t, "field 'header': expected the header row 'x,y,z,r', got " + quoted(t));
    header = true;
  }
  if (!header) in.failAtEnd("field 'header': no header row 'x,y,z,r' (empty or truncated file?)");

  PeriodicCell cell;
  if (given) {
    if (fileCell && *fileCell != given->matrix())
      in.fail({}, "field 'cell': the file's '# cell' line differs from the cell passed by the caller");
    cell = *given;
  } else if (fileCell) {
    cell = PeriodicCell(*fileCell);
  } else {
    in.fail({},
            "field 'cell': no '# cell H00 ... H22' line before the header row; add one or pass the "
            "cell explicitly (readPackingCsv overload with a PeriodicCell)");
  }

  static constexpr std::array<const char*, 4> kField{"x", "y", "z", "r"};
  Packing out{ParticleStore{}, cell};
  while (in.next()) {
    const std::string_view t = trim(in.line());
    if (t.empty() || t.front() == '#') continue;
    const auto f = splitComma(t);
    if (f.size() < 4)
      in.fail(t, "field '" + std::string(kField[f.size()]) + "' is missing: expected 4 comma-separated " +
                     "fields x,y,z,r, got " + std::to_string(f.size()));
    if (f.size() > 4)
      in.fail(f[4], "expected 4 comma-separated fields x,y,z,r, got " + std::to_string(f.size()) +
                        " (extra field " + quoted(f[4]) + ")");
    const Vec3 x(in.finite(f[0], "x"), in.finite(f[1], "y"), in.finite(f[2], "z"));
    const double r = in.positive(f[3], "r");
    checkCount(in, out.particles.size());
    out.particles.add(wrapChecked(in, f[0], cell, x), r, density, material);
  }
  if (out.particles.size() == 0) in.failAtEnd("no particle rows after the header row 'x,y,z,r'");
  return out;
}

// ---- LAMMPS -------------------------------------------------------------------------------------

// Text before '#', trimmed, and the trimmed comment after it (LAMMPS's "Atoms # sphere" style hint).
std::pair<std::string_view, std::string_view> splitComment(std::string_view line) {
  const std::size_t h = line.find('#');
  if (h == std::string_view::npos) return {trim(line), {}};
  return {trim(line.substr(0, h)), trim(line.substr(h + 1))};
}

// A section keyword starts with a letter; header lines start with a number.
bool isSectionLine(std::string_view t) {
  return !t.empty() && ((t.front() >= 'A' && t.front() <= 'Z') || (t.front() >= 'a' && t.front() <= 'z'));
}

struct AtomKey {
  long long id;
  std::size_t index;
  long line;
  std::size_t offset;  // byte offset of the line
};

}  // namespace

Packing readPackingCsv(const std::string& path, double density, int material) {
  return readCsv(path, density, material, nullptr);
}

Packing readPackingCsv(const std::string& path, double density, int material, const PeriodicCell& cell) {
  return readCsv(path, density, material, &cell);
}

void writePackingCsv(const std::string& path, const ParticleStore& particles, const PeriodicCell& cell) {
  std::string s = "# fabriclab packing v1\n# cell";
  const Mat3& H = cell.matrix();
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) s += ' ' + g17(H(a, b));
  s += "\nx,y,z,r\n";
  char row[128];
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const Vec3& x = particles.pos[i];
    std::snprintf(row, sizeof row, "%.17g,%.17g,%.17g,%.17g\n", x.x(), x.y(), x.z(), particles.radius[i]);
    s += row;
  }
  writeFileAtomically(path, s);
}

Packing readLammpsData(const std::string& path, int material) {
  checkArguments("readLammpsData", 1.0, material);
  LineReader in(path);
  if (!in.next()) in.failAtEnd("empty file, expected a LAMMPS data file");  // line 1 is the title

  // ---- header
  long long atoms = -1, types = -1;
  std::array<std::optional<std::pair<double, double>>, 3> box;
  static constexpr std::array<const char*, 3> kLo{"xlo", "ylo", "zlo"}, kHi{"xhi", "yhi", "zhi"};
  std::string_view section, hint;
  bool haveSection = false;
  while (in.next()) {
    const auto [t, comment] = splitComment(in.line());
    if (t.empty()) continue;
    if (isSectionLine(t)) {
      section = t;
      hint = comment;
      haveSection = true;
      break;
    }
    const auto tok = splitWhitespace(t);
    if (tok.size() == 2 && tok[1] == "atoms") {
      if (atoms >= 0) in.fail(tok[1], "field 'atoms': declared twice");
      atoms = in.integer(tok[0], "atoms", 1, static_cast<long long>(kMaxParticles));
    } else if (tok.size() == 3 && tok[1] == "atom" && tok[2] == "types") {
      if (types >= 0) in.fail(tok[1], "field 'atom types': declared twice");
      types = in.integer(tok[0], "atom types", 1, 65536);
    } else if (tok.size() == 6 && tok[3] == "xy" && tok[4] == "xz" && tok[5] == "yz") {
      const double xy = in.finite(tok[0], "xy"), xz = in.finite(tok[1], "xz"), yz = in.finite(tok[2], "yz");
      if (xy != 0.0 || xz != 0.0 || yz != 0.0)
        in.fail(tok[3], "field 'xy xz yz': triclinic boxes are not supported (only orthorhombic), got tilts " +
                            g17(xy) + " " + g17(xz) + " " + g17(yz));
    } else {
      int axis = -1;
      for (int k = 0; k < 3; ++k)
        if (tok.size() == 4 && tok[2] == kLo[k] && tok[3] == kHi[k]) axis = k;
      if (axis < 0)
        in.fail(t, "unsupported header line " + quoted(t) +
                       ": expected 'N atoms', 'N atom types', 'lo hi xlo xhi' (or y, z) or 'xy xz yz'");
      if (box[axis]) in.fail(tok[2], "field '" + std::string(kLo[axis]) + " " + kHi[axis] + "': declared twice");
      const double lo = in.finite(tok[0], kLo[axis]), hi = in.finite(tok[1], kHi[axis]);
      if (!(hi > lo))
        in.fail(tok[1],
                "field '" + std::string(kHi[axis]) + "' must exceed '" + kLo[axis] + "', got " + quoted(tok[1]));
      box[axis] = std::make_pair(lo, hi);
    }
  }
  if (!haveSection) in.failAtEnd("missing section: no 'Atoms' section (empty or truncated file?)");
  if (atoms < 0) in.fail(section, "field 'atoms': no 'N atoms' header line before the first section");
  for (int k = 0; k < 3; ++k)
    if (!box[k])
      in.fail(section,
              "field '" + std::string(kLo[k]) + " " + kHi[k] + "': no box header line before the first section");
  const Vec3 lo(box[0]->first, box[1]->first, box[2]->first);
  const Vec3 len(box[0]->second - lo.x(), box[1]->second - lo.y(), box[2]->second - lo.z());
  if (!(len.prod() > 0.0 && std::isfinite(len.prod())))
    in.fail(section, "field 'xlo xhi': the box volume must be a positive finite number, got " + g17(len.prod()));
  const PeriodicCell cell = PeriodicCell::box(len.x(), len.y(), len.z());

  // ---- sections: each holds exactly <atoms> lines (LAMMPS's rule)
  Packing out{ParticleStore{}, cell};
  std::vector<AtomKey> keys;  // sorted by id once Atoms is read
  bool haveAtoms = false, haveVelocities = false;
  static constexpr std::array<const char*, 10> kAtomField{"atom-ID", "atom-type", "diameter", "density", "x",
                                                          "y",       "z",         "ix",       "iy",      "iz"};
  static constexpr std::array<const char*, 7> kVelField{"atom-ID", "vx", "vy", "vz", "wx", "wy", "wz"};
  while (haveSection) {
    const std::string name(section);
    const bool isAtoms = name == "Atoms", isVelocities = name == "Velocities";
    if (!isAtoms && !isVelocities)
      in.fail(section, "field 'section': unknown or unsupported section " + quoted(section) +
                           " (expected 'Atoms' or 'Velocities' of atom_style sphere)");
    if ((isAtoms && haveAtoms) || (isVelocities && haveVelocities))
      in.fail(section, "field 'section': section '" + name + "' appears twice");
    if (isVelocities && !haveAtoms)
      in.fail(section, "field 'section': 'Velocities' must follow the 'Atoms' section");
    if (isAtoms && !hint.empty() && hint != "sphere")
      in.fail(hint, "field 'atom_style': only atom_style sphere is supported, got " + quoted(hint));

    constexpr std::size_t expectedFields = 7;
    for (long long n = 0; n < atoms; ++n) {
      bool got = in.next();
      while (got && n == 0 && splitComment(in.line()).first.empty()) got = in.next();  // blank after keyword
      if (!got)
        in.failAtEnd("field 'atoms': section '" + name + "' has " + std::to_string(n) + " lines but the header " +
                     "declares " + std::to_string(atoms) + " atoms (truncated file?)");
      const std::string_view t = splitComment(in.line()).first;
      if (t.empty() || isSectionLine(t))
        in.fail(t, "field 'atoms': section '" + name + "' has " + std::to_string(n) + " lines but the header " +
                       "declares " + std::to_string(atoms) + " atoms");
      const auto tok = splitWhitespace(t);
      const bool imageFlags = isAtoms && tok.size() == 10;
      if (tok.size() != expectedFields && !imageFlags) {
        const std::string what =
            isAtoms ? "7 fields 'atom-ID atom-type diameter density x y z' (or 10 with image flags)"
                    : "7 fields 'atom-ID vx vy vz wx wy wz'";
        if (tok.size() < expectedFields)
          in.fail(t, "field '" + std::string(isAtoms ? kAtomField[tok.size()] : kVelField[tok.size()]) +
                         "' is missing: expected " + what + ", got " + std::to_string(tok.size()));
        in.fail(tok[expectedFields], "expected " + what + ", got " + std::to_string(tok.size()) + " fields");
      }
      const long long id = in.integer(tok[0], "atom-ID", 1, (1LL << 62));
      if (isAtoms) {
        const long long maxType = types > 0 ? types : 65536;
        in.integer(tok[1], "atom-type", 1, maxType);
        const double d = in.positive(tok[2], "diameter");
        const double rho = in.positive(tok[3], "density");
        const Vec3 x(in.finite(tok[4], "x"), in.finite(tok[5], "y"), in.finite(tok[6], "z"));
        if (imageFlags)
          for (int k = 7; k < 10; ++k) in.integer(tok[k], kAtomField[k], -(1LL << 30), 1LL << 30);
        keys.push_back({id, out.particles.size(), in.lineNumber(), in.lineOffset()});
        out.particles.add(wrapChecked(in, tok[4], cell, x - lo), 0.5 * d, rho, material);
      } else {
        const auto it =
            std::lower_bound(keys.begin(), keys.end(), id, [](const AtomKey& a, long long v) { return a.id < v; });
        if (it == keys.end() || it->id != id)
          in.fail(tok[0], "field 'atom-ID': no atom with ID " + quoted(tok[0]) + " in the 'Atoms' section");
        if (it->line < 0) in.fail(tok[0], "field 'atom-ID': velocity of atom " + quoted(tok[0]) + " given twice");
        it->line = -1;  // mark as seen
        out.particles.vel[it->index] =
            Vec3(in.finite(tok[1], "vx"), in.finite(tok[2], "vy"), in.finite(tok[3], "vz"));
        out.particles.angVel[it->index] =
            Vec3(in.finite(tok[4], "wx"), in.finite(tok[5], "wy"), in.finite(tok[6], "wz"));
      }
    }
    if (isAtoms) {
      std::sort(keys.begin(), keys.end(), [](const AtomKey& a, const AtomKey& b) {
        return std::tie(a.id, a.line) < std::tie(b.id, b.line);
      });
      for (std::size_t k = 1; k < keys.size(); ++k)
        if (keys[k].id == keys[k - 1].id)
          in.failAt(keys[k].line, keys[k].offset,
                    "field 'atom-ID': ID " + std::to_string(keys[k].id) + " already used on line " +
                        std::to_string(keys[k - 1].line));
    }
    haveAtoms = haveAtoms || isAtoms;
    haveVelocities = haveVelocities || isVelocities;

    // Next section keyword, or the end of the file.
    haveSection = false;
    while (in.next()) {
      const auto [t, comment] = splitComment(in.line());
      if (t.empty()) continue;
      if (!isSectionLine(t))
        in.fail(t, "field 'atoms': section '" + name + "' has more lines than the " + std::to_string(atoms) +
                       " atoms declared in the header");
      section = t;
      hint = comment;
      haveSection = true;
      break;
    }
  }
  if (!haveAtoms) in.failAtEnd("missing section: no 'Atoms' section");
  return out;
}

void writeLammpsData(const std::string& path, const ParticleStore& particles, const PeriodicCell& cell,
                     const std::vector<Material>& materials) {
  const Mat3& H = cell.matrix();
  if (!(H - Mat3(H.diagonal().asDiagonal())).isZero(0.0))
    throw InputError("writeLammpsData '" + path +
                     "': only orthorhombic cells are supported, the cell matrix has "
                     "off-diagonal terms");
  if (materials.empty()) throw InputError("writeLammpsData '" + path + "': no materials given");
  std::string s = "LAMMPS data file written by FabricLab (atom_style sphere, units si)\n\n";
  s += std::to_string(particles.size()) + " atoms\n" + std::to_string(materials.size()) + " atom types\n\n";
  s += "0 " + g17(H(0, 0)) + " xlo xhi\n0 " + g17(H(1, 1)) + " ylo yhi\n0 " + g17(H(2, 2)) + " zlo zhi\n";
  s += "\nAtoms # sphere\n\n";
  char row[256];
  std::vector<Vec3> wrapped(particles.size());
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const std::size_t m = particles.material[i];
    if (m >= materials.size())
      throw InputError("writeLammpsData '" + path + "': particle " + std::to_string(i) + " names material " +
                       std::to_string(m) + " but only " + std::to_string(materials.size()) + " are given");
    wrapped[i] = particles.pos[i];
    cell.wrap(wrapped[i]);
    const Vec3& x = wrapped[i];
    std::snprintf(row, sizeof row, "%zu %zu %.17g %.17g %.17g %.17g %.17g\n", i + 1, m + 1,
                  2.0 * particles.radius[i], materials[m].density, x.x(), x.y(), x.z());
    s += row;
  }
  s += "\nVelocities\n\n";
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const Vec3 v = particles.vel[i] + cell.velocityGradient() * wrapped[i];  // lab-frame velocity
    const Vec3& w = particles.angVel[i];
    std::snprintf(row, sizeof row, "%zu %.17g %.17g %.17g %.17g %.17g %.17g\n", i + 1, v.x(), v.y(), v.z(), w.x(),
                  w.y(), w.z());
    s += row;
  }
  writeFileAtomically(path, s);
}

}  // namespace fl
