#include "ui/snapshot.hpp"

#include <cmath>

namespace fl::ui {

const char* runStateName(RunState s) {
  switch (s) {
    case RunState::Empty: return "no scene";
    case RunState::Ready: return "ready";
    case RunState::Running: return "running";
    case RunState::Paused: return "paused";
    case RunState::Finished: return "finished";
    case RunState::Error: return "error";
  }
  return "?";
}

double Snapshot::meanNormalForce() const {
  if (contacts.empty()) return 0.0;
  double sum = 0.0;
  for (const auto& c : contacts) sum += c.normalForce;
  return sum / static_cast<double>(contacts.size());
}

std::vector<Vec3> Snapshot::contactNormals() const {
  std::vector<Vec3> n;
  n.reserve(contacts.size());
  for (const auto& c : contacts) {
    const double len = c.branch.norm();
    if (len > 0) n.push_back(c.branch / len);
  }
  return n;
}

std::vector<double> Snapshot::contactForces() const {
  std::vector<double> f;
  f.reserve(contacts.size());
  for (const auto& c : contacts)
    if (c.branch.squaredNorm() > 0) f.push_back(c.normalForce);
  return f;
}

void fillParticles(const Simulation& sim, Snapshot& out) {
  const ParticleStore& p = sim.particles();
  const ContactStore& c = sim.contacts();
  const PeriodicCell& cell = sim.cell();
  const std::size_t n = p.size();
  out.cell = cell.matrix();
  out.positions.resize(n);
  out.radii.assign(p.radius.begin(), p.radius.end());
  out.speeds.resize(n);
  out.contactCounts.assign(n, 0);
  out.meanStress.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    // Positions are wrapped only at neighbour rebuilds; wrap a copy so the picture stays in the box.
    Vec3 x = p.pos[i];
    cell.wrap(x);
    out.positions[i] = x;
    out.speeds[i] = p.vel[i].norm();
  }
  out.contacts.clear();
  // The result array may be shorter than the pair list right after a rebuild; read what is there.
  const std::size_t pairs = std::min(c.size(), c.result.size());
  out.contacts.reserve(pairs / 2);
  for (std::size_t k = 0; k < pairs; ++k) {
    if (!c.active(k)) continue;
    const auto i = c.first[k], j = c.second[k];
    ContactSegment s;
    s.first = i;
    s.second = j;
    s.start = out.positions[static_cast<std::size_t>(i)];
    s.branch = c.branch(k, p, cell);
    s.normalForce = c.result[k].normalForce;
    out.contacts.push_back(s);
    ++out.contactCounts[static_cast<std::size_t>(i)];
    ++out.contactCounts[static_cast<std::size_t>(j)];
    // trace of f (x) r_c for each side: F_n times the lever arm (r - delta/2), compression positive
    const double half = 0.5 * c.result[k].overlap;
    const double fn = c.result[k].normalForce;
    out.meanStress[static_cast<std::size_t>(i)] += fn * (p.radius[static_cast<std::size_t>(i)] - half);
    out.meanStress[static_cast<std::size_t>(j)] += fn * (p.radius[static_cast<std::size_t>(j)] - half);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double r = p.radius[i];
    const double volume = 4.0 / 3.0 * kPi * r * r * r;
    out.meanStress[i] = volume > 0 ? out.meanStress[i] / (3.0 * volume) : 0.0;
  }
}

Snapshot makeSnapshot(Runner& runner, const RunStatus& status, const Snapshot* previous) {
  Snapshot s;
  s.status = status;
  s.serial = previous ? previous->serial + 1 : 1;
  fillParticles(runner.simulation(), s);
  s.current = runner.measure();
  s.hasCurrent = true;
  // Share the time series with the previous snapshot while they have not grown (the runner only
  // appends), so publishing 30 times a second does not copy thousands of samples each time.
  const auto& samples = runner.samples();
  if (previous && previous->samples && previous->samples->size() == samples.size())
    s.samples = previous->samples;
  else
    s.samples = std::make_shared<const std::vector<Sample>>(samples);
  const auto& cycles = runner.cycles();
  if (previous && previous->cycles && previous->cycles->size() == cycles.size())
    s.cycles = previous->cycles;
  else
    s.cycles = std::make_shared<const std::vector<CycleRecord>>(cycles);
  s.summaries = runner.summaries();
  s.stages = runner.scene().stages;
  return s;
}

}  // namespace fl::ui
