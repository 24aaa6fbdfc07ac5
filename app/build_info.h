// The git commit this binary was built from (cmake/build_info.cmake, refreshed on every build):
// "abcdef012345", "abcdef012345+dirty" when tracked files had uncommitted changes, or "unknown".
// Benchmark outputs record it beside the device and the command line.
#pragma once

namespace nbvh::app {

const char* build_commit();

} // namespace nbvh::app
