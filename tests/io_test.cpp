// File input/output: atomic writes and append logs, packing CSV and LAMMPS data round trips, one test
// per kind of rejected input (the message must name file, line and field), a small mutation fuzz (the
// readers may only succeed or throw InputError), and the VTK XML files checked as XML with the counts
// ParaView relies on.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/errors.hpp"
#include "core/packing_io.hpp"
#include "core/vtk_xml_writer.hpp"
#include "test_support.hpp"

using namespace fl;
namespace fs = std::filesystem;

namespace {

// A fresh directory per test (other test binaries may run at the same time).
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    m_dir = fs::temp_directory_path() /
            ("fl_io_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
    fs::remove_all(m_dir);
    fs::create_directories(m_dir);
  }
  ~TempDir() { fs::remove_all(m_dir); }
  std::string operator/(const std::string& name) const { return (m_dir / name).string(); }
  const fs::path& path() const { return m_dir; }

 private:
  fs::path m_dir;
};

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

void spit(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

// The InputError message of <read>, or "" when it did not throw.
template <class F>
std::string inputError(F read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expectMentions(const std::string& msg, std::initializer_list<std::string> parts) {
  ASSERT_FALSE(msg.empty()) << "expected an InputError";
  for (const std::string& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
}

const std::string kCsvHead = "# fabriclab packing v1\n# cell 0.004 0 0 0 0.004 0 0 0 0.004\nx,y,z,r\n";

std::string csvError(const TempDir& dir, const std::string& body) {
  const std::string path = dir / "packing.csv";
  spit(path, body);
  return inputError([&] { readPackingCsv(path, 2570.0, 0); });
}

const std::string kLammpsHead =
    "LAMMPS data file\n\n2 atoms\n1 atom types\n\n0 0.004 xlo xhi\n0 0.004 ylo yhi\n0 0.004 zlo zhi\n\n";
const std::string kLammpsAtoms =
    "Atoms # sphere\n\n1 1 0.001 2570 0.001 0.001 0.001\n2 1 0.001 2570 0.002 0.001 0.001\n";

std::string lammpsError(const TempDir& dir, const std::string& body) {
  const std::string path = dir / "packing.data";
  spit(path, body);
  return inputError([&] { readLammpsData(path, 0); });
}

// ---- minimal XML checks -------------------------------------------------------------------------

// True when every tag is closed in order (enough to catch a broken writer; not a full XML parser).
bool tagsBalanced(const std::string& xml) {
  std::vector<std::string> stack;
  std::size_t k = 0;
  while ((k = xml.find('<', k)) != std::string::npos) {
    const std::size_t e = xml.find('>', k);
    if (e == std::string::npos) return false;
    const std::string tag = xml.substr(k + 1, e - k - 1);
    k = e + 1;
    if (tag.empty() || tag[0] == '?') continue;
    if (tag[0] == '/') {
      if (stack.empty() || stack.back() != tag.substr(1)) return false;
      stack.pop_back();
    } else if (tag.back() != '/') {
      stack.push_back(tag.substr(0, tag.find(' ')));
    }
  }
  return stack.empty();
}

std::string attribute(const std::string& xml, const std::string& name) {
  const std::string key = name + "=\"";
  const std::size_t b = xml.find(key);
  if (b == std::string::npos) return "";
  const std::size_t s = b + key.size();
  return xml.substr(s, xml.find('"', s) - s);
}

// Values of the DataArray called <name> (or the first unnamed one, the Points, for "").
std::vector<double> dataArray(const std::string& xml, const std::string& name) {
  std::size_t b = 0;
  for (;;) {
    b = xml.find("<DataArray", b);
    if (b == std::string::npos) return {};
    const std::size_t e = xml.find('>', b);
    const std::string head = xml.substr(b, e - b);
    b = e + 1;
    if (name.empty() ? head.find("Name=") == std::string::npos
                     : head.find("Name=\"" + name + "\"") != std::string::npos)
      break;
  }
  std::istringstream in(xml.substr(b, xml.find("</DataArray>", b) - b));
  std::vector<double> v;
  double x;
  while (in >> x) v.push_back(x);
  return v;
}

Simulation twoOverlapping() {
  ParticleStore p;
  p.add({0.5e-3, 0.5e-3, 0.5e-3}, 0.5e-3, 2570, 0);
  p.add({1.49e-3, 0.5e-3, 0.5e-3}, 0.5e-3, 2570, 0);
  return Simulation(std::move(p), PeriodicCell::box(4e-3, 4e-3, 4e-3), {Material::paperGlass()},
                    NumericsSettings{});
}

ParticleStore randomParticles(const PeriodicCell& cell, int n, std::uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> s(0.1, 0.9), r(0.2e-3, 0.6e-3);
  ParticleStore p;
  for (int k = 0; k < n; ++k) p.add(cell.matrix() * Vec3(s(rng), s(rng), s(rng)), r(rng), 2570, 0);
  return p;
}

}  // namespace

// ---- atomic files ---------------------------------------------------------------------------------

TEST(AtomicFile, ReplacesContentAndLeavesNoTempFile) {
  TempDir dir;
  const std::string path = dir / "out.txt";
  writeFileAtomically(path, "first\n");
  writeFileAtomically(path, "second\n");
  EXPECT_EQ(slurp(path), "second\n");
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir.path())) {
    ++files;
    EXPECT_EQ(e.path().filename(), "out.txt");
  }
  EXPECT_EQ(files, 1);
}

TEST(AtomicFile, MissingDirectoryThrowsIoErrorNamingThePath) {
  TempDir dir;
  const std::string path = dir / "no/such/dir/out.vtu";
  try {
    writeFileAtomically(path, "x");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No such file"), std::string::npos) << e.what();
  }
}

TEST(AtomicFile, AppendLogWritesTheHeaderOnceAndEveryLineAtOnce) {
  TempDir dir;
  const std::string path = dir / "series.csv";
  {
    AppendLog log(path, "t,p");
    log.append("0,1");
    EXPECT_EQ(slurp(path), "t,p\n0,1\n");  // flushed, not waiting for close
  }
  // a run killed inside a record: the kernel kept "1,2.5" of "1,2.5e-3\n". Kept and terminated, it would be a
  // well-formed row with a wrong number; it is dropped
  spit(path, slurp(path) + "1,2.5");
  AppendLog log(path, "t,p");
  log.append("2,3");
  EXPECT_EQ(slurp(path), "t,p\n0,1\n2,3\n");
  EXPECT_THROW(AppendLog(dir / "missing/series.csv", "t"), IoError);
}

TEST(AtomicFile, AppendLogDropsAnUnfinishedLineAcrossBlocksAndAnUnfinishedHeader) {
  TempDir dir;
  const std::string path = dir / "series.csv";
  // the unfinished line longer than the 4096-byte block read back from the end
  const std::string done = "t,p\n0,1\n";
  spit(path, done + std::string(9000, '7'));
  {
    AppendLog log(path, "t,p");
    log.append("1,2");
  }
  EXPECT_EQ(slurp(path), done + "1,2\n");
  // killed inside the header of a new file: the header is written again, whole
  spit(path, "t,");
  {
    AppendLog log(path, "t,p");
    log.append("0,1");
  }
  EXPECT_EQ(slurp(path), "t,p\n0,1\n");
  // a file that ends with its newline is left as it is
  {
    AppendLog log(path, "t,p");
    log.append("1,2");
  }
  EXPECT_EQ(slurp(path), "t,p\n0,1\n1,2\n");
}

// ---- packing CSV ----------------------------------------------------------------------------------

TEST(PackingCsv, RoundTripIsBitExact) {
  TempDir dir;
  Mat3 H;
  H << 4.1e-3, 0.3e-3, -0.2e-3, 0.1e-3, 3.7e-3, 0.25e-3, 0.0, 0.15e-3, 4.4e-3;  // a sheared cell
  const PeriodicCell cell(H);
  const ParticleStore p = randomParticles(cell, 50, 7);
  writePackingCsv(dir / "p.csv", p, cell);
  const Packing q = readPackingCsv(dir / "p.csv", 2570.0, 0);
  EXPECT_EQ(q.cell.matrix(), H);
  ASSERT_EQ(q.particles.size(), p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_EQ(q.particles.pos[i], p.pos[i]);
    EXPECT_EQ(q.particles.radius[i], p.radius[i]);
  }
}

TEST(PackingCsv, PositionsAreWrappedIntoTheCell) {
  TempDir dir;
  spit(dir / "p.csv", kCsvHead + "-0.001,0.005,0.002,0.0005\n");
  const Packing q = readPackingCsv(dir / "p.csv", 2570.0, 0);
  EXPECT_NEAR(q.particles.pos[0].x(), 0.003, 1e-15);
  EXPECT_NEAR(q.particles.pos[0].y(), 0.001, 1e-15);
}

TEST(PackingCsv, MissingCellNeedsAnExplicitCell) {
  TempDir dir;
  const std::string body = "# fabriclab packing v1\nx,y,z,r\n0.001,0.001,0.001,0.0005\n";
  expectMentions(csvError(dir, body), {"packing.csv:2:", "'cell'"});
  const Packing q = readPackingCsv(dir / "packing.csv", 2570.0, 0, PeriodicCell::box(4e-3, 4e-3, 4e-3));
  EXPECT_EQ(q.particles.size(), 1u);
  EXPECT_EQ(q.cell.matrix()(1, 1), 4e-3);
}

TEST(PackingCsv, NegativeRadiusNamesFileLineAndField) {
  TempDir dir;
  const std::string msg = csvError(dir, kCsvHead + "0.001,0.001,0.001,0.0005\n0.002,0.001,0.001,-3\n");
  expectMentions(msg, {"packing.csv:5:", "field 'r' must be a positive number, got '-3'", "byte"});
}

TEST(PackingCsv, NanAndInfinityAreRejected) {
  TempDir dir;
  expectMentions(csvError(dir, kCsvHead + "0.001,nan,0.001,0.0005\n"), {"packing.csv:4:", "field 'y'", "'nan'"});
  expectMentions(csvError(dir, kCsvHead + "0.001,0.001,0.001,inf\n"), {"packing.csv:4:", "field 'r'"});
  expectMentions(csvError(dir, kCsvHead + "0.001,0.001,1e999,0.0005\n"), {"packing.csv:4:", "field 'z'"});
}

TEST(PackingCsv, WrongColumnCountIsRejected) {
  TempDir dir;
  expectMentions(csvError(dir, kCsvHead + "0.001,0.001,0.0005\n"), {"packing.csv:4:", "field 'r' is missing"});
  expectMentions(csvError(dir, kCsvHead + "0.001,0.001,0.001,0.0005,7\n"), {"packing.csv:4:", "got 5"});
}

TEST(PackingCsv, TruncatedFileIsRejected) {
  TempDir dir;
  expectMentions(csvError(dir, kCsvHead + "0.001,0.001,0.001,0.0005\n0.002,0.00"),
                 {"packing.csv:5:", "field 'z' is missing", "truncated"});
  expectMentions(csvError(dir, "# fabriclab packing v1\n# cell 0.004 0 0 0 0.004 0 0 0"),
                 {"packing.csv:2:", "field 'cell'"});
  expectMentions(csvError(dir, kCsvHead), {"packing.csv:3:", "no particle rows"});
}

TEST(PackingCsv, ParticleFarOutsideTheCellIsRejected) {
  TempDir dir;
  expectMentions(csvError(dir, kCsvHead + "0.001,0.013,0.001,0.0005\n"),
                 {"packing.csv:4:", "field 'y'", "outside"});
}

TEST(PackingCsv, BadHeaderAndVersionAreRejected) {
  TempDir dir;
  expectMentions(csvError(dir, "# fabriclab packing v2\n"), {"packing.csv:1:", "'version'", "'v2'"});
  expectMentions(csvError(dir, "# cell 0.004 0 0 0 0.004 0 0 0 0.004\nx,y,r\n"), {"packing.csv:2:", "'header'"});
  expectMentions(csvError(dir, "# cell 0.004 0 0 0 -0.004 0 0 0 0.004\nx,y,z,r\n"),
                 {"packing.csv:1:", "'cell'", "determinant"});
}

TEST(PackingCsv, GarbageOnlyEverGivesInputError) {
  TempDir dir;
  const PeriodicCell cell = PeriodicCell::box(4e-3, 4e-3, 4e-3);
  writePackingCsv(dir / "good.csv", randomParticles(cell, 5, 3), cell);
  const std::string good = slurp(dir / "good.csv");
  std::mt19937 rng(11);
  static const char kChars[] = "0123456789.,-+eE#\n\r nanif\0\xff";
  const std::string alphabet(kChars, sizeof kChars - 1);
  for (int trial = 0; trial < 1000; ++trial) {
    std::string s = good;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < edits && !s.empty(); ++k) {
      const std::size_t at = rng() % s.size();
      switch (rng() % 4) {
        case 0: s[at] = alphabet[rng() % alphabet.size()]; break;
        case 1: s.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
        case 2: s.erase(at, 1 + rng() % 20); break;
        default: s.resize(at); break;
      }
    }
    spit(dir / "fuzz.csv", s);
    try {
      readPackingCsv(dir / "fuzz.csv", 2570.0, 0);
    } catch (const InputError&) {
    }  // anything else (another exception, a crash, a hang) fails the test
  }
}

// ---- LAMMPS data ----------------------------------------------------------------------------------

TEST(PackingLammps, RoundTrip) {
  TempDir dir;
  const PeriodicCell cell = PeriodicCell::box(4e-3, 5e-3, 6e-3);
  ParticleStore p = randomParticles(cell, 40, 5);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.vel[i] = Vec3(0.01 * i, -0.02, 0.5);
    p.angVel[i] = Vec3(3.0, -1.0 * i, 0.25);
  }
  Material glass = Material::paperGlass();
  glass.density = 2650.0;
  writeLammpsData(dir / "p.data", p, cell, {glass});
  const Packing q = readLammpsData(dir / "p.data", 0);
  EXPECT_EQ(q.cell.matrix(), cell.matrix());
  ASSERT_EQ(q.particles.size(), p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_LE((q.particles.pos[i] - p.pos[i]).norm(), 1e-15 * p.pos[i].norm());
    EXPECT_EQ(q.particles.radius[i], p.radius[i]);
    EXPECT_EQ(q.particles.vel[i], p.vel[i]);
    EXPECT_EQ(q.particles.angVel[i], p.angVel[i]);
    EXPECT_NEAR(q.particles.mass(i), 2650.0 * 4.0 / 3.0 * kPi * std::pow(p.radius[i], 3),
                1e-12 * q.particles.mass(i));
  }
}

TEST(PackingLammps, ReadsImageFlagsShiftedBoxAndVelocitiesById) {
  TempDir dir;
  spit(dir / "p.data",
       "title\n2 atoms\n1 atom types\n-0.002 0.002 xlo xhi\n0 0.004 ylo yhi\n0 0.004 zlo zhi\n0 0 0 xy xz yz\n\n"
       "Atoms # sphere\n\n7 1 0.001 2500 -0.001 0.001 0.001 0 0 0\n3 1 0.002 2500 0.001 0.001 0.001 1 0 -1\n\n"
       "Velocities\n\n3 1 2 3 4 5 6\n7 -1 -2 -3 -4 -5 -6\n");
  const Packing q = readLammpsData(dir / "p.data", 0);
  ASSERT_EQ(q.particles.size(), 2u);
  EXPECT_NEAR(q.particles.pos[0].x(), 0.001, 1e-18);  // relative to xlo
  EXPECT_EQ(q.particles.radius[1], 0.001);
  EXPECT_EQ(q.particles.vel[0], Vec3(-1, -2, -3));
  EXPECT_EQ(q.particles.angVel[1], Vec3(4, 5, 6));
}

TEST(PackingLammps, TriclinicBoxIsRejected) {
  TempDir dir;
  const std::string head = kLammpsHead.substr(0, kLammpsHead.size() - 1) + "0.001 0 0 xy xz yz\n\n";
  expectMentions(lammpsError(dir, head + kLammpsAtoms), {"packing.data:9:", "'xy xz yz'", "triclinic"});
}

TEST(PackingLammps, TruncatedFileIsRejected) {
  TempDir dir;
  const std::string atoms = kLammpsAtoms.substr(0, kLammpsAtoms.rfind("2 1"));
  expectMentions(lammpsError(dir, kLammpsHead + atoms), {"packing.data:12:", "'atoms'", "truncated"});
  expectMentions(lammpsError(dir, kLammpsHead + atoms + "2 1 0.001 2570 0.002"),
                 {"packing.data:13:", "field 'y' is missing"});
  expectMentions(lammpsError(dir, kLammpsHead), {"packing.data:", "missing section"});
}

TEST(PackingLammps, UnknownAndMissingSectionsAreRejected) {
  TempDir dir;
  expectMentions(lammpsError(dir, kLammpsHead + "Bonds\n\n1 1 1 2\n"),
                 {"packing.data:10:", "'section'", "'Bonds'"});
  expectMentions(lammpsError(dir, kLammpsHead + kLammpsAtoms + "\nMasses\n\n1 1.0\n"),
                 {"packing.data:15:", "'Masses'"});
  expectMentions(lammpsError(dir, kLammpsHead + "Velocities\n\n1 0 0 0 0 0 0\n2 0 0 0 0 0 0\n"),
                 {"packing.data:10:", "must follow the 'Atoms'"});
  expectMentions(lammpsError(dir, "t\n2 atoms\n0 0.004 xlo xhi\n0 0.004 ylo yhi\n\n" + kLammpsAtoms),
                 {"packing.data:6:", "'zlo zhi'"});
  expectMentions(lammpsError(dir, kLammpsHead + "Atoms # atomic\n\n"), {"packing.data:10:", "'atom_style'"});
}

TEST(PackingLammps, BadFieldsNameFileLineAndField) {
  TempDir dir;
  const std::string a1 = "Atoms\n\n1 1 0.001 2570 0.001 0.001 0.001\n";
  expectMentions(lammpsError(dir, kLammpsHead + a1 + "2 1 -0.001 2570 0.002 0.001 0.001\n"),
                 {"packing.data:13:", "field 'diameter' must be a positive number, got '-0.001'"});
  expectMentions(lammpsError(dir, kLammpsHead + a1 + "2 1 0.001 nan 0.002 0.001 0.001\n"),
                 {"packing.data:13:", "field 'density'", "'nan'"});
  expectMentions(lammpsError(dir, kLammpsHead + a1 + "1 1 0.001 2570 0.002 0.001 0.001\n"),
                 {"packing.data:13:", "field 'atom-ID'", "line 12"});
  expectMentions(lammpsError(dir, kLammpsHead + a1 + "2 2 0.001 2570 0.002 0.001 0.001\n"),
                 {"packing.data:13:", "field 'atom-type'"});
  expectMentions(lammpsError(dir, kLammpsHead + a1 + "2 1 0.001 2570 0.002 0.001 0.1\n"),
                 {"packing.data:13:", "field 'z'", "outside"});
  expectMentions(lammpsError(dir, kLammpsHead + kLammpsAtoms + "3 1 0.001 2570 0.002 0.001 0.001\n"),
                 {"packing.data:14:", "more lines"});
  expectMentions(lammpsError(dir, "t\n60000000 atoms\n"), {"packing.data:2:", "field 'atoms'"});
  expectMentions(lammpsError(dir, kLammpsHead + kLammpsAtoms + "\nVelocities\n\n1 0 0 0 0 0 0\n9 0 0 0 0 0 0\n"),
                 {"packing.data:18:", "field 'atom-ID'", "no atom with ID '9'"});
}

TEST(PackingLammps, GarbageOnlyEverGivesInputError) {
  TempDir dir;
  const PeriodicCell cell = PeriodicCell::box(4e-3, 4e-3, 4e-3);
  writeLammpsData(dir / "good.data", randomParticles(cell, 4, 3), cell, {Material::paperGlass()});
  const std::string good = slurp(dir / "good.data");
  std::mt19937 rng(13);
  static const char kChars[] = "0123456789.-+eE# \n\rAtomsxyzlohi\0\xff";
  const std::string alphabet(kChars, sizeof kChars - 1);
  for (int trial = 0; trial < 1000; ++trial) {
    std::string s = good;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < edits && !s.empty(); ++k) {
      const std::size_t at = rng() % s.size();
      switch (rng() % 4) {
        case 0: s[at] = alphabet[rng() % alphabet.size()]; break;
        case 1: s.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
        case 2: s.erase(at, 1 + rng() % 20); break;
        default: s.resize(at); break;
      }
    }
    spit(dir / "fuzz.data", s);
    try {
      readLammpsData(dir / "fuzz.data", 0);
    } catch (const InputError&) {
    }
  }
}

TEST(IoErrors, UnreadableFileIsIoError) {
  TempDir dir;
  EXPECT_THROW(readPackingCsv(dir / "absent.csv", 2570.0, 0), IoError);
  EXPECT_THROW(readLammpsData(dir / "absent.data", 0), IoError);
  EXPECT_THROW(readPackingCsv(dir.path().string(), 2570.0, 0), IoError);  // a directory
}

// ---- VTK XML ----------------------------------------------------------------------------------------

TEST(VtkXml, ParticlesFileHasOnePointPerParticle) {
  TempDir dir;
  const Simulation sim = twoOverlapping();
  writeParticlesVtu(dir / "particles.vtu", sim);
  const std::string xml = slurp(dir / "particles.vtu");
  EXPECT_TRUE(tagsBalanced(xml));
  EXPECT_EQ(attribute(xml, "NumberOfPoints"), "2");
  EXPECT_EQ(attribute(xml, "NumberOfCells"), "2");
  EXPECT_EQ(dataArray(xml, "radius"), (std::vector<double>{0.5e-3, 0.5e-3}));
  EXPECT_EQ(dataArray(xml, "velocity").size(), 6u);
  EXPECT_EQ(dataArray(xml, "angular_velocity").size(), 6u);
  EXPECT_EQ(dataArray(xml, "contact_count"), (std::vector<double>{1, 1}));
  EXPECT_EQ(dataArray(xml, "id"), (std::vector<double>{0, 1}));
  EXPECT_EQ(dataArray(xml, "types"), (std::vector<double>{1, 1}));
  EXPECT_NEAR(dataArray(xml, "")[3], 1.49e-3, 1e-12);
}

TEST(VtkXml, ContactsFileHasOneLinePerActiveContact) {
  TempDir dir;
  const Simulation sim = twoOverlapping();
  ASSERT_EQ(sim.contacts().activeCount(), 1u);
  writeContactsVtu(dir / "contacts.vtu", sim);
  const std::string xml = slurp(dir / "contacts.vtu");
  EXPECT_TRUE(tagsBalanced(xml));
  EXPECT_EQ(attribute(xml, "NumberOfPoints"), "2");
  EXPECT_EQ(attribute(xml, "NumberOfCells"), "1");
  EXPECT_EQ(dataArray(xml, "types"), (std::vector<double>{3}));
  const auto overlap = dataArray(xml, "overlap");
  ASSERT_EQ(overlap.size(), 1u);
  EXPECT_NEAR(overlap[0], 10e-6, 1e-12);
  EXPECT_GT(dataArray(xml, "normal_force")[0], 0.0);
  EXPECT_EQ(dataArray(xml, "force").size(), 3u);
}

TEST(VtkXml, LineAcrossThePeriodicBoundaryHasTheBranchLength) {
  TempDir dir;
  ParticleStore p;
  p.add({0.2e-3, 2e-3, 2e-3}, 0.5e-3, 2570, 0);
  p.add({3.21e-3, 2e-3, 2e-3}, 0.5e-3, 2570, 0);  // its image at -0.79 mm overlaps particle 0 by 10 um
  const Simulation sim(std::move(p), PeriodicCell::box(4e-3, 4e-3, 4e-3), {Material::paperGlass()},
                       NumericsSettings{});
  const ContactStore& c = sim.contacts();
  ASSERT_EQ(c.activeCount(), 1u);
  double branch = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k)
    if (c.active(k)) branch = c.distance(k, sim.particles().radius);
  writeContactsVtu(dir / "contacts.vtu", sim);
  const auto pts = dataArray(slurp(dir / "contacts.vtu"), "");
  ASSERT_EQ(pts.size(), 6u);
  const double length = (Vec3(pts[3], pts[4], pts[5]) - Vec3(pts[0], pts[1], pts[2])).norm();
  EXPECT_NEAR(length, branch, 1e-8 * branch);
  EXPECT_NEAR(length, 0.99e-3, 1e-9);
}

TEST(VtkXml, CellFileIsOneHexahedron) {
  TempDir dir;
  Mat3 H;
  H << 2, 0.5, 0, 0, 3, 0, 0, 0, 4;
  writeCellVtu(dir / "cell.vtu", PeriodicCell(H));
  const std::string xml = slurp(dir / "cell.vtu");
  EXPECT_TRUE(tagsBalanced(xml));
  EXPECT_EQ(attribute(xml, "NumberOfPoints"), "8");
  EXPECT_EQ(dataArray(xml, "types"), (std::vector<double>{12}));
  const auto pts = dataArray(xml, "");
  ASSERT_EQ(pts.size(), 24u);
  EXPECT_EQ(Vec3(pts[18], pts[19], pts[20]), Vec3(2.5, 3, 4));  // corner 6 = H (1,1,1)
}

TEST(VtkXml, PvdIsValidAfterEveryAdd) {
  TempDir dir;
  PvdCollection pvd(dir / "particles.pvd");
  pvd.add(0.0, "particles_0.vtu");
  EXPECT_TRUE(tagsBalanced(slurp(pvd.path())));
  pvd.add(1.25e-7, "run \"a\"&b/particles_1.vtu");
  const std::string xml = slurp(pvd.path());
  EXPECT_TRUE(tagsBalanced(xml));
  EXPECT_NE(xml.find("timestep=\"1.25e-07\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("file=\"run &quot;a&quot;&amp;b/particles_1.vtu\""), std::string::npos) << xml;
  EXPECT_THROW(pvd.add(std::nan(""), "x.vtu"), InputError);
  PvdCollection lost(dir / "missing/particles.pvd");
  EXPECT_THROW(lost.add(0.0, "x.vtu"), IoError);
  EXPECT_EQ(lost.size(), 0u);
}
