// Step 3 of the pipeline (simulation.hpp): the contact forces of every listed pair, written into the
// contact store, with the Love–Weber stress, the axis stiffness, the contact and sliding counts and (if
// tracked) the dissipated energies summed per fixed chunk of pairs in the same pass. The default law runs
// vectorised over blocks of touching pairs (contact_block.hpp) and leaves the diagnostics' extremes and mean
// force and the elastic energies to measureContacts, which reads them off the stored contacts when asked for;
// the Mindlin–Deresiewicz law runs vectorised over blocks of touching pairs too (mindlin_deresiewicz_block.hpp)
// and sums them all itself.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include <omp.h>

#include "contact_block.hpp"
#include "contact_kernels.hpp"
#include "mindlin_deresiewicz_block.hpp"
#include "simulation.hpp"
#include "streaming_store.hpp"

namespace fl {

namespace {
// What both contact passes read and write: the arrays as plain pointers for the OpenMP loops, the cell
// and its L, the time step and the pair count. The particles' x, r, v and 1/m come from their one-line copy
// (PassParticle, particle_store.hpp), omega and the material from the store.
struct PassArrays {
  const PassParticle* pp;  // x, r, v, 1/m
  const Vec3* w;           // angular velocities
  const std::uint16_t* mat;
  const std::int32_t* first;
  const std::int32_t* second;
  const Image* image;
  ContactHistory* hist;
  PairResult* result;
  const PeriodicCell& cell;  // H, for the image shift H·image
  const Mat3& L;  // velocity gradient
  double dt;      // [s]
  std::size_t np;  // listed pairs
  PassArrays(const HugeVector<PassParticle>& pass, const ParticleStore& p, ContactStore& c,
             const PeriodicCell& periodicCell, double timeStep)
      : pp(pass.data()), w(p.angVel.data()), mat(p.material.data()), first(c.first.data()),
        second(c.second.data()), image(c.image.data()), hist(c.history.data()), result(c.result.data()),
        cell(periodicCell), L(periodicCell.velocityGradient()), dt(timeStep), np(c.size()), n(p.size()) {}
  std::size_t n;   // particles
  std::size_t chunks(std::size_t chunk) const { return (np + chunk - 1) / chunk; }
  // l = x_j + H image - x_i for pair p = (i, j, image)
  Vec3 branch(std::size_t p, int i, int j) const {
    Vec3 d = pp[j].x - pp[i].x;
    const Image img = image[p];
    if (!img.isZero()) d += cell.shift(img.vec());
    return d;
  }
};

}  // namespace

void Simulation::computeContacts() {
  // the tangential law is chosen once per pass, not per pair
  if (m_num.tangentialModel == TangentialModel::MindlinDeresiewicz) dispatchContactPass<true>();
  else dispatchContactPass<false>();
}

template <bool kMD>
void Simulation::dispatchContactPass() {
  // one instantiation per combination of optional terms: no branch on a disabled feature in the loop
  const bool damping = m_num.restitution < 1.0;
  const bool affine = !m_cell.velocityGradient().isZero(0.0);
  const int mode = (m_num.trackEnergy ? 4 : 0) | (damping ? 2 : 0) | (affine ? 1 : 0);
  switch (mode) {
    case 0: contactPass<false, false, false, kMD>(); break;
    case 1: contactPass<false, false, true, kMD>(); break;
    case 2: contactPass<false, true, false, kMD>(); break;
    case 3: contactPass<false, true, true, kMD>(); break;
    case 4: contactPass<true, false, false, kMD>(); break;
    case 5: contactPass<true, false, true, kMD>(); break;
    case 6: contactPass<true, true, false, kMD>(); break;
    default: contactPass<true, true, true, kMD>(); break;
  }
}

void Simulation::syncTangentialHistory() {
  if (m_num.tangentialModel != TangentialModel::MindlinDeresiewicz) {
    // leaving the law: its locked micro-slip energy is dissipated (the ledger stays balanced)
    if (m_num.trackEnergy)
      for (const MdHistory& h : m_c.mdHistory) m_energy.frictionWork += h.locked;
    m_c.mdHistory.clear();
    m_c.mdHistory.shrink_to_fit();
  } else if (m_c.mdHistory.size() != m_c.size()) {
    m_c.mdHistory.assign(m_c.size(), MdHistory{});
    for (std::size_t p = 0; p < m_c.size(); ++p) m_c.mdHistory[p].prevNormalForce = m_c.result[p].normalForce;
  }
}

template <bool kEnergy, bool kDamping, bool kAffine, bool kMD>
void Simulation::contactPass() {
  if constexpr (kMD) {
    contactPassMindlinDeresiewicz<kEnergy, kDamping, kAffine>();
  } else {
    updateShares();
    if (m_boundary.exchange) contactPassBlocked<kEnergy, kDamping, kAffine, true>();
    else contactPassBlocked<kEnergy, kDamping, kAffine, false>();
  }
}

template <bool kEnergy, bool kDamping, bool kAffine, bool kHalo>
void Simulation::contactPassBlocked() {
  // Three phases per block of listed pairs, all within one reduction chunk (so the bits do not depend on
  // the thread count): 1. gather the touching pairs' inputs into a PairBlock (branch-free compaction);
  // 2. the law, vectorised across the block (kernels::hertzMindlinBlock); 3. scatter the results and
  // history back and sum the chunk's partials in pair order.
  static_assert(kChunk % kernels::kBlockPairs == 0, "reduction chunks hold whole blocks");
  static_assert(kernels::kBlockPairs == 64, "a block's touching pairs are one word of ContactStore::touched");
  static_assert(ThreadBoundary::kHaloBlock == kernels::kBlockPairs, "a block's halo pairs are one word");
  static_assert(sizeof(ContactHistory) == 32, "two pairs' history per line (kHistoryAhead's prefetch)");
  if (!m_c.touchedValid) m_c.markTouched();  // after a rebuild, a restore or the other law's pass
  m_ranges.reset(m_boundary.chunkBegin, 1);  // contactPass made the shares (updateShares)
  int team = 0;
  // the cores set how long a wait spins (spin_wait.hpp): one thread never waits, and asks nothing (a system call)
  const int cores = m_num.threads > 1 ? m_team.cores() : 1;
  const std::uint64_t round = m_haloProgress.beginRound(m_num.threads, cores);
  const auto loop = [this, &team, round](const int t, const int nt) {
    if (t == 0) team = nt;
    // locals of each thread, which no store of the pass can alias (kickPass)
    std::uint64_t* touched = m_c.touched.data();
    const PassArrays arr(m_pass, m_p, m_c, m_cell, m_dt);
    const std::size_t np = arr.np, nchunks = arr.chunks(kChunk);
    const PassParticle* pass = arr.pp;
    const PairTable& table = m_pairs;
    Chunk* chunks = m_chunks.data();
    const Vec3* omega = arr.w;
    const ThreadBoundary& tb = m_boundary;
    PassParticle* haloPass = m_haloPass.data();
    Vec3* haloW = m_haloW.data();
    KickSeed* seeds = m_seeds.data();
    const auto n = static_cast<std::int32_t>(arr.n);
    RoundProgress& haloProgress = m_haloProgress;
    ShareBalance& balance = m_balance;
    // this thread's time and chunks, for the shares of the next boundaries (share_balance.hpp)
    const bool timed = nt > 1 && nt == tb.threads && balance.measuring();
    const auto start = timed ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
    std::size_t chunksDone = 0;
    // with the boundary of this team: each owner first copies the partners other threads read into the halo
    // (thread_boundary.hpp), and the pass reads them there, whichever thread computes the pair. No barrier: the
    // owner publishes its progress every kHaloBatch slots, and a reader waits before a block of its share for
    // the slots it and the next block read (haloNeed), before a chunk of another share for all of them.
    const bool exchange = kHalo && nt == tb.threads && tb.exchange;
    if (exchange) {
      const std::size_t q0 = tb.haloBegin[t], q1 = tb.haloBegin[t + 1];
      std::size_t q = q0;
      do {
        for (const std::size_t qe = std::min(q1, q + kHaloBatch); q < qe; ++q) {
          const std::int32_t j = tb.halo[q];
          // streaming stores: a plain store would first wait for each line that the readers hold since the last
          // pass (~330 ns a line with the vCPUs far apart, where this copy took ~23 µs a step against ~3.5)
          double line[8];
          static_assert(sizeof(PassParticle) == sizeof line);
          std::memcpy(line, &pass[j], sizeof line);
          streamLine(haloPass + q, line);
          streamWords(haloW[q].data(), omega[j].data(), 3);
        }
        streamFence();  // the slots are written before the count that tells the readers so
        haloProgress.publish(t, round, static_cast<std::uint32_t>(q - q0));
      } while (q < q1);
    }
    std::uint32_t haloHave = exchange ? 0 : std::numeric_limits<std::uint32_t>::max();  // slots known written
    // (each wait reads the owner's line, which its next publication takes back: so a reader notes all that
    // is published, and reads the line again only when a block needs more)
    const auto awaitHalo = [&haloHave, &haloProgress, &tb, t, nt, round](std::uint32_t need) {
      if (need <= haloHave) return;
      std::uint32_t have = std::numeric_limits<std::uint32_t>::max();
      for (int s = 0; s < nt; ++s) {
        const auto size = static_cast<std::uint32_t>(tb.haloBegin[s + 1] - tb.haloBegin[s]);
        if (s == t || size == 0) continue;
        const std::uint32_t done = haloProgress.waitFor(s, round, std::min(need, size));
        if (done < size) have = std::min(have, done);  // a whole group counts as every slot
      }
      haloHave = have;
    };
    const std::int32_t* partner = exchange ? tb.partner.data() : arr.second;
    // a partner index past the particle count is a halo slot (kHalo only: one thread pays no select)
    const auto passOf = [pass, haloPass, n](std::int32_t jn) -> const PassParticle& {
      if constexpr (kHalo) return jn < n ? pass[jn] : haloPass[jn - n];
      return pass[jn];
    };
    const auto omegaOf = [omega, haloW, n](std::int32_t jn) -> const Vec3& {
      if constexpr (kHalo) return jn < n ? omega[jn] : haloW[jn - n];
      return omega[jn];
    };
    kernels::PairBlock b{};  // per thread, ~23 KiB: stays in L1 through the three phases
    std::int32_t index[kernels::kBlockPairs];  // pair of each slot
    // one material (the paper's scenes): every pair has the same parameters, written into all the block's
    // slots once per pass (the friction may have changed since the last), not gathered per pair
    const bool oneMaterial = table.materialCount() == 1;
    if (oneMaterial) {
      const PairParams& pp = table(0, 0);
      std::fill_n(b.effYoung, kernels::kBlockPairs, pp.effYoung);
      std::fill_n(b.effShear, kernels::kBlockPairs, pp.effShear);
      std::fill_n(b.friction, kernels::kBlockPairs, pp.friction);
      std::fill_n(b.dampingRatio, kernels::kBlockPairs, pp.dampingRatio);
    }
    // the partners to prefetch: all of them when the state outgrows the caches (kLargeStateFrom), else those
    // outside this thread's own particles (another core drifted them; none with one thread)
    const bool all = arr.n >= kLargeStateFrom;
    const bool stream = all;  // result lines by streaming stores (kLargeStateFrom)
    const bool remote = !all && nt > 1;
    const bool own = nt == m_boundary.threads;
    const auto ownFrom = static_cast<std::uint32_t>(own ? m_boundary.begin[t] : staticBegin(t, nt, arr.n));
    const auto ownTo = static_cast<std::uint32_t>(own ? m_boundary.begin[t + 1] : staticBegin(t + 1, nt, arr.n));
    const std::uint32_t ownSpan = ownTo - ownFrom;
    const std::uint64_t* haloPairs = tb.haloPairs.data();  // exchange: the pairs that read a halo slot
    const std::uint32_t* haloNeed = tb.haloNeed.data();
    ThreadRuns runs(m_ranges, t, nt, nchunks);  // the chunks this thread computes, run by run
    // Its own share's runs, then (StealingRanges::nextOwn) the seeds this thread owes: the leading adjacency
    // entries of other threads' particles that its share of the chunks holds, summed as soon as the whole share
    // is computed (with the runs another thread took from it: waitForTakers) and before it takes runs of another
    // share, so the other threads go on meanwhile (after a barrier, the other thread waited for them); then runs
    // taken from the share before it, each reported done when the next is claimed.
    bool taking = false;
    std::size_t takenItems = 0;
    const auto nextRun = [&](std::size_t& runBegin, std::size_t& runEnd) {
      if (takenItems != 0) runs.doneTaken(takenItems);
      takenItems = 0;
      if (!taking) {
        if (runs.nextOwn(runBegin, runEnd)) {
          chunksDone += runEnd - runBegin;
          return true;
        }
        taking = true;
        if (exchange) {
          runs.waitForTakers();
          const std::int32_t* seedEntry = tb.seedEntry.data();
          const std::int32_t* seedEntryBegin = tb.seedEntryBegin.data();
          const std::int32_t eEnd = seedEntryBegin[tb.seedBegin[t + 1]];
          for (std::size_t q = tb.seedBegin[t]; q < tb.seedBegin[t + 1]; ++q) {
            const double ri = m_p.radius[tb.seedParticle[q]];  // not the pass copy: its owner's line
            double fx = 0.0, fy = 0.0, fz = 0.0, tx = 0.0, ty = 0.0, tz = 0.0;
            for (std::int32_t e = seedEntryBegin[q]; e < seedEntryBegin[q + 1]; ++e) {
              if (e + kSeedAhead < eEnd) __builtin_prefetch(arr.result + (seedEntry[e + kSeedAhead] >> 1));
              const std::int32_t entry = seedEntry[e];
              kickEntry(arr.result[entry >> 1], entry, ri, fx, fy, fz, tx, ty, tz);
            }
            seeds[q] = {fx, fy, fz, tx, ty, tz};
          }
        }
      }
      if (!runs.nextTaken(runBegin, runEnd)) return false;
      takenItems = runEnd - runBegin;
      chunksDone += takenItems;
      return true;
    };
    for (std::size_t runBegin, runEnd; nextRun(runBegin, runEnd);)
    for (std::size_t k = runBegin; k < runEnd; ++k) {
      // in a chunk of its own share the partners this thread did not drift are exactly the halo slots, which
      // their block's word lists; in a chunk taken from another share every partner is tested
      const bool haloOnly = exchange && !all && k >= tb.chunkBegin[t] && k < tb.chunkBegin[t + 1];
      if (exchange && !haloOnly) awaitHalo(std::numeric_limits<std::uint32_t>::max());  // any slot
      Chunk acc;
      kernels::BlockSums sums;
      const std::size_t chunkEnd = std::min(np, (k + 1) * kChunk);
      for (std::size_t p0 = k * kChunk; p0 < chunkEnd; p0 += kernels::kBlockPairs) {
        const std::size_t p1 = std::min(chunkEnd, p0 + kernels::kBlockPairs);
        // the next block's partners that are not in cache: the lines a later thread drifts (on this kind of VM
        // a line last written by the other core arrives 50-200 ns late, docs/performance.md). At 4000 spheres
        // (3 MB) prefetching every partner cost ~15 % of a 1-thread step. When the state outgrows the caches
        // (a whole sweep lies between a line's drift and its pass) every partner is prefetched in loop 1a
        // instead, kPartnerAhead pairs ahead, and the history lines kHistoryAhead pairs ahead, for writing.
        if (haloOnly) {
          awaitHalo(haloNeed[p0 / kernels::kBlockPairs]);  // this block's slots and the next one's
          if (p1 < np)
            for (std::uint64_t w = haloPairs[p1 / kernels::kBlockPairs]; w != 0; w &= w - 1) {
              const std::int32_t jn = partner[p1 + static_cast<std::size_t>(__builtin_ctzll(w))];
              __builtin_prefetch(&passOf(jn));
              __builtin_prefetch(&omegaOf(jn));
            }
        } else if (remote)
          for (std::size_t q = p1, qEnd = std::min(np, p1 + kernels::kBlockPairs); q < qEnd; ++q) {
            const std::int32_t jn = partner[q];
            if (static_cast<std::uint32_t>(jn) - ownFrom >= ownSpan) {  // a halo slot lies outside too
              __builtin_prefetch(&passOf(jn));
              __builtin_prefetch(&omegaOf(jn));
            }
          }
        // 1a. geometry of every listed pair: each is written to slot m, which advances only for a touching
        // pair, and marked in the block's word of touching pairs. No branch depends on the data (40 % of the
        // listed pairs do not touch: a branch on it was mispredicted about as often).
        int m = 0;
        std::uint64_t touchingNow = 0;
        for (std::size_t p = p0; p < p1; ++p) {
          if (all && (p & 1) == 0 && p + kHistoryAhead < np)  // a line holds two pairs' history
            __builtin_prefetch(&arr.hist[p + kHistoryAhead], 1);
          if (all && p + kPartnerAhead < np) {  // one pair's partner per pair, not a burst per block
            const std::int32_t ahead = partner[p + kPartnerAhead];
            __builtin_prefetch(&passOf(ahead));
            __builtin_prefetch(&omegaOf(ahead));
          }
          const int i = arr.first[p];
          const PassParticle& pj = passOf(partner[p]);
          Vec3 d = pj.x - pass[i].x;  // l = x_j + H image - x_i
          const Image img = arr.image[p];
          if (!img.isZero()) d += arr.cell.shift(img.vec());
          const double ri = pass[i].radius, rj = pj.radius;
          const double R = ri + rj;
          const double dist2 = d.squaredNorm();
          const int touching = dist2 < R * R;
          touchingNow |= static_cast<std::uint64_t>(touching) << (p - p0);
          index[m] = static_cast<std::int32_t>(p);
          b.dx[m] = d.x(), b.dy[m] = d.y(), b.dz[m] = d.z();
          b.dist2[m] = dist2;
          b.ri[m] = ri, b.rj[m] = rj;
          m += touching;
        }
        // 1b. the rest of the inputs, for the touching pairs only
        for (int s = 0; s < m; ++s) {
          const std::size_t p = static_cast<std::size_t>(index[s]);
          const int i = arr.first[p];
          const std::int32_t jn = partner[p];
          const PassParticle& pj = passOf(jn);
          const Vec3& wj = omegaOf(jn);
          // relative velocity of the centres, with the mean field L·d, which carries the image shift
          // velocity L·H·n for pairs across the boundary (verification ladder §2)
          Vec3 vr = pj.v - pass[i].v;
          if constexpr (kAffine) vr += arr.L * Vec3(b.dx[s], b.dy[s], b.dz[s]);
          const ContactHistory& h = arr.hist[p];
          b.vx[s] = vr.x(), b.vy[s] = vr.y(), b.vz[s] = vr.z();
          b.wix[s] = arr.w[i].x(), b.wiy[s] = arr.w[i].y(), b.wiz[s] = arr.w[i].z();
          b.wjx[s] = wj.x(), b.wjy[s] = wj.y(), b.wjz[s] = wj.z();
          if constexpr (kDamping) b.invMassSum[s] = pass[i].invMass + pj.invMass;  // m* of the damping
          if (!oneMaterial) {
            const PairParams& pp = table(arr.mat[i], arr.mat[arr.second[p]]);
            b.effYoung[s] = pp.effYoung, b.effShear[s] = pp.effShear;
            b.friction[s] = pp.friction, b.dampingRatio[s] = pp.dampingRatio;
          }
          b.tx[s] = h.tangentialForce.x(), b.ty[s] = h.tangentialForce.y(), b.tz[s] = h.tangentialForce.z();
          b.aPrev[s] = h.contactRadius;
        }
        // the contacts that opened (they touched at the last pass: a > 0 in their history, and their results
        // are only ever non-zero with it; a rebuild zeroes the results but carries the history): results and
        // history are zero (the kick gathers the zero force as is)
        std::uint64_t& touchedWord = touched[p0 / kernels::kBlockPairs];
        for (std::uint64_t opened = touchedWord & ~touchingNow; opened != 0; opened &= opened - 1) {
          const std::size_t p = p0 + static_cast<std::size_t>(__builtin_ctzll(opened));
          arr.result[p] = PairResult{};
          arr.hist[p] = ContactHistory{};
        }
        touchedWord = touchingNow;
        b.count = m;
        // 2. the law across the block
        kernels::hertzMindlinBlock<kDamping, kEnergy>(b, arr.dt);
        // 3. the block's sums (vectorised), and the scatter of results and history
        kernels::blockSums<kEnergy>(b, sums);
        for (int s = 0; s < m; ++s) {
          const std::size_t p = static_cast<std::size_t>(index[s]);
          arr.hist[p].tangentialForce = Vec3(b.tx[s], b.ty[s], b.tz[s]);
          arr.hist[p].contactRadius = b.aPrev[s];
          if (stream) {
            // the line in PairResult's order: force, moment, overlap, normal force
            const double line[8] = {b.fx[s], b.fy[s], b.fz[s], b.mx[s], b.my[s], b.mz[s], b.delta[s], b.fn[s]};
            streamLine(arr.result + p, line);
          } else {
            arr.result[p] = {Vec3(b.fx[s], b.fy[s], b.fz[s]), Vec3(b.mx[s], b.my[s], b.mz[s]), b.delta[s], b.fn[s]};
          }
        }
        acc.contacts += static_cast<std::size_t>(m);
      }
      acc.stress = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&sums.s[0][0]);
      acc.stiffness = Vec3(sums.k[0], sums.k[1], sums.k[2]);
      acc.sliding = static_cast<std::size_t>(sums.sliding);
      if constexpr (kEnergy) {
        acc.friction = sums.dissipatedT;
        acc.damping = sums.dampPower * arr.dt;
      }
      chunks[k] = acc;
    }
    if (stream) streamFence();  // the kick's threads read these lines after the region's barrier
    if (timed)
      balance.addPass(t, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), chunksDone);
  };
  m_team.each(m_num.threads, loop);
  m_seedsReady = kHalo && team == m_boundary.threads && m_boundary.exchange;
  m_profile.stolenRuns += static_cast<long>(m_ranges.stolen());
  // the diagnostics' extremes and means and the elastic energies are read off the stored contacts on demand
  reduceContactChunks<kEnergy, false>((m_c.size() + kChunk - 1) / kChunk);
}

template <bool kEnergy, bool kDamping, bool kAffine>
void Simulation::contactPassMindlinDeresiewicz() {
  // Per block of up to kBlockPairs listed pairs, all within one reduction chunk (so the bits do not depend on
  // the thread count): 1. the branch vector pair by pair, the touching pairs' inputs and history gathered into
  // a PairBlock and an MdBlock; 2. the normal contact (kernels::hertzNormalBlock, as the default law's) and
  // the tangential law (kernels::mindlinDeresiewiczBlock), vectorised across the block; 3. in pair order the
  // history and results scattered back (the pairs the law flags through the scalar kernel, from their
  // unchanged history), then the block's sums (kernels::blockSums, kernels::mdBlockMeasures), vectorised.
  m_c.touchedValid = false;  // this pass changes the history without ContactStore::touched
  m_seedsReady = false;      // nor does it sum the seeds: the kick reads every entry
  updateShares();
  m_ranges.reset(m_boundary.chunkBegin, 1);
  const auto loop = [this](const int t, const int nt) {
  // locals of each thread, which no store of the pass can alias (kickPass)
  const PassArrays arr(m_pass, m_p, m_c, m_cell, m_dt);
  const std::size_t np = arr.np, nchunks = arr.chunks(kChunk);
  const PassParticle* pass = arr.pp;
  const Mat3& L = arr.L;
  const double dt = arr.dt;
  MdHistory* mdHist = m_c.mdHistory.data();
  const PairTable& table = m_pairs;
  Chunk* chunks = m_chunks.data();
  kernels::PairBlock g{};  // per thread, ~23 + 15 KiB: the geometry and the law's state stay in L1
  kernels::MdBlock b{};
  std::int32_t index[kernels::kBlockPairs];  // pair of each slot
  ThreadRuns runs(m_ranges, t, nt, nchunks);
  for (std::size_t runBegin, runEnd; runs.next(runBegin, runEnd);)
  for (std::size_t k = runBegin; k < runEnd; ++k) {
    Chunk acc;
    const std::size_t end = std::min(np, (k + 1) * kChunk);
    for (std::size_t p0 = k * kChunk; p0 < end; p0 += kernels::kBlockPairs) {
      // 1. the touching pairs into the blocks
      int m = 0;
      for (std::size_t p = p0, p1 = std::min(end, p0 + kernels::kBlockPairs); p < p1; ++p) {
        const int i = arr.first[p], j = arr.second[p];
        const Vec3 d = arr.branch(p, i, j);
        const double ri = pass[i].radius, rj = pass[j].radius;
        const double R = ri + rj;
        const double dist2 = d.squaredNorm();
        if (dist2 >= R * R) {
          // not touching: results and history are zero (the kick gathers the zero force unconditionally)
          if (arr.hist[p].contactRadius != 0.0) {  // a touching pair always has a > 0 (see contactPassBlocked)
            arr.result[p] = PairResult{};
            arr.hist[p] = ContactHistory{};
            // the contact opened: its locked micro-slip energy is dissipated
            if constexpr (kEnergy) acc.friction += mdHist[p].locked;
            mdHist[p] = MdHistory{};
          }
          continue;
        }
        // v_j - v_i, with the mean field L·l, which carries the image shift velocity L·H·n for pairs across the
        // boundary (verification ladder §2); the spins' part is hertzNormalBlock's
        Vec3 v = pass[j].v - pass[i].v;
        if constexpr (kAffine) v += L * d;
        const Vec3& wi = arr.w[i];
        const Vec3& wj = arr.w[j];
        const PairParams& pp = table(arr.mat[i], arr.mat[j]);
        g.dx[m] = d.x(), g.dy[m] = d.y(), g.dz[m] = d.z();
        g.dist2[m] = dist2;
        g.ri[m] = ri, g.rj[m] = rj;
        g.vx[m] = v.x(), g.vy[m] = v.y(), g.vz[m] = v.z();
        g.wix[m] = wi.x(), g.wiy[m] = wi.y(), g.wiz[m] = wi.z();
        g.wjx[m] = wj.x(), g.wjy[m] = wj.y(), g.wjz[m] = wj.z();
        g.invMassSum[m] = pass[i].invMass + pass[j].invMass;
        g.effYoung[m] = pp.effYoung;
        g.dampingRatio[m] = pp.dampingRatio;
        b.effShear[m] = pp.effShear;
        b.friction[m] = pp.friction;
        kernels::mdGatherHistory(b, m, arr.hist[p], mdHist[p]);
        index[m] = static_cast<std::int32_t>(p);
        ++m;
      }
      if (m == 0) continue;
      // 2. the normal contact and the tangential law across the block
      g.count = b.count = m;
      kernels::hertzNormalBlock<kDamping>(g);
      kernels::mdTakeGeometry(b, g.nx, g.ny, g.nz, g.vtx, g.vty, g.vtz, g.a, g.fn);
      kernels::mindlinDeresiewiczBlock(b, dt);
      // 3. in pair order: history (the scalar kernel where the block flagged a pair) and results
      for (int s = 0; s < m; ++s) {
        const std::size_t p = static_cast<std::size_t>(index[s]);
        const kernels::MdSlotResult tr = kernels::mdScatter(b, s, dt, arr.hist[p], mdHist[p]);
        const Vec3 n(g.nx[s], g.ny[s], g.nz[s]);
        Vec3 ft = tr.force;
        if constexpr (kDamping) {
          if (!tr.sliding) {
            const Vec3 vt(g.vtx[s], g.vty[s], g.vtz[s]);
            const double kt = kernels::mindlinStiffness(b.effShear[s], g.a[s]);
            const Vec3 fd = -kernels::dampingCoefficient(g.dampingRatio[s], kt, g.reducedMass[s]) * vt;
            ft += fd;
            g.dampPower[s] -= fd.dot(vt);
          }
        } else {
          g.dampPower[s] = 0.0;  // blockSums adds it with kEnergy
        }
        const Vec3 f = g.fn[s] * n + ft;
        arr.result[p] = {f, n.cross(f), g.delta[s], g.fn[s]};
        g.fx[s] = f.x(), g.fy[s] = f.y(), g.fz[s] = f.z();
        g.sliding[s] = tr.sliding ? 1.0 : 0.0;
        g.dissipatedT[s] = tr.dissipated;
        b.storedEnergy[s] = tr.storedEnergy;  // the scalar kernel's where it ran
      }
      // the block's sums: those of the default law (stress, stiffness, sliding, dissipation) and the measures
      kernels::BlockSums sums;
      kernels::blockSums<kEnergy>(g, sums);
      kernels::MdBlockMeasures measures;
      kernels::mdBlockMeasures<kEnergy>(g, b, measures);
      acc.stress += Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&sums.s[0][0]);
      acc.stiffness += Vec3(sums.k[0], sums.k[1], sums.k[2]);
      acc.contacts += static_cast<std::size_t>(m);
      acc.sliding += static_cast<std::size_t>(sums.sliding);
      acc.sumForce += measures.sumForce;
      acc.maxOverlapRatio = std::max(acc.maxOverlapRatio, measures.maxOverlapRatio);
      acc.maxKOverM = std::max(acc.maxKOverM, measures.maxKOverM);
      if constexpr (kEnergy) {
        acc.elasticN += measures.elasticN;
        acc.elasticT += measures.elasticT;
        acc.friction += sums.dissipatedT;
        acc.damping += sums.dampPower * dt;
      }
    }
    chunks[k] = acc;
  }
  };
  m_team.each(m_num.threads, loop);
  m_profile.stolenRuns += static_cast<long>(m_ranges.stolen());
  reduceContactChunks<kEnergy, true>((m_c.size() + kChunk - 1) / kChunk);
}

template <bool kEnergy, bool kMeasured>
void Simulation::reduceContactChunks(std::size_t nchunks) {
  Mat3 s = Mat3::Zero();
  double eN = 0.0, eT = 0.0, fr = 0.0, dm = 0.0, sf = 0.0, mo = 0.0, mk = 0.0;
  Vec3 stiff = Vec3::Zero();
  std::size_t nc = 0, ns = 0;
  for (std::size_t k = 0; k < nchunks; ++k) {
    const Chunk& a = m_chunks[k];
    s += a.stress;
    stiff += a.stiffness;
    nc += a.contacts;
    ns += a.sliding;
    if constexpr (kEnergy) {
      fr += a.friction;
      dm += a.damping;
    }
    if constexpr (kMeasured) {
      eN += a.elasticN;
      eT += a.elasticT;
      sf += a.sumForce;
      mo = std::max(mo, a.maxOverlapRatio);
      mk = std::max(mk, a.maxKOverM);
    }
  }
  m_stressPrev = m_stress;
  m_stress = s / m_cell.volume();
  if constexpr (kEnergy) {
    m_energy.frictionWork += fr;
    m_energy.contactDampingWork += dm;
  }
  m_diag.contacts = nc;
  m_diag.sliding = ns;
  m_diag.axisStiffness = stiff / m_cell.volume();
  m_contactsMeasured = kMeasured;
  if constexpr (kMeasured) {
    m_diag.meanContactForce = nc ? sf / static_cast<double>(nc) : 0.0;
    m_diag.maxOverlapRatio = mo;
    m_diag.maxStiffnessOverMass = mk;
    if constexpr (kEnergy) {
      m_elasticNormal = eN;
      m_elasticTangential = eT;
    }
  }
}

void Simulation::measureContacts() const {
  if (m_contactsMeasured) return;
  // The default law's pass leaves these to be read off the stored contacts: the same formulas as the law
  // (contact_kernels.hpp), from the overlap, force and history of each touching pair after the last pass.
  // Serial, in pair order: the same bits for any thread count.
  double sumForce = 0.0, maxOverlap = 0.0, maxKOverM = 0.0, elasticN = 0.0, elasticT = 0.0;
  const ContactStore& c = m_c;
  for (std::size_t p = 0; p < c.size(); ++p) {
    const PairResult& q = c.result[p];
    if (!(q.overlap > 0.0)) continue;
    const int i = c.first[p], j = c.second[p];
    const PairParams& pp = m_pairs(m_p.material[i], m_p.material[j]);
    const double a = c.history[p].contactRadius;  // of this step
    const double kn = kernels::hertzStiffness(pp.effYoung, a), kt = kernels::mindlinStiffness(pp.effShear, a);
    sumForce += q.force.norm();
    maxOverlap = std::max(maxOverlap, q.overlap / std::min(m_p.radius[i], m_p.radius[j]));
    maxKOverM = std::max(maxKOverM, std::max(kn, 3.5 * kt) * (m_p.invMass[i] + m_p.invMass[j]));
    elasticN += kernels::hertzEnergy(kernels::hertzForce(pp.effYoung, a, q.overlap), q.overlap);
    if (kt > 0.0) elasticT += c.history[p].tangentialForce.squaredNorm() * (0.5 / kt);
  }
  const std::size_t nc = m_diag.contacts;
  m_diag.meanContactForce = nc ? sumForce / static_cast<double>(nc) : 0.0;
  m_diag.maxOverlapRatio = maxOverlap;
  m_diag.maxStiffnessOverMass = maxKOverM;
  m_elasticNormal = elasticN;
  m_elasticTangential = elasticT;
  m_contactsMeasured = true;
}

}  // namespace fl
