// The headless runner shared by `fabriclab-run` (core-only build) and `fabriclab --headless`.
// It never touches Qt, so it works with no display.
#pragma once

namespace fl::app {

// argv[1..]: see usage() in headless.cpp. Returns the process exit code.
int runHeadless(int argc, char** argv);

}  // namespace fl::app
