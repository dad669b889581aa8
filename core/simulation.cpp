#include "simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <type_traits>


#include "errors.hpp"
#include "history_carry.hpp"
#include "neighbor_search.hpp"

namespace fl {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
// -1, 0 or +1: the direction Cundall's local damping opposes (drift and kick)
inline double signOf(double x) { return x > 0 ? 1.0 : (x < 0 ? -1.0 : 0.0); }

}  // namespace

const char* stageName(Stage s) {
  switch (s) {
    case Stage::Drift: return "drift";
    case Stage::Neighbours: return "neighbours";
    case Stage::Contacts: return "contacts";
    case Stage::Kick: return "kick";
    case Stage::Control: return "control";
    default: return "?";
  }
}

double StageProfile::total() const {
  double t = 0.0;
  for (double s : seconds) t += s;
  return t;
}

Simulation::Simulation(ParticleStore particles, PeriodicCell cell, std::vector<Material> materials,
                       NumericsSettings numerics)
    : m_p(std::move(particles)), m_cell(std::move(cell)), m_materials(std::move(materials)), m_num(numerics) {
  m_num.validate();
  if (!isTangentialModel(m_num.tangentialModel))
    throw InputError("numerics.tangential_model: unknown value " +
                     std::to_string(static_cast<int>(m_num.tangentialModel)) + "; allowed: " + tangentialModelList());
  if (m_materials.empty()) throw InputError("simulation: at least one material is required");
  if (m_p.size() < 1) throw InputError("simulation: no particles");
  for (std::size_t i = 0; i < m_p.size(); ++i)
    if (m_p.material[i] >= m_materials.size())
      throw InputError("simulation: particle " + std::to_string(i) + " names material " +
                       std::to_string(m_p.material[i]) + " but only " + std::to_string(m_materials.size()) +
                       " are defined");
  m_pairs = PairTable(m_materials, m_num.restitution);
  // density scaling multiplies mass and inertia: divide the inverses
  if (m_num.densityScale != 1.0)
    for (std::size_t i = 0; i < m_p.size(); ++i) {
      m_p.invMass[i] /= m_num.densityScale;
      m_p.invInertia[i] /= m_num.densityScale;
    }
  m_rayleigh = rayleighTimeStep(m_p, m_materials, m_num.densityScale);
  m_dt = m_num.timeStep > 0.0 ? m_num.timeStep : m_num.timeStepFactor * m_rayleigh;
  m_meanDiameter = meanDiameter(m_p);
  setSkin(m_num.skin > 0.0 ? m_num.skin : verlet_skin::kMaxFraction * m_meanDiameter);
  refresh();
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

void Simulation::setFriction(double mu) {
  if (!(mu >= 0.0)) throw InputError("friction must be >= 0, got " + std::to_string(mu));
  for (auto& m : m_materials) m.friction = mu;
  m_pairs.setFriction(mu);
}

void Simulation::setTimeStep(double dt) {
  if (!(dt > 0.0)) throw InputError("time step must be > 0 s");
  m_dt = dt;
}

void Simulation::setLocalDamping(double alpha) {
  if (!(alpha >= 0.0 && alpha < 1.0)) throw InputError("localDamping must be in [0, 1)");
  m_num.localDamping = alpha;
}

void Simulation::refresh() {
  rebuildNeighbours();
  computeContacts();
  m_stressPrev = m_stress;
}

void Simulation::step() {
  auto t0 = Clock::now();
  auto& sec = m_profile.seconds;
  drift();
  auto t1 = Clock::now();
  sec[int(Stage::Drift)] += std::chrono::duration<double>(t1 - t0).count();
  forcesAndControl();
  auto t2 = Clock::now();
  kick(KickMode::Alone);
  sec[int(Stage::Kick)] += since(t2);
  ++m_profile.steps;
}

void Simulation::run(long steps) {
  if (steps <= 0) return;
  // Velocity Verlet's closing half kick of one step and the opening half kick and drift of the next read and
  // write the same particle lines: between two steps of one run nobody looks at the state, so they are one
  // sweep (kickPass<..., kDrift>), with the same arithmetic in the same order as step() after step(): the same
  // bits (tests/fused_run_test.cpp). The fused kick keeps the force and torque in registers for the drift and
  // does not store them, and leaves x and v in the pass copy alone (m_storeBehind); the last step's kick
  // stands alone and writes them all back, so the run ends on a whole step. 4000 spheres ~4.5 % faster on 1
  // thread and ~4 % on 2, 256 000 spheres 4-8 % (bench/ab.sh; docs/performance.md, twentieth session).
  // The team is held for all the steps: each loop is handed to the waiting threads, not forked (thread_team.hpp).
  m_team.hold(m_num.threads, [this, steps] {
    auto& sec = m_profile.seconds;
    auto t0 = Clock::now();
    drift();
    sec[int(Stage::Drift)] += since(t0);
    for (long k = 0; k < steps; ++k) {
      forcesAndControl();
      auto t1 = Clock::now();
      if (k + 1 < steps) {
        kick(KickMode::ThenDrift);  // this step's closing kick and the next step's drift
        ++m_profile.fusedKicks;
      } else {
        kick(KickMode::Closing);  // and x and v back into the store
      }
      sec[int(Stage::Kick)] += since(t1);  // with the next step's drift when fused
      ++m_profile.steps;
    }
  });
}

// 2.-4.: neighbours, contacts, the clock and the controller. The controller reads only what the
// contact pass made (cell_controller.hpp), so it runs before the kick: the kick may then be fused with the
// next step's drift, which is the first to use the new L.
void Simulation::forcesAndControl() {
  auto& sec = m_profile.seconds;
  auto t1 = Clock::now();
  ++m_listSteps;
  // the list is rebuilt when a pair outside it may touch, or (automatic skin) when it is found much wider than
  // the displacements need; its new skin follows them (verlet_skin.hpp)
  const verlet_skin::ListStats list = listStats(displacementBound());
  const bool automatic = !(m_num.skin > 0.0);
  if (list.used > m_skin || (automatic && verlet_skin::tooWide(list, m_meanDiameter))) {
    setSkin(automatic ? verlet_skin::optimal(list, m_meanDiameter) : m_num.skin);
    rebuildNeighbours();
    ++m_profile.rebuilds;
  }
  auto t2 = Clock::now();
  sec[int(Stage::Neighbours)] += std::chrono::duration<double>(t2 - t1).count();
  computeContacts();
  auto t3 = Clock::now();
  sec[int(Stage::Contacts)] += std::chrono::duration<double>(t3 - t2).count();
  m_time += m_dt;
  ++m_step;
  if (m_controller) m_cell.setVelocityGradient(m_controller->update(*this));
  sec[int(Stage::Control)] += since(t3);
}

// ---- 1. drift -----------------------------------------------------------------------------------
// What the drift of every particle shares: the cell's step and the local damping.
struct Simulation::DriftPlan {
  double dt, h, alpha;
  bool affine;
  Mat3 phi, Fref;
};

Simulation::DriftPlan Simulation::beginDrift() {
  DriftPlan d;
  d.dt = m_dt;
  d.h = 0.5 * m_dt;
  d.alpha = m_num.localDamping;
  // Boundary work of the affine deformation over this step, trapezoidal in stress:
  // dW = -V (sigma : L) dt with compression-positive sigma (see energy_ledger.hpp).
  const Mat3& L = m_cell.velocityGradient();
  const double V0 = m_cell.volume();
  d.phi = m_cell.advance(d.dt);
  d.affine = !L.isZero(0.0);
  if (d.affine && m_num.trackEnergy) {
    const double Vm = 0.5 * (V0 + m_cell.volume());
    m_energy.boundaryWork -= Vm * (m_stress.cwiseProduct(L)).sum() * d.dt;
  }
  d.Fref = m_cell.matrix() * m_refHinv;
  return d;
}

namespace {
// The kick and the drift run in two loops each, kickPass alone or fused with the next drift (run), and must give
// the same bits in both: g++ fuses multiplies and adds into FMAs (-ffp-contract=fast, its default for C++) as
// each loop's context allows, so the integrator's multiply-adds are written as FMAs and leave it nothing to fuse.

// v + c f: a half kick (c = dt/2 over the mass or the moment of inertia) or a move (c = dt)
[[gnu::always_inline]] inline Vec3 plusScaled(const Vec3& v, double c, const Vec3& f) {
  return Vec3(std::fma(c, f.x(), v.x()), std::fma(c, f.y(), v.y()), std::fma(c, f.z(), v.z()));
}

// A x + b, for a 3x3 A
[[gnu::always_inline]] inline Vec3 affineMap(const Mat3& A, const Vec3& x, const Vec3& b) {
  Vec3 y;
  for (int k = 0; k < 3; ++k) y[k] = std::fma(A(k, 2), x[2], std::fma(A(k, 1), x[1], std::fma(A(k, 0), x[0], b[k])));
  return y;
}

// The drift of one particle (step 1) from its force f and torque t: the opening half kick, Cundall's damping
// as in the kick, and the move; returns |x - F_ref x_ref|^2 for the rebuild test.
template <class Plan>
[[gnu::always_inline]] inline double driftParticle(const Plan& d, Vec3 f, Vec3 t, Vec3& v, Vec3& w, double im,
                                                   double ii, Vec3& x, const Vec3& x0, PassParticle& pass) {
  if (d.alpha > 0.0) {
    for (int k = 0; k < 3; ++k) {
      f[k] = std::fma(-d.alpha * std::abs(f[k]), signOf(v[k]), f[k]);
      t[k] = std::fma(-d.alpha * std::abs(t[k]), signOf(w[k]), t[k]);
    }
  }
  v = plusScaled(v, d.h * im, f);
  w = plusScaled(w, d.h * ii, t);
  x = d.affine ? affineMap(d.phi, x, d.dt * v) : plusScaled(x, d.dt, v);  // Phi x + dt v, or x + dt v
  pass.x = x;
  pass.v = v;
  const Vec3 u = affineMap(-d.Fref, x0, x);
  return std::fma(u.z(), u.z(), std::fma(u.y(), u.y(), u.x() * u.x()));
}
}  // namespace

void Simulation::drift() {
  const DriftPlan plan = beginDrift();
  updateShares();
  m_ranges.reset(m_boundary.begin, kParticleGrain);
  m_threadMax.reset(m_num.threads);
  const auto loop = [this, &plan](const int thread, const int threads) {
  // locals of each thread, which no store of the loop can alias (kickPass)
  const DriftPlan d = plan;
  Vec3* x = m_p.pos.data();
  Vec3* v = m_p.vel.data();
  Vec3* w = m_p.angVel.data();
  const Vec3* F = m_p.force.data();
  const Vec3* T = m_p.torque.data();
  const double* im = m_p.invMass.data();
  const double* ii = m_p.invInertia.data();
  const Vec3* x0 = m_refPos.data();
  PassParticle* pass = m_pass.data();
  const std::size_t n = m_p.size();
  const bool prefetch = thread > 0;  // see kPrefetchAhead
  double maxd2 = 0.0;
  ThreadRuns runs(m_ranges, thread, threads, n);  // the particles this thread moves, run by run
  for (std::size_t begin, end; runs.next(begin, end);)
  for (std::size_t i = begin; i < end; ++i) {
    if (prefetch && i + kPrefetchAhead < n) {
      __builtin_prefetch(x + i + kPrefetchAhead, 1);
      __builtin_prefetch(v + i + kPrefetchAhead, 1);
      __builtin_prefetch(w + i + kPrefetchAhead, 1);
      __builtin_prefetch(pass + i + kPrefetchAhead, 1);
    }
    maxd2 = std::max(maxd2, driftParticle(d, F[i], T[i], v[i], w[i], im[i], ii[i], x[i], x0[i], pass[i]));
  }
  m_threadMax.put(thread, maxd2);
  };
  m_team.each(m_num.threads, loop);
  m_maxDisp2 = m_threadMax.max();
  m_profile.stolenRuns += static_cast<long>(m_ranges.stolen());
}

// ---- 2. neighbours ------------------------------------------------------------------------------
double Simulation::displacementBound() const {
  // A pair's gap can shrink by at most |u_i| + |u_j| (fluctuations since the rebuild) plus
  // ||F - I|| * |l| (homogeneous cell strain since the rebuild, F = H H_ref^-1, |l| <= cut-off).
  const Mat3 strain = m_cell.matrix() * m_refHinv - Mat3::Identity();
  return 2.0 * std::sqrt(m_maxDisp2) + strain.norm() * m_cutoff;
}

verlet_skin::ListStats Simulation::listStats(double used) const {
  // the contacts of the last pass (m_diag.contacts) among the listed pairs: the rest are the list's gaps
  const double gaps = static_cast<double>(m_c.size()) - static_cast<double>(std::min(m_diag.contacts, m_c.size()));
  return {m_skin, m_listSteps, used, gaps / static_cast<double>(m_p.size())};
}

void Simulation::setSkin(double skin) {
  m_skin = skin;
  m_cutoff = 2.0 * m_p.maxRadius() + m_skin;
}

double Simulation::meanDiameter(const ParticleStore& p) {
  double d = 0.0;
  for (double r : p.radius) d += 2.0 * r;
  return d / static_cast<double>(p.size());
}

void Simulation::rebuildNeighbours() {
  const std::size_t n = m_p.size();
  if (m_storeBehind) {  // inside run(): x and v are the pass copy's
    for (std::size_t i = 0; i < n; ++i) {
      m_p.pos[i] = m_pass[i].x;
      m_p.vel[i] = m_pass[i].v;
    }
  }
  // the list being replaced steps aside (its pairs; the history stays, to be carried over in place), and the new
  // list is written into the arrays of the list before it: a rebuild writes no fresh memory (huge_pages.hpp)
  m_oldPairs.first.swap(m_c.first);
  m_oldPairs.second.swap(m_c.second);
  m_oldPairs.image.swap(m_c.image);
  m_imageBeforeWrap = m_p.image;  // the old pairs' keys are of the image counters before wrapping
  // wrap into the cell
  for (std::size_t i = 0; i < n; ++i) m_p.image[i] += m_cell.wrap(m_p.pos[i]);
  {
    PairList L;
    L.first.swap(m_c.first);
    L.second.swap(m_c.second);
    L.image.swap(m_c.image);
    findPairs(m_p, m_cell, m_skin, m_num.threads, &m_team, m_grid, L);
    m_c.first.swap(L.first);
    m_c.second.swap(L.second);
    m_c.image.swap(L.image);
    fitCapacity(m_c.first, m_c.size());  // after a list that grew by more than the room left (the first)
    fitCapacity(m_c.second, m_c.size());
    fitCapacity(m_c.image, m_c.size());
  }
  // the history carried over by key, inside its array (history_carry.hpp)
  matchHistory({m_oldPairs.first, m_oldPairs.second, m_oldPairs.image, m_imageBeforeWrap}, m_c.history,
               {m_c.first, m_c.second, m_c.image, m_p.image}, m_historyMatch);
  moveHistory(m_c.history, m_historyMatch);
  if (m_num.tangentialModel == TangentialModel::MindlinDeresiewicz) {
    if (m_c.mdHistory.empty()) m_c.mdHistory.assign(m_oldPairs.first.size(), MdHistory{});
    moveHistory(m_c.mdHistory, m_historyMatch);
  } else {
    m_c.mdHistory.clear();
  }
  m_c.touched.clear();  // the new list's are made by the first pass that wants them (contact_store.hpp)
  m_c.touchedValid = false;
  m_c.resizeResults();
  m_c.buildAdjacency(n);
  // the old list's arrays are ready for the next list (written once now, when they are first made or resized)
  m_oldPairs.first.clear();
  m_oldPairs.second.clear();
  m_oldPairs.image.clear();
  fitCapacity(m_oldPairs.first, m_c.size());
  fitCapacity(m_oldPairs.second, m_c.size());
  fitCapacity(m_oldPairs.image, m_c.size());
  m_refPos = m_p.pos;
  m_refHinv = m_cell.inverse();
  m_maxDisp2 = 0.0;
  m_listSteps = 0;
  resizeChunks();
  packPassParticles();
}

void Simulation::packPassParticles() {
  const std::size_t n = m_p.size();
  m_pass.resize(n);
  for (std::size_t i = 0; i < n; ++i) m_pass[i] = {m_p.pos[i], m_p.radius[i], m_p.vel[i], m_p.invMass[i]};
}

void Simulation::resizeChunks() {
  m_chunks.resize(std::max<std::size_t>(1, (std::max(m_c.size(), m_p.size()) + kChunk - 1) / kChunk));
  m_boundary.threads = 0;  // the pairs changed: the shares are made again at their first use
  m_seedsReady = false;
}

std::vector<std::size_t> Simulation::chunkFirstParticles() const {
  const std::size_t chunks = (m_c.size() + kChunk - 1) / kChunk;
  std::vector<std::size_t> first(chunks + 1, m_p.size());
  for (std::size_t k = 0; k < chunks; ++k) first[k] = static_cast<std::size_t>(m_c.first[k * kChunk]);
  return first;
}

void Simulation::updateShares() {
  const int nt = std::max(1, m_num.threads);
  if (m_boundary.threads == nt) return;
  // each thread's particles start at the first particle of its first chunk's pairs (pairs are sorted by their
  // first particle); without a chunk each, the particles are split statically and nothing is exchanged; the
  // halo and seeds only while the state stays in cache (kLargeStateFrom)
  // the shares' edges: equal, fixed or from the threads' measured costs (share_balance.hpp)
  m_balance.prepare(nt);
  std::vector<std::size_t> edges;
  if (nt > 1) edges = m_balance.edges(nt, chunkFirstParticles());
  m_boundary = buildThreadBoundary(m_c, m_p.size(), nt, kChunk, m_p.size() < kLargeStateFrom, edges);
  m_haloPass.resize(m_boundary.halo.size());
  m_haloW.resize(m_boundary.halo.size());
  m_seeds.assign(m_boundary.seedParticle.size(), KickSeed{});
  m_seedsReady = false;
}

// ---- 3. contacts: core/contact_pass.cpp ---------------------------------------------------------

// ---- 4. kick ------------------------------------------------------------------------------------
void Simulation::kick(KickMode mode) {
  switch (mode) {
    case KickMode::ThenDrift: {
      const DriftPlan d = beginDrift();  // the next step's cell; the kick reads no cell
      kickIn<KickMode::ThenDrift>(&d);
      m_storeBehind = true;
      return;
    }
    case KickMode::Closing:
      kickIn<KickMode::Closing>(nullptr);
      m_storeBehind = false;
      return;
    case KickMode::Alone:
      kickIn<KickMode::Alone>(nullptr);
      return;
  }
}

template <Simulation::KickMode kMode>
void Simulation::kickIn(const DriftPlan* plan) {
  // seeds only after a pass that summed them (thread_boundary.hpp); one thread never has any
  const bool seeds = m_seedsReady;
  if (m_num.localDamping > 0.0) seeds ? kickPass<true, true, kMode>(plan) : kickPass<true, false, kMode>(plan);
  else seeds ? kickPass<false, true, kMode>(plan) : kickPass<false, false, kMode>(plan);
}

template <bool kLocalDamping, bool kSeeded, Simulation::KickMode kMode>
void Simulation::kickPass(const DriftPlan* plan) {
  constexpr bool kDrift = kMode == KickMode::ThenDrift;
  // after a drift of run(), the pass copy holds x and the mid-step v (the store's may be behind: m_storeBehind)
  constexpr bool kFromPass = kMode != KickMode::Alone;
  const std::size_t count = m_p.size();
  const std::size_t nchunks = (count + kChunk - 1) / kChunk;
  if constexpr (kLocalDamping) m_kickWork.resize(3 * count);
  updateShares();
  const bool seedsReady = m_seedsReady;
  m_seedsReady = false;
  // After a pass with the halo and seeds (a state in cache; the boundary's team) each thread kicks its own share
  // whole (one run of all of it, so none is left to take): a run another thread took here made it write the
  // pass lines, and read the result lines, of particles whose pairs the owner computes next, each a round trip
  // between the cores in the next pass (with the vCPUs far apart the 2-thread step was ~6 % slower for it).
  m_ranges.reset(m_boundary.begin, kSeeded && seedsReady ? count : kParticleGrain);
  m_threadMax.reset(m_num.threads);
  const auto loop = [this, plan, seedsReady, nchunks](const int thread, const int threads) {
  // the loop's inputs, locals of each thread: no store of the loop can alias them (read through the closure,
  // the step size and the arrays' addresses were loaded again after stores: the 2-thread kick ~12 % slower)
  const int n = static_cast<int>(m_p.size());
  const double h = 0.5 * m_dt;
  const double alpha = m_num.localDamping;
  const std::int32_t* adjStart = m_c.adjStart.data();
  const std::int32_t* adjEntry = m_c.adjEntry.data();
  const PairResult* res = m_c.result.data();
  const int entries = adjStart[n];
  const double* rad = m_p.radius.data();
  Vec3* F = m_p.force.data();
  Vec3* T = m_p.torque.data();
  Vec3* v = m_p.vel.data();
  Vec3* w = m_p.angVel.data();
  const double* im = m_p.invMass.data();
  const double* ii = m_p.invInertia.data();
  double* kickWork = m_kickWork.data();
  const ThreadBoundary& tb = m_boundary;
  const KickSeed* seeds = m_seeds.data();
  // kDrift: the next step's drift of each particle right after its kick (run)
  Vec3* x = m_p.pos.data();
  const Vec3* x0 = m_refPos.data();
  PassParticle* pass = m_pass.data();
  ShareBalance& balance = m_balance;
  double maxd2 = 0.0;
  const DriftPlan d = kDrift ? *plan : DriftPlan{};  // a local copy: the stores below cannot alias it
  // the seeds of the last pass hold the leading entries another thread computed, whichever thread kicks the
  // particle; without them (another team size, the Mindlin–Deresiewicz pass) every entry is read in place
  const bool seeded = kSeeded && seedsReady && threads == tb.threads;
  const std::int32_t* kickBegin = tb.kickBegin.data();
  const std::int32_t* seedOf = tb.seedOf.data();
  const std::int32_t* seededList = tb.seeded.data();  // the seeded particles, ascending (when seeded)
  // result lines to prefetch (kPrefetchEntries): all when the state outgrows the caches, else those of the pairs
  // outside this thread's own share of the pass, which another thread most likely computed (with the seeds,
  // none: they carry those entries)
  const bool own = threads == m_boundary.threads;
  const std::size_t passChunks = (m_c.size() + kChunk - 1) / kChunk;
  const auto ownFrom = static_cast<std::uint32_t>(
      2 * kChunk * (own ? m_boundary.chunkBegin[thread] : staticBegin(thread, threads, passChunks)));
  const auto ownTo = static_cast<std::uint32_t>(std::min(
      2 * m_c.size(), 2 * kChunk * (own ? m_boundary.chunkBegin[thread + 1] : staticBegin(thread + 1, threads, passChunks))));
  const bool large = static_cast<std::size_t>(n) >= kLargeStateFrom;
  const bool fetch = large || (threads > 1 && !seeded);
  const std::uint32_t ownSpan = large ? 0 : ownTo - ownFrom;  // every entry lies outside an empty span
  // this thread's time and particles, for the shares of the next boundaries (share_balance.hpp)
  const bool timed = threads > 1 && own && balance.measuring();
  const auto start = timed ? Clock::now() : Clock::time_point{};
  std::size_t particlesDone = 0;
  ThreadRuns runs(m_ranges, thread, threads, static_cast<std::size_t>(n));  // the particles this thread kicks, run by run
  for (std::size_t begin, end; runs.next(begin, end);) {
  particlesDone += end - begin;
  // the next seeded particle from this run's first on (the list ends with an index past every particle)
  std::size_t nextSeed = 0;
  if (kSeeded && seeded)
    nextSeed = static_cast<std::size_t>(
        std::lower_bound(tb.seeded.begin(), tb.seeded.end(), static_cast<std::int32_t>(begin)) - tb.seeded.begin());
  for (std::size_t i = begin; i < end; ++i) {
    if (kDrift && thread > 0 && i + kPrefetchAhead < static_cast<std::size_t>(n))  // as the drift does
      __builtin_prefetch(pass + i + kPrefetchAhead, 1);
    // Pairs that do not touch hold a zero force (the contact pass keeps it so), so they are gathered
    // without a branch: adding zero changes nothing but the sign of a zero. Scalar sums: with Eigen
    // temporaries g++ spilled a cross product as two 8-byte stores read back as one 16-byte load, a
    // store-forwarding stall on the loop-carried torque (kick 5x slower).
    const double ri = rad[i];
    double fx = 0.0, fy = 0.0, fz = 0.0, tx = 0.0, ty = 0.0, tz = 0.0;
    std::int32_t firstEntry = adjStart[i];
    if (kSeeded && seeded && static_cast<std::int32_t>(i) == seededList[nextSeed]) {
      const KickSeed& s0 = seeds[seedOf[i]];
      fx = s0.fx, fy = s0.fy, fz = s0.fz, tx = s0.tx, ty = s0.ty, tz = s0.tz;
      firstEntry = kickBegin[i];
      ++nextSeed;
    }
    for (std::int32_t e = firstEntry; e < adjStart[i + 1]; ++e) {
      // the result line kPrefetchEntries entries ahead (about 16 particles), if it is not in this core's cache
      if (fetch && e + kPrefetchEntries < entries) {
        const auto ahead = static_cast<std::uint32_t>(adjEntry[e + kPrefetchEntries]);
        if (ahead - ownFrom >= ownSpan) __builtin_prefetch(res + (ahead >> 1));
      }
      const std::int32_t entry = adjEntry[e];
      kickEntry(res[entry >> 1], entry, ri, fx, fy, fz, tx, ty, tz);
    }
    const Vec3 fu(fx, fy, fz), tu(tx, ty, tz);
    Vec3 f = fu, t = tu;
    if constexpr (!kDrift) {  // fused with the next drift, the force and torque are used only here (run)
      F[i] = fu;
      T[i] = tu;
    }
    const Vec3 vmid = kFromPass ? pass[i].v : v[i];
    if constexpr (kLocalDamping) {
      // Cundall non-viscous damping: each component of the force opposes the velocity by alpha |F|
      for (int a = 0; a < 3; ++a) {
        f[a] = std::fma(-alpha * std::abs(f[a]), signOf(vmid[a]), f[a]);
        t[a] = std::fma(-alpha * std::abs(t[a]), signOf(w[i][a]), t[a]);
        kickWork[3 * i + a] = alpha * (std::abs(fu[a] * vmid[a]) + std::abs(tu[a] * w[i][a])) * m_dt;
      }
    }
    Vec3 vi = plusScaled(vmid, h * im[i], f), wi = plusScaled(w[i], h * ii[i], t);
    if constexpr (kDrift) {
      // x and v stay in the pass copy alone until the run's closing kick (or a rebuild) writes them back
      Vec3 xi = pass[i].x;
      maxd2 = std::max(maxd2, driftParticle(d, fu, tu, vi, wi, im[i], ii[i], xi, x0[i], pass[i]));
    } else {
      v[i] = vi;
      if constexpr (kFromPass) x[i] = pass[i].x;
    }
    w[i] = wi;
  }
  }
  if (timed) balance.addKick(thread, since(start), particlesDone);
  if constexpr (kLocalDamping) {
    // the work of each fixed chunk of particles, summed in particle order: the same bits for any split
#pragma omp barrier
#pragma omp for schedule(static)
    for (std::size_t k = 0; k < nchunks; ++k) {
      double work = 0.0;
      const std::size_t e = 3 * std::min<std::size_t>(n, (k + 1) * kChunk);
      for (std::size_t q = 3 * k * kChunk; q < e; ++q) work += kickWork[q];
      m_chunks[k].localDamping = work;
    }
  }
  m_threadMax.put(thread, maxd2);
  };
  m_team.each(m_num.threads, loop);
  m_profile.stolenRuns += static_cast<long>(m_ranges.stolen());
  // every kWindowSteps steps: shares that follow the threads' speeds, made at the next pass if they moved
  if (m_boundary.threads > 1 && m_balance.endStep() &&
      m_balance.reconsider(m_boundary.chunkBegin, chunkFirstParticles())) {
    m_boundary.threads = 0;
    ++m_profile.shareChanges;
  }
  if constexpr (kDrift) m_maxDisp2 = m_threadMax.max();
  if constexpr (kLocalDamping) {
    if (m_num.trackEnergy)
      for (std::size_t k = 0; k < nchunks; ++k) m_energy.localDampingWork += m_chunks[k].localDamping;
  }
}

std::size_t Simulation::memoryBytes() const {
  auto b = [](const auto& v) { return v.capacity() * sizeof(typename std::decay_t<decltype(v)>::value_type); };
  const ParticleStore& p = m_p;
  const ContactStore& c = m_c;
  return b(p.pos) + b(p.vel) + b(p.angVel) + b(p.force) + b(p.torque) + b(p.radius) + b(p.invMass) +
         b(p.invInertia) + b(p.id) + b(p.material) + b(p.image) + b(c.first) + b(c.second) + b(c.image) +
         b(c.history) + b(c.mdHistory) + b(c.result) + b(c.adjStart) + b(c.adjEntry) + b(m_refPos) +
         b(m_pass) + b(m_chunks) + b(m_kickWork) + b(m_haloPass) + b(m_haloW) + b(m_seeds) +
         b(m_boundary.partner) + b(m_boundary.halo) + b(m_boundary.seedParticle) + b(m_boundary.seedOf) +
         b(m_boundary.kickBegin) + b(m_boundary.seeded) + b(m_boundary.seedEntry) +
         b(m_boundary.seedEntryBegin) + b(m_boundary.haloPairs) + b(m_oldPairs.first) +
         b(m_oldPairs.second) + b(m_oldPairs.image) + b(m_historyMatch) + b(m_imageBeforeWrap) + m_grid.bytes();
}

// ---- measures -----------------------------------------------------------------------------------
Mat3 Simulation::kineticStress() const {
  Mat3 s = Mat3::Zero();
  for (std::size_t i = 0; i < m_p.size(); ++i) s += (1.0 / m_p.invMass[i]) * m_p.vel[i] * m_p.vel[i].transpose();
  return s / m_cell.volume();
}

const EnergyLedger& Simulation::energy() {
  measureContacts();
  m_energy.elasticNormal = m_elasticNormal;
  m_energy.elasticTangential = m_elasticTangential;
  double k = 0.0;
  for (std::size_t i = 0; i < m_p.size(); ++i)
    k += 0.5 * (m_p.vel[i].squaredNorm() / m_p.invMass[i] + m_p.angVel[i].squaredNorm() / m_p.invInertia[i]);
  m_energy.kinetic = k;
  return m_energy;
}

double Simulation::unbalancedForceRatio() const {
  const ContactDiagnostics& d = diagnostics();
  if (d.contacts == 0 || d.meanContactForce <= 0.0) return 0.0;
  double s = 0.0;
  for (const Vec3& f : m_p.force) s += f.norm();
  return s / static_cast<double>(m_p.size()) / d.meanContactForce;
}

double Simulation::stiffnessTimeStep() const {
  const double kOverM = diagnostics().maxStiffnessOverMass;
  if (kOverM <= 0.0) return std::numeric_limits<double>::infinity();
  return 2.0 / std::sqrt(kOverM);
}

}  // namespace fl
