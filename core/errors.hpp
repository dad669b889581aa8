// Typed errors. One base (fl::Error); user mistakes are found at setup (scene validation),
// never thrown from inside a parallel region: kernels flag, the step reports after the region.
#pragma once

#include <stdexcept>
#include <string>

namespace fl {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A scene/parameter value outside its allowed range; the message names file, field and range.
class InputError : public Error {
 public:
  using Error::Error;
};

// The periodic cell became too small for the largest particle plus the neighbour skin.
class CellTooSmallError : public Error {
 public:
  using Error::Error;
};

// The integration blew up (NaN/Inf, runaway overlap or kinetic energy); says the cause and a fix.
class InstabilityError : public Error {
 public:
  using Error::Error;
};

// A file could not be read or written (checkpoint, packing, output).
class IoError : public Error {
 public:
  using Error::Error;
};

}  // namespace fl
