// Neighbour search for the periodic cell: a cell grid in reduced coordinates (O(N)), and a brute-force
// all-pairs, all-27-images reference used by tests and by cells too small for a 3x3x3 grid.
// A pair is listed when |x_j + H·n - x_i| < r_i + r_j + skin. Each (i, j) appears once, i < j, with the
// unique image n that brings j within the cut-off; that uniqueness needs every perpendicular cell width
// > 2·(2 r_max + skin), else CellTooSmallError (for a strongly sheared triclinic cell the brute force's
// 27 images may not contain the nearest one: the grid path is used whenever it fits).
#pragma once

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

// Positions must be wrapped into the cell. Output pairs are sorted by (i, j). `team`: the held team of a run
// (thread_team.hpp), else `threads` threads are forked.
PairList findPairsGrid(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads,
                       ThreadTeam* team = nullptr);
PairList findPairsBruteForce(const ParticleStore& p, const PeriodicCell& cell, double skin);
// Chooses the grid when the cell holds at least 3 bins per direction, else brute force.
PairList findPairs(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads,
                   ThreadTeam* team = nullptr);
// Throws CellTooSmallError when the cell cannot hold the interaction range unambiguously.
void checkCellSize(const PeriodicCell& cell, double cutoff);

}  // namespace fl
