// Bit-exact save/restore of a Simulation (verification ladder §5: save at step N, reload, run k steps:
// identical to an unbroken run). Everything the next step reads is saved, including the neighbour-list
// reference positions and the previous stress used by the boundary-work integral.
#include <cmath>
#include <cstddef>
#include <cstring>

#include "binary_io.hpp"
#include "simulation.hpp"

namespace fl {

namespace {
// 4: the contact results carry the moment n x f in place of the normal (PairResult).
// 3: numerics carry the tangential model; the Mindlin–Deresiewicz history follows the contact history.
// 2: read for compatibility (the default tangential law, no extra history); 2 and 3 give the moments from
// their normals and forces.
// 5: the steps since the last rebuild (the automatic skin's clock, verlet_skin.hpp); older states restart it at 0.
constexpr std::uint32_t kStateVersion = 5;

// NumericsSettings as written by state version 2 (same members and order, no tangentialModel).
struct NumericsSettingsV2 {
  double timeStepFactor, timeStep, localDamping, restitution, densityScale, skin;
  bool trackEnergy;
  int threads;
};
static_assert(sizeof(NumericsSettingsV2) == 56 &&
                  offsetof(NumericsSettingsV2, threads) == offsetof(NumericsSettings, threads),
              "NumericsSettings must keep the version-2 members first, in order");

void putMat(BinaryWriter& w, const Mat3& m) {
  for (int k = 0; k < 9; ++k) w.put(m.data()[k]);
}
Mat3 getMat(BinaryReader& r, const char* f) {
  Mat3 m;
  for (int k = 0; k < 9; ++k) m.data()[k] = r.get<double>(f);
  return m;
}
}  // namespace

void Simulation::saveState(BinaryWriter& w) const {
  w.put(kStateVersion);
  // materials and numerics
  w.put<std::uint64_t>(m_materials.size());
  for (const Material& m : m_materials) {
    w.putString(m.name);
    w.put(m.youngModulus);
    w.put(m.poissonRatio);
    w.put(m.density);
    w.put(m.friction);
  }
  w.put(m_num);
  // particles
  w.putVector(m_p.pos);
  w.putVector(m_p.vel);
  w.putVector(m_p.angVel);
  w.putVector(m_p.force);
  w.putVector(m_p.torque);
  w.putVector(m_p.radius);
  w.putVector(m_p.invMass);
  w.putVector(m_p.invInertia);
  w.putVector(m_p.id);
  w.putVector(m_p.material);
  w.putVector(m_p.image);
  // cell
  putMat(w, m_cell.matrix());
  putMat(w, m_cell.velocityGradient());
  putMat(w, m_cell.logStrainReference());
  w.put(m_cell.logStrain());
  w.put(m_cell.logStrainCompensation());
  // contacts
  w.putVector(m_c.first);
  w.putVector(m_c.second);
  w.putVector(m_c.image);
  w.putVector(m_c.history);
  w.putVector(m_c.mdHistory);  // empty with the default tangential law
  {
    // the results as separate arrays (the distance is derived: r_i + r_j - delta)
    const std::size_t np = m_c.size();
    std::vector<Vec3> moment(np), force(np);
    std::vector<double> overlap(np), distance(np), normalForce(np);
    for (std::size_t p = 0; p < np; ++p) {
      const PairResult& q = m_c.result[p];
      moment[p] = q.moment;
      overlap[p] = q.overlap;
      distance[p] = q.overlap > 0.0 ? m_c.distance(p, m_p.radius) : 0.0;
      normalForce[p] = q.normalForce;
      force[p] = q.force;
    }
    w.putVector(moment);
    w.putVector(overlap);
    w.putVector(distance);
    w.putVector(normalForce);
    w.putVector(force);
  }
  // integrator and bookkeeping
  w.put(m_dt);
  w.put(m_time);
  w.put(m_rayleigh);
  w.put(m_step);
  w.put(m_skin);
  w.put(m_cutoff);
  w.putVector(m_refPos);
  putMat(w, m_refHinv);
  w.put(m_maxDisp2);
  w.put(m_listSteps);
  putMat(w, m_stress);
  putMat(w, m_stressPrev);
  measureContacts();  // the ledger and the diagnostics of the last pass, whole
  EnergyLedger ledger = m_energy;
  ledger.elasticNormal = m_elasticNormal;
  ledger.elasticTangential = m_elasticTangential;
  w.put(ledger);
  w.put(m_diag);
}

Simulation Simulation::restoreState(BinaryReader& r) {
  const auto version = r.get<std::uint32_t>("state version");
  if (version < 2 || version > kStateVersion)
    r.fail("simulation state version " + std::to_string(version) + " is not supported (expected 2 to " +
           std::to_string(kStateVersion) + ")");
  Simulation s;
  const auto nm = r.get<std::uint64_t>("material count");
  if (nm == 0 || nm > 65535) r.fail("implausible material count");
  for (std::uint64_t k = 0; k < nm; ++k) {
    Material m;
    m.name = r.getString("material name");
    m.youngModulus = r.get<double>("material E");
    m.poissonRatio = r.get<double>("material nu");
    m.density = r.get<double>("material density");
    m.friction = r.get<double>("material friction");
    s.m_materials.push_back(m);
  }
  if (version == 2) {
    const auto v2 = r.get<NumericsSettingsV2>("numerics");
    unsigned char b;  // inspect the flag's byte without loading it as a bool (a corrupted byte would be UB)
    std::memcpy(&b, &v2.trackEnergy, 1);
    if (b > 1) r.fail("invalid numerics.trackEnergy flag");
    s.m_num.timeStepFactor = v2.timeStepFactor;
    s.m_num.timeStep = v2.timeStep;
    s.m_num.localDamping = v2.localDamping;
    s.m_num.restitution = v2.restitution;
    s.m_num.densityScale = v2.densityScale;
    s.m_num.skin = v2.skin;
    s.m_num.trackEnergy = v2.trackEnergy;
    s.m_num.threads = v2.threads;
    s.m_num.tangentialModel = TangentialModel::MindlinNoSlip;
  } else {
    s.m_num = r.get<NumericsSettings>("numerics");
    unsigned char b;
    std::memcpy(&b, &s.m_num.trackEnergy, 1);
    if (b > 1) r.fail("invalid numerics.trackEnergy flag");
    if (!isTangentialModel(s.m_num.tangentialModel))
      r.fail("invalid numerics.tangentialModel " + std::to_string(static_cast<int>(s.m_num.tangentialModel)) +
             " (allowed: " + tangentialModelList() + ")");
  }
  try {
    s.m_num.validate();
  } catch (const InputError& e) {
    r.fail(std::string("invalid numerics: ") + e.what());
  }
  ParticleStore& p = s.m_p;
  r.getVectorInto(p.pos, "positions");
  r.getVectorInto(p.vel, "velocities");
  r.getVectorInto(p.angVel, "angular velocities");
  r.getVectorInto(p.force, "forces");
  r.getVectorInto(p.torque, "torques");
  r.getVectorInto(p.radius, "radii");
  r.getVectorInto(p.invMass, "inverse masses");
  r.getVectorInto(p.invInertia, "inverse inertias");
  p.id = r.getVector<std::int32_t>("ids");
  p.material = r.getVector<std::uint16_t>("material indices");
  p.image = r.getVector<Vec3i>("images");
  const std::size_t n = p.pos.size();
  if (n == 0 || p.vel.size() != n || p.angVel.size() != n || p.force.size() != n || p.torque.size() != n ||
      p.radius.size() != n || p.invMass.size() != n || p.invInertia.size() != n || p.id.size() != n ||
      p.material.size() != n || p.image.size() != n)
    r.fail("particle arrays have inconsistent lengths");
  for (std::size_t i = 0; i < n; ++i)
    if (p.material[i] >= nm || !(p.radius[i] > 0.0)) r.fail("invalid particle " + std::to_string(i));
  const Mat3 H = getMat(r, "cell matrix"), L = getMat(r, "velocity gradient"), Href = getMat(r, "cell reference");
  const Vec3 logStrain = r.get<Vec3>("log strain");
  const Vec3 logComp = r.get<Vec3>("log strain compensation");
  if (!(H.determinant() > 0.0) || !(Href.determinant() > 0.0)) r.fail("cell matrix is not invertible");
  s.m_cell.restore(H, L, Href, logStrain, logComp);
  ContactStore& c = s.m_c;
  r.getVectorInto(c.first, "pair first");
  r.getVectorInto(c.second, "pair second");
  r.getVectorInto(c.image, "pair image");
  r.getVectorInto(c.history, "contact history");
  if (version >= 3) r.getVectorInto(c.mdHistory, "Mindlin-Deresiewicz history");
  // version 4: the moments n x f; before: the normals
  const auto normalOrMoment = r.getVector<Vec3>(version >= 4 ? "contact moments" : "contact normals");
  const auto overlap = r.getVector<double>("contact overlaps");
  const auto distance = r.getVector<double>("contact distances");  // derived data: length checked only
  const auto normalForce = r.getVector<double>("contact normal forces");
  const auto force = r.getVector<Vec3>("contact forces");
  const std::size_t np = c.first.size();
  if (c.second.size() != np || c.image.size() != np || c.history.size() != np || normalOrMoment.size() != np ||
      overlap.size() != np || distance.size() != np || normalForce.size() != np || force.size() != np)
    r.fail("contact arrays have inconsistent lengths");
  c.result.resize(np);
  for (std::size_t q = 0; q < np; ++q) {
    const Vec3 moment = version >= 4 ? normalOrMoment[q] : Vec3(normalOrMoment[q].cross(force[q]));
    c.result[q] = {force[q], moment, overlap[q], normalForce[q]};
  }
  const bool md = s.m_num.tangentialModel == TangentialModel::MindlinDeresiewicz;
  if (c.mdHistory.size() != (md ? np : 0))
    r.fail("the Mindlin-Deresiewicz history has " + std::to_string(c.mdHistory.size()) + " entries, expected " +
           std::to_string(md ? np : 0));
  for (std::size_t k = 0; k < c.mdHistory.size(); ++k) {
    const MdHistory& h = c.mdHistory[k];
    std::int32_t branch;
    std::memcpy(&branch, &h.branch, sizeof branch);
    if (branch < 0 || branch > 2 || !(h.locked >= 0.0) || !std::isfinite(h.locked))
      r.fail("invalid Mindlin-Deresiewicz history of contact " + std::to_string(k));
  }
  for (std::size_t k = 0; k < np; ++k)
    if (c.first[k] < 0 || c.second[k] < 0 || static_cast<std::size_t>(c.first[k]) >= n ||
        static_cast<std::size_t>(c.second[k]) >= n)
      r.fail("contact " + std::to_string(k) + " names a particle that does not exist");
  c.buildAdjacency(n);
  s.m_dt = r.get<double>("time step");
  s.m_time = r.get<double>("time");
  s.m_rayleigh = r.get<double>("rayleigh step");
  s.m_step = r.get<long>("step");
  s.m_skin = r.get<double>("skin");
  s.m_cutoff = r.get<double>("cutoff");
  s.m_meanDiameter = meanDiameter(s.m_p);
  r.getVectorInto(s.m_refPos, "reference positions");
  if (s.m_refPos.size() != n) r.fail("reference positions have the wrong length");
  s.m_refHinv = getMat(r, "reference inverse cell");
  s.m_maxDisp2 = r.get<double>("max displacement");
  s.m_listSteps = version >= 5 ? r.get<long>("steps since the last rebuild") : 0;
  if (s.m_listSteps < 0) r.fail("steps since the last rebuild must be >= 0");
  s.m_stress = getMat(r, "stress");
  s.m_stressPrev = getMat(r, "previous stress");
  s.m_energy = r.get<EnergyLedger>("energy ledger");
  s.m_diag = r.get<ContactDiagnostics>("diagnostics");
  s.m_elasticNormal = s.m_energy.elasticNormal;
  s.m_elasticTangential = s.m_energy.elasticTangential;
  s.m_contactsMeasured = true;
  if (!(s.m_dt > 0.0)) r.fail("time step must be > 0");
  // friction may have been changed during the run: the materials carry the current value
  s.m_pairs = PairTable(s.m_materials, s.m_num.restitution);
  s.resizeChunks();
  s.packPassParticles();
  return s;
}

void Simulation::reconfigure(const Material& material, const NumericsSettings& numerics) {
  measureContacts();  // of the last pass, with the moduli it used
  numerics.validate();
  if (!isTangentialModel(numerics.tangentialModel))
    throw InputError("reconfigure: unknown numerics.tangential_model; allowed: " + tangentialModelList());
  for (std::uint16_t m : m_p.material)
    if (m != 0) throw InputError("reconfigure: the specimen uses several materials; a scene defines one");
  m_materials = {material};
  m_num = numerics;  // its skin applies from the next rebuild (0: automatic); the current list keeps its own
  for (std::size_t i = 0; i < m_p.size(); ++i) {
    const double r = m_p.radius[i];
    const double m = material.density * numerics.densityScale * 4.0 / 3.0 * kPi * r * r * r;
    m_p.invMass[i] = 1.0 / m;
    m_p.invInertia[i] = 1.0 / (0.4 * m * r * r);
  }
  m_pairs = PairTable(m_materials, m_num.restitution);
  m_rayleigh = rayleighTimeStep(m_p, m_materials, m_num.densityScale);
  m_dt = m_num.timeStep > 0.0 ? m_num.timeStep : m_num.timeStepFactor * m_rayleigh;
  packPassParticles();  // new masses
  syncTangentialHistory();  // the scene may select another tangential law
}

}  // namespace fl
