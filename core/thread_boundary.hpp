// What crosses between the threads' shares of one step (issue 6: the 2-thread speed-up; docs/performance.md,
// ninth and nineteenth sessions). The particles are split where the contact pass's split of the pair chunks
// (equal, or at edges from the threads' measured costs: share_balance.hpp) puts each thread's first pair, so a
// thread drifts and kicks the particles whose pairs it computes as first particle. These are the shares each
// thread starts from; the loops then balance as they go
// (work_stealing.hpp), and a run taken from another share reads its lines in place.
// What still crosses goes through two compact arrays instead of the owners' own lines:
//  - halo: the partners another thread's pass reads (x, r, v, 1/m and omega after the drift), copied by their
//    owner into dense slots at the start of the pass; the owner's particle lines are then never shared, so
//    its drift and kick write them without waiting for the other core to give them up. The owner writes the
//    slots by streaming stores (a plain store waits for each line the readers hold since the last pass: at
//    4000 spheres the copy took ~23 µs a step with the vCPUs far apart, ~3.5 µs so) and publishes its progress
//    as it copies, in the order the readers first need the slots (haloNeed); a reader waits only for the
//    slots of its next blocks, not at a barrier for the whole copy;
//  - seeds: when a particle's first adjacency entries are pairs that one other thread computed, that thread
//    sums them after its pass, in the kick's order and with the kick's operations (kickEntry), into a seed;
//    the owner's kick starts from the seed and reads the rest itself (at 4000 spheres ~500 seeds against
//    ~1300 result lines the other core wrote). The thread that owes a seed sums it once its own share of the
//    pass is done, runs another thread took from it included (StealingRanges::waitForTakers), before it takes
//    runs of another share; the kick walks the list of seeded particles (seeded) beside its own.
// On hosts that put the two vCPUs on far cores (~170 ns a line) this made 2 threads 1.34-1.36x faster than the
// shared lines read in place under work stealing (1.4-1.5x with a static split); near (~30 ns) it is level.
// Halo slots are copies and seeds are the kick's own partial sums, so the bits do not depend on the split.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "contact_store.hpp"
#include "work_stealing.hpp"  // staticBegin

namespace fl {

struct ThreadBoundary {
  int threads = 0;        // 0: not built
  bool exchange = false;  // halo and seeds in use: more than one thread, and a pair chunk for each
  std::vector<std::size_t> begin;       // particle shares [begin[t], begin[t+1]), threads + 1 entries
  std::vector<std::size_t> chunkBegin;  // the pass's shares of the pair chunks, threads + 1 entries
  // per pair: the second particle, or particleCount + its halo slot when another thread owns it
  std::vector<std::int32_t> partner;
  // particle of each halo slot, grouped by owner and within a group in the order of the pairs that first read it
  std::vector<std::int32_t> halo;
  std::vector<std::size_t> haloBegin;    // slots thread t fills: [haloBegin[t], haloBegin[t+1])
  std::vector<std::int32_t> seedParticle;  // particle of seed slot s >= 1 (slot 0 is the zero seed)
  std::vector<std::size_t> seedBegin;    // seed slots thread t sums: [seedBegin[t], seedBegin[t+1])
  std::vector<std::int32_t> seedOf;      // per particle: its seed slot, 0 for none
  std::vector<std::int32_t> kickBegin;   // per particle: the first adjacency entry its own kick reads
  // the leading entries each seed sums, slot s's in [seedEntryBegin[s], seedEntryBegin[s + 1]) (slot 0: none), a
  // copy of the adjacency's in the slots' order: the sum walks one run and prefetches the result lines ahead. Read
  // through seedParticle, adjStart and kickBegin, each seed's first line waited for its chain of loads: the seeds
  // took thread 0 6.5-6.9 us of a ~138 us step at 4000 spheres, with this run 3.9-4.2 (forty-second session)
  std::vector<std::int32_t> seedEntry;
  std::vector<std::int32_t> seedEntryBegin;
  // the particles that have a seed, ascending, and a last entry past every particle index: the kick walks it
  // beside its particles and reads seedOf and kickBegin only where they match, so the ~90 % of particles
  // without a seed cost it one comparison (reading both per particle made the kick ~10 % slower)
  std::vector<std::int32_t> seeded;
  // per block of kHaloBlock pairs: bit b set when pair (block * kHaloBlock + b) reads its partner from a halo
  // slot. The pass prefetches the next block's halo slots from it instead of testing every partner of it.
  std::vector<std::uint64_t> haloPairs;
  // per block: how many leading slots of its owner's group a reader needs before it computes the block and
  // prefetches the next (the largest place in a group that the pairs of both blocks read, plus one; taken over
  // all owners, so with more than one owner it may ask for more than it reads, never less)
  std::vector<std::uint32_t> haloNeed;
  static constexpr std::size_t kHaloBlock = 64;
};

// The kick's partial sum over a particle's first adjacency entries: force and torque.
struct KickSeed {
  double fx = 0.0, fy = 0.0, fz = 0.0, tx = 0.0, ty = 0.0, tz = 0.0;
};

// the sign of a pair's force on its first (side 0) and second (side 1) particle: a load, where computing it
// from the side bit took four operations of the kick's ~20 an entry
inline constexpr double kSideSign[2] = {-1.0, 1.0};

// One adjacency entry (pair << 1 | side) of a particle of radius ri added to its force and torque sums: the
// kick's operation, shared with the seeds so both give the same bits. Side 1 (second particle) receives +f,
// side 0 -f; the torque is -(r_self - delta/2) n x f on both (contact point on the pair axis). g++ contracts
// these multiply-adds (-ffp-contract=fast), which can differ between code paths (docs/performance.md, eighth
// session): this one function is inlined into both, and tests/determinism_test.cpp compares the bits of 1 to
// 4 threads. Written as explicit std::fma, with the same bits, it made the 1-thread kick 10 % slower.
inline void kickEntry(const PairResult& c, std::int32_t entry, double ri, double& fx, double& fy, double& fz,
                      double& tx, double& ty, double& tz) {
  const double sign = kSideSign[entry & 1];
  const double arm = ri - 0.5 * c.overlap;
  tx -= arm * c.moment.x();
  ty -= arm * c.moment.y();
  tz -= arm * c.moment.z();
  fx += sign * c.force.x();
  fy += sign * c.force.y();
  fz += sign * c.force.z();
}

// The boundary of `threads` shares for the store's pairs (sorted by first particle, adjacency built) over
// `particleCount` particles, with the pass splitting ceil(pairs / chunk) chunks statically, or at `edges` when
// given (threads + 1 ascending chunk indices, the last the chunk count: share_balance.hpp). With one thread,
// or fewer chunks than threads, the shares are the static split of the particles and nothing is exchanged
// (exchange false: the per-pair and per-particle arrays are left empty).
// halo: false gives the shares alone (exchange false), for states that outgrow the caches, where the lines
// crossing the shares' seam are a small part of what every step streams from memory (at 256 000 spheres the
// halo and seeds made 2 threads 1-6 % slower: docs/performance.md, nineteenth session).
ThreadBoundary buildThreadBoundary(const ContactStore& c, std::size_t particleCount, int threads,
                                   std::size_t chunk, bool halo = true, const std::vector<std::size_t>& edges = {});

}  // namespace fl
