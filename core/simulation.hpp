// The simulation: particles, periodic cell, contact store and the step pipeline.
//
// One step (velocity Verlet; Cundall & Strack 1979 explicit DEM), as a flat list of timed stages:
//   1. drift      half kick v += dt/2 a, x = Phi x + dt v', cell H = Phi H (Phi = exp(L dt))
//   2. neighbours rebuild the Verlet list when a displacement or the cell strain may exceed the skin
//   3. contacts   Hertz–Mindlin forces for every pair, written into the contact store, with the
//                 Love–Weber stress and (if tracked) the dissipated energies summed in the same pass; the
//                 tangential law (numerics.tangentialModel) is a template parameter chosen once per pass.
//                 What only measurements read (the diagnostics' extremes, the elastic energies) is read off
//                 the stored contacts when asked for, not computed every step
//   4. control    the cell controller (if any) sets L for the next step from the pass's stress
//   5. kick       forces gathered per particle in a fixed order, half kick v += dt/2 a
// run(n) fuses each step's kick with the next step's drift: one sweep over the particles instead of two.
// Deterministic: every reduction is over fixed-size chunks summed in chunk order, and forces are gathered
// per particle from the CSR adjacency, so the bits do not depend on the thread count, nor on which thread
// computed what: the parallel loops balance their work between the threads as they go (work_stealing.hpp),
// and while the state fits in cache the partners and force sums that cross the threads' shares go through a
// halo and seeds (thread_boundary.hpp): copies and the kick's own partial sums.
// Stress sign: compression positive (soil mechanics), sigma = (1/V) sum_c f_c (x) l_c with f_c the force
// on j and l_c the branch vector from i to j.
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "cell_controller.hpp"
#include "contact_store.hpp"
#include "energy_ledger.hpp"
#include "material.hpp"
#include "neighbor_search.hpp"
#include "numerics.hpp"
#include "particle_store.hpp"
#include "periodic_cell.hpp"
#include "share_balance.hpp"
#include "thread_boundary.hpp"
#include "thread_team.hpp"
#include "verlet_skin.hpp"
#include "work_stealing.hpp"

namespace fl {

class BinaryWriter;
class BinaryReader;

enum class Stage { Drift, Neighbours, Contacts, Kick, Control, Count };
const char* stageName(Stage s);

// Cumulative wall time per stage [s] and counts.
struct StageProfile {
  std::array<double, static_cast<int>(Stage::Count)> seconds{};
  long steps = 0;
  long rebuilds = 0;
  long stolenRuns = 0;  // runs of a parallel loop one thread took from another's share (work_stealing.hpp)
  long fusedKicks = 0;  // steps whose kick ran with the next step's drift (Simulation::run)
  long shareChanges = 0;  // times the threads' shares were made again from their measured speeds (share_balance.hpp)
  double total() const;
};

// Diagnostics of the last force pass. The default law's pass sums the counts and the axis stiffness; the
// extremes and the mean force are read off the stored contacts when first asked for after a step
// (Simulation::diagnostics), so a step that nobody measures does not pay for them.
struct ContactDiagnostics {
  double maxOverlapRatio = 0.0;   // max delta / min(r_i, r_j) [-]
  double maxStiffnessOverMass = 0.0;  // max (k_n or 3.5 k_t) / m* [1/s^2]
  double meanContactForce = 0.0;  // mean |f_c| over touching pairs [N]
  std::size_t contacts = 0;       // touching pairs
  std::size_t sliding = 0;        // pairs at the Coulomb limit
  // Tangent stiffness of the packing for an affine strain along each axis, d sigma_kk / d eps_kk
  // = (1/V) sum k_n (n_k l_k)^2 [Pa]; scales the servo gain.
  Vec3 axisStiffness = Vec3::Zero();
};

class Simulation {
 public:
  // From this many particles (~7.6 MB of state at ~760 bytes each) the state outgrows the caches, and the step
  // reads its lines as it would from memory:
  // - software prefetches pay for every line, not only those the other core last wrote: the contact pass
  //   prefetches every partner and the kick every result line (with one thread, 32 000 spheres (24 MB) ran
  //   3.2e6 particle-steps/s without and 4.5e6 with the partners' prefetch, 4000 spheres (3 MB) ~15 % faster
  //   without; Zen 3, docs/performance.md);
  // - the contact pass writes its result lines with streaming stores (core/streaming_store.hpp): 256 000 and
  //   1M spheres 4-14 % faster on an Intel host, 32 000 level (docs/performance.md, sixteenth session).
  static constexpr std::size_t kLargeStateFrom = 10000;
  Simulation(ParticleStore particles, PeriodicCell cell, std::vector<Material> materials,
             NumericsSettings numerics);
  ~Simulation();
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;

  void step();
  // steps whole steps, the same bits as calling step() as often; between them nobody can look at the state,
  // so each step's closing kick is fused with the next step's drift (simulation.cpp)
  void run(long steps);

  // state
  const ParticleStore& particles() const { return m_p; }
  ParticleStore& mutableParticles() { return m_p; }  // callers must call refresh() after editing
  const PeriodicCell& cell() const { return m_cell; }
  const ContactStore& contacts() const { return m_c; }
  // The contact pass's copy of x, r, v, 1/m, one line per particle. Between steps x, r and 1/m equal the
  // store's (checkInvariants checks it); v is the mid-step velocity the last pass used.
  const HugeVector<PassParticle>& passParticles() const { return m_pass; }
  const std::vector<Material>& materials() const { return m_materials; }
  const NumericsSettings& numerics() const { return m_num; }
  double time() const { return m_time; }     // [s]
  long stepCount() const { return m_step; }
  double timeStep() const { return m_dt; }   // [s]
  double rayleighStep() const { return m_rayleigh; }  // [s], with density scaling
  // 2 sqrt(m*/k) at the stiffest current contact [s]; infinity without contacts.
  double stiffnessTimeStep() const;
  double skin() const { return m_skin; }  // of the current neighbour list [m] (automatic: verlet_skin.hpp)

  // measures read from stored data
  const Mat3& contactStress() const { return m_stress; }  // [Pa], compression positive
  Mat3 kineticStress() const;                             // (1/V) sum m v' v' [Pa]
  const EnergyLedger& energy();  // refreshes the kinetic term and reads the elastic ones off the contacts
  double unbalancedForceRatio() const;  // mean |F_i| / mean |f_c|
  const ContactDiagnostics& diagnostics() const {
    measureContacts();
    return m_diag;
  }
  // What every pass sums itself (either law), read without measuring the contacts: the servo's per-step
  // inputs. diagnostics() reads the rest off all stored contacts, serially, so a controller that called it
  // every step paid a measurement per step (11-17 % of a servo-controlled run; docs/performance.md).
  const Vec3& axisStiffness() const { return m_diag.axisStiffness; }
  // true once the diagnostics' extremes and the elastic energies of the last pass have been read off the
  // contacts (or the pass summed them itself): a step that nobody measured leaves it false
  bool contactsMeasured() const { return m_contactsMeasured; }
  const StageProfile& profile() const { return m_profile; }
  // The threads' shares and what crosses between them, as the last parallel step made them (thread_boundary.hpp)
  const ThreadBoundary& threadBoundary() const { return m_boundary; }
  // The threads' shares of the step are measured from their speed (the default, share_balance.hpp); fixed here
  // instead (one weight per thread; empty: equal). Neither changes the results, only the time.
  void setFixedShares(std::vector<double> shares) {
    m_balance.fix(std::move(shares));
    m_boundary.threads = 0;  // made again at the next use
  }
  const ShareBalance& shareBalance() const { return m_balance; }
  // Heap bytes held by the state (particle and pair arrays by capacity, history, adjacency, reduction
  // chunks); the neighbour grid is a temporary of each rebuild and not counted.
  std::size_t memoryBytes() const;

  // commands (apply between steps)
  void setVelocityGradient(const Mat3& L) { m_cell.setVelocityGradient(L); }
  // Installs the controller and applies it at once (from the stored forces), so the next step already
  // follows it; nullptr leaves the current L in place.
  void setController(std::shared_ptr<CellController> c) {
    m_controller = std::move(c);
    if (m_controller) m_cell.setVelocityGradient(m_controller->update(*this));
  }
  const std::shared_ptr<CellController>& controller() const { return m_controller; }
  void setFriction(double mu);            // all material pairs
  void setTimeStep(double dt);
  void setLocalDamping(double alpha);
  // Rebuild the neighbour list and recompute forces after the particles or cell were edited.
  void refresh();
  // Restore time/counters (checkpoint restart).
  void setClock(double time, long step) {
    m_time = time;
    m_step = step;
  }
  EnergyLedger& mutableEnergy() { return m_energy; }

  // Full state for bit-exact restart (simulation_state.cpp): particles, cell, contact store with
  // history, neighbour-list reference, stresses, energies, clock. The controller is not included.
  void saveState(BinaryWriter& w) const;
  static Simulation restoreState(BinaryReader& r);
  // Applies another scene's material and numerics to a restored specimen (branching one specimen into
  // several histories): masses from the new density and density scale, pair table, time step, threads.
  // The contact state and the skin are kept.
  void reconfigure(const Material& material, const NumericsSettings& numerics);

 private:
  struct DriftPlan;  // the cell's step and the damping, which every particle's drift shares
  DriftPlan beginDrift();  // advances the cell by one step and books its boundary work
  void drift();
  double displacementBound() const;  // how far the gap of a pair may have shrunk since the last rebuild [m]
  void setSkin(double skin);  // the next list's skin, and its cut-off
  verlet_skin::ListStats listStats(double used) const;  // what the automatic skin reads of the current list
  static double meanDiameter(const ParticleStore& p);
  void forcesAndControl();  // neighbours, contacts, the clock and the controller
  void rebuildNeighbours();
  void resizeChunks();  // m_chunks for the current pair and particle counts
  void packPassParticles();  // m_pass from the particle store, whole
  void computeContacts();
  Simulation() = default;  // for restoreState
  template <bool kMindlinDeresiewicz>
  void dispatchContactPass();
  template <bool kEnergy, bool kDamping, bool kAffine, bool kMindlinDeresiewicz>
  void contactPass();  // selects one of the two below
  // Default law: pairs gathered into blocks of touching pairs, law vectorised across them (contact_block.hpp).
  // kHalo: the partners of other threads' shares are read from the halo and the seeds are summed
  // (thread_boundary.hpp); one thread pays no select
  template <bool kEnergy, bool kDamping, bool kAffine, bool kHalo>
  void contactPassBlocked();
  // Mindlin–Deresiewicz law: the normal contact as the default law's (hertzNormalBlock) and the tangential
  // law vectorised over blocks of touching pairs (mindlin_deresiewicz_block.hpp), the rare pairs it flags
  // through the scalar kernel.
  template <bool kEnergy, bool kDamping, bool kAffine>
  void contactPassMindlinDeresiewicz();
  // Sums the pass's chunk partials in chunk order into the stress, energies and diagnostics.
  // kMeasured: the pass summed the diagnostics' extremes and means and the elastic energies itself (the
  // Mindlin–Deresiewicz pass); else they are left to measureContacts.
  template <bool kEnergy, bool kMeasured>
  void reduceContactChunks(std::size_t nchunks);
  // The diagnostics' extremes and mean force and the elastic energies of the last pass, read off the stored
  // contacts (results and history), once per pass and only when asked for (contact_pass.cpp).
  void measureContacts() const;
  // Sizes the Mindlin–Deresiewicz history array for the selected law (empty for the default law; when
  // switching to it, fresh histories start from the stored normal forces).
  void syncTangentialHistory();
  enum class KickMode {
    Alone,      // step(): v in the store
    ThenDrift,  // run(): each particle then drifts by *plan; x and v are left in the pass copy alone
    Closing,    // run()'s last kick: x and the mid-step v read from the pass copy, and written back to the store
  };
  void kick(KickMode mode);
  template <KickMode kMode>
  void kickIn(const DriftPlan* plan);  // picks the kick for the damping and the seeds
  // kSeeded: the last pass summed the seeds of this team
  template <bool kLocalDamping, bool kSeeded, KickMode kMode>
  void kickPass(const DriftPlan* plan);
  // The threads' own shares of the pair chunks (a static split) and of the particles (each thread's starting
  // where the pairs of its first chunk start, so that it drifts and kicks the particles whose pairs it computes
  // as first particle), with the halo and seeds between them (thread_boundary.hpp), for m_num.threads; made
  // again after each rebuild or restore and when the thread count changes. The parallel loops start from them
  // and balance from there (work_stealing.hpp).
  void updateShares();
  std::vector<std::size_t> chunkFirstParticles() const;  // the first particle of each pair chunk, then the count

  ParticleStore m_p;
  HugeVector<PassParticle> m_pass;  // the contact pass's copy of x, r, v, 1/m (particle_store.hpp)
  PeriodicCell m_cell;
  std::vector<Material> m_materials;
  PairTable m_pairs;
  NumericsSettings m_num;
  ContactStore m_c;
  std::shared_ptr<CellController> m_controller;

  double m_dt = 0.0, m_time = 0.0, m_rayleigh = 0.0;
  long m_step = 0;
  double m_skin = 0.0, m_cutoff = 0.0;  // of the current list
  double m_meanDiameter = 0.0;  // [m], the automatic skin's unit (verlet_skin.hpp)
  long m_listSteps = 0;         // steps since the last rebuild
  // rebuild bookkeeping
  HugeVector<Vec3> m_refPos;  // positions at the last rebuild
  Mat3 m_refHinv;              // H^-1 at the last rebuild
  double m_maxDisp2 = 0.0;     // max |x - F x_ref|^2 after the last drift
  // The pairs of the list being replaced, set aside during a rebuild for the history's carry-over; between
  // rebuilds these arrays keep their capacity, and the next rebuild's list is written into them. With the history
  // moved in place and the grid's scratch kept, a rebuild writes no fresh memory (a fresh page costs ~1.6 ms a MB
  // on the VMs we measure on: docs/performance.md, fortieth session).
  PairList m_oldPairs;
  HugeVector<std::uint32_t> m_historyMatch;  // history_carry.hpp
  std::vector<Vec3i> m_imageBeforeWrap;      // the particles' image counters before the rebuild wraps them
  GridScratch m_grid;

  Mat3 m_stress = Mat3::Zero();
  Mat3 m_stressPrev = Mat3::Zero();
  EnergyLedger m_energy;  // its elastic terms are filled from m_elasticNormal/Tangential by energy()
  mutable ContactDiagnostics m_diag;
  mutable double m_elasticNormal = 0.0, m_elasticTangential = 0.0;  // [J], of the last pass
  mutable bool m_contactsMeasured = false;  // m_diag and the elastic energies are of the last pass
  StageProfile m_profile;
  // Fixed reduction block (pairs or particles): results are independent of the thread count. Small enough
  // that 2 threads share ~60 blocks of a 4000-sphere packing evenly, large enough to amortise a block's sums.
  static constexpr std::size_t kChunk = 256;
  // How far ahead (particles) the drift prefetches the lines it will write: lines last read by the other
  // core arrive ~200 ns late on this kind of VM, ~25 particles' work at ~8 ns each (docs/performance.md,
  // "per-thread busy time": 4 ahead left the second thread's drift 50 % slower than the first's). Only the
  // threads after the first prefetch: the first thread's particles are read by no other thread's pass, and its
  // streams are sequential.
  static constexpr int kPrefetchAhead = 32;
  // How far ahead (adjacency entries) the kick prefetches the result lines it will gather: ~16 particles of
  // the dense packing's ~8.7 listed pairs each, ~200 ns of the kick's work (35 entries left the second
  // thread, which gathers the results the first wrote across the boundary, 20 % slower). Only the lines of
  // pairs outside the thread's own share of the pass (another core most likely wrote them), or all from
  // kLargeStateFrom particles: with one thread at 4000 spheres, prefetching every entry cost 2-7 % of a step.
  static constexpr int kPrefetchEntries = 140;
  // How far ahead (entries of ThreadBoundary::seedEntry, ~8 seeds) the seeds' sum prefetches the result lines.
  static constexpr int kSeedAhead = 16;
  // How far ahead (listed pairs, ~40 particles) the contact pass prefetches each partner's pass line and omega
  // when the state outgrows the caches: one pair's prefetch per pair computed, spread through the block's
  // geometry loop. The same prefetches issued as a burst of 128 per block of 64 pairs left the step 6 % slower
  // at 1M spheres (docs/performance.md, twenty-fifth session); 96 to 256 pairs ahead measured alike.
  static constexpr std::size_t kPartnerAhead = 128;
  // How far ahead (listed pairs, 8 KiB) the same loop prefetches the history lines it reads and writes back, one
  // line per two pairs: 256 000 and 1M spheres 4-6 % faster on 1 thread, ~5 % on 2 (twenty-fifth session; a burst
  // of the 32 lines of a later block was 3-10 % slower in the nineteenth and twenty-fourth).
  static constexpr std::size_t kHistoryAhead = 256;
  // Partial sums of one fixed block of pairs (or particles), reduced in block order.
  struct Chunk {
    Mat3 stress = Mat3::Zero();  // sum f (x) l [N m]
    double elasticN = 0.0, elasticT = 0.0, friction = 0.0, damping = 0.0, localDamping = 0.0;
    double sumForce = 0.0, maxOverlapRatio = 0.0, maxKOverM = 0.0;
    Vec3 stiffness = Vec3::Zero();
    std::size_t contacts = 0, sliding = 0;
    char pad[64] = {};  // keep neighbouring chunks on separate cache lines
  };
  std::vector<Chunk> m_chunks;
  // the kick's local-damping work terms of each particle (3 per particle, in the order the serial sum adds
  // them), summed per fixed chunk of particles after the kick: the threads' shares need not fall on chunks
  HugeVector<double> m_kickWork;
  // Runs of particles a thread claims at a time in the drift and the kick: ~0.9 µs of drift and ~2.6 µs of kick
  // work at ~14 and ~41 ns a particle (4000 spheres, one thread), against a claim's ~10 ns (an atomic on a line
  // its own thread holds); 32 and 128 were no better (docs/performance.md, twelfth session).
  static constexpr std::size_t kParticleGrain = 64;
  ThreadTeam m_team;        // the threads of the step's loops, held through run() (thread_team.hpp)
  ThreadMax m_threadMax;    // the largest drift of each thread in the last drift
  StealingRanges m_ranges;  // the claims of the current parallel loop
  // the threads' shares of the pair chunks and particles (chunkBegin, begin) with the halo and seeds, for a team
  // of m_boundary.threads (updateShares; 0: to be made)
  ThreadBoundary m_boundary;
  ShareBalance m_balance;  // where the threads' shares of the boundary begin
  std::vector<PassParticle> m_haloPass;  // halo slots: the pass copy and omega of other threads' partners
  std::vector<Vec3> m_haloW;
  std::vector<KickSeed> m_seeds;  // slot 0 stays zero
  RoundProgress m_haloProgress;   // how many of its halo slots each thread has copied in this pass
  static constexpr std::size_t kHaloBatch = 64;  // slots an owner copies between two publications
  bool m_seedsReady = false;      // the last pass summed the seeds for this team
  // inside run(), after a fused kick and drift: the particle store's x and v are behind the pass copy's (its
  // closing kick and rebuilds bring them back)
  bool m_storeBehind = false;
};

}  // namespace fl
