// fabriclab-run: the core-only headless command (no Qt, no VTK), for cluster nodes and batch studies.
#include "headless.hpp"

int main(int argc, char** argv) { return fl::app::runHeadless(argc, argv); }
