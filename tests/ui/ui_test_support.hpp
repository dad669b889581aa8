// Shared helpers of the GUI tests: a tiny scene (fast enough for a unit test) and an event-loop wait.
#pragma once

#include <QCoreApplication>
#include <QElapsedTimer>
#include <QThread>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace fl::ui::test {

// ~200 particles: a gas, then isotropic compression (and a short cyclic stage when asked), sampled often.
inline std::string tinySceneJson(bool withCycles = false, int count = 200) {
  std::string s = R"({
  "name": "tiny test scene",
  "specimen": {"source": "gas", "count": )" + std::to_string(count) + R"(, "solid_fraction": 0.3, "seed": 7},
  "numerics": {"time_step_factor": 0.3, "local_damping": 0.1, "density_scale": 100, "threads": 1},
  "servo": {"max_strain_rate": 10, "max_inertial_number": 1e-2, "unbalanced_tolerance": 1e-2},
  "stages": [
    {"type": "isotropic_compression", "name": "compress", "pressure": 100e3, "friction": 0.1,
     "friction_after": 0.235})";
  if (withCycles)
    s += R"(,
    {"type": "cyclic", "name": "cycles", "drainage": "undrained", "amplitude": 5e-4, "cycles": 2,
     "inertial_number": 1e-3, "samples_per_cycle": 20})";
  s += R"(
  ],
  "output": {"sample_interval": 50, "checkpoint_at_stage_end": false}
})";
  return s;
}

inline std::string writeFile(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / ("fabriclab_ui_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

inline bool waitUntil(const std::function<bool()>& condition, int timeoutMs = 20000) {
  QElapsedTimer timer;
  timer.start();
  while (!condition()) {
    if (timer.elapsed() > timeoutMs) return false;
    QCoreApplication::processEvents(QEventLoop::AllEvents, 20);
    QThread::msleep(2);
  }
  return true;
}

}  // namespace fl::ui::test
