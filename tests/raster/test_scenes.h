// tests/raster/test_scenes.h: forwards to the shared kit (tests/kit/) under the old name
// raster::test, for the files that other work still has open and that include it here
// (tests/raster/moment_maps_test.cpp, tests/studies/path_test.cpp, path_shard_test.cpp). New code
// includes tests/kit/test_scenes.h and tests/kit/render_checked.h; this file goes once those do.
#pragma once

#include "tests/kit/render_checked.h"
#include "tests/kit/test_scenes.h"

namespace shadowlab::raster::test {
using namespace shadowlab::test;
}  // namespace shadowlab::raster::test
