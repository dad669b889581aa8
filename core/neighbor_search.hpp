// Neighbour search for the periodic cell: a cell grid in reduced coordinates (O(N)), and a brute-force
// all-pairs, all-27-images reference used by tests and by cells too small for a 3x3x3 grid.
// A pair is listed when |x_j + H·n - x_i| < r_i + r_j + skin. Each (i, j) appears once, i < j, with the
// unique image n that brings j within the cut-off; that uniqueness needs every perpendicular cell width
// > 2·(2 r_max + skin), else CellTooSmallError (for a strongly sheared triclinic cell the brute force's
// 27 images may not contain the nearest one: the grid path is used whenever it fits).
#pragma once

#include <cstdint>
#include <vector>

#include "contact_store.hpp"
#include "periodic_cell.hpp"
#include "particle_store.hpp"

namespace fl {

class ThreadTeam;

struct PairList {  // in the contact store's arrays (huge_pages.hpp), moved there whole
  HugeVector<std::int32_t> first, second;
  HugeVector<Image> image;
};

// What the grid search keeps between calls, so that a rebuild touches no fresh memory: on the VMs we measure on,
// a fresh page costs ~1.6 ms a MB the first time it is written (docs/performance.md, fortieth session). Held by
// the simulation for its whole life; the arrays only grow.
struct GridScratch {
  HugeVector<std::int32_t> binOf;     // each particle's bin
  HugeVector<std::int32_t> binStart;  // bin b holds binItem[binStart[b] .. binStart[b+1])
  HugeVector<std::int32_t> binItem;   // the particles, bin after bin
  std::vector<PairList> threadPairs;  // the pairs of threads 1, 2, ...; thread 0 writes into the output
  std::size_t bytes() const;          // capacity, for Simulation::memoryBytes
};

// Positions must be wrapped into the cell. Output pairs are sorted by (i, j), the same for any thread count.
// `team`: the held team of a run (thread_team.hpp), else `threads` threads are forked. The second form writes
// into `out`, whose arrays keep their capacity, and reuses `scratch`.
PairList findPairsGrid(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads,
                       ThreadTeam* team = nullptr);
void findPairsGrid(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads, ThreadTeam* team,
                   GridScratch& scratch, PairList& out);
PairList findPairsBruteForce(const ParticleStore& p, const PeriodicCell& cell, double skin);
// Chooses the grid when the cell holds at least 3 bins per direction, else brute force.
PairList findPairs(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads,
                   ThreadTeam* team = nullptr);
void findPairs(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads, ThreadTeam* team,
               GridScratch& scratch, PairList& out);
// Throws CellTooSmallError when the cell cannot hold the interaction range unambiguously.
void checkCellSize(const PeriodicCell& cell, double cutoff);

}  // namespace fl
