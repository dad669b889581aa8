// Spatial (Morton / Z-order) ordering of a packing's particles, for cache locality: neighbours in space
// become neighbours in memory, so a contact pair's two particles, and the pair data the kick gathers, mostly
// sit in the same cache lines and, with OpenMP's static split, in the same thread's half of the arrays
// (issue 6: "spatial sorting of particles", "threads that share no cache lines"). LAMMPS does the same by
// default (atom_modify sort). Applied to a packing before a Simulation is built from it, so particle
// indices stay fixed during a run; each particle keeps its `id`.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "particle_store.hpp"
#include "periodic_cell.hpp"

namespace fl {

// 30-bit Morton code of reduced coordinates s in [0, 1)^3 (10 bits per axis; s is wrapped first).
std::uint32_t mortonCode(const Vec3& reduced);

// Permutation that sorts the particles by the Morton code of their reduced positions (ties by index, so
// the order is deterministic): order[k] is the old index of the particle placed at k.
std::vector<std::size_t> mortonOrder(const ParticleStore& particles, const PeriodicCell& cell);

// Rearranges every per-particle array (hot and cold, ids included) so new index k holds old order[k].
// Throws InputError unless order is a permutation of 0..n-1.
void reorderParticles(ParticleStore& particles, const std::vector<std::size_t>& order);

// mortonOrder then reorderParticles.
void sortSpatially(ParticleStore& particles, const PeriodicCell& cell);

}  // namespace fl
