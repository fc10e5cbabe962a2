// tests/scene/backend_test.cpp: the backends' names parse back to the Backend they print.
#include "scene/backend.h"

#include <set>
#include <string>

#include <gtest/gtest.h>

namespace shadowlab::scene {
namespace {

TEST(BackendNames, AreTheThreeOfTheCommandLineAndEachParsesBackToItsBackend) {
    // DESIGN.md's command line: --backend raster|raytrace|reference.
    std::set<std::string> names;
    for (const Backend b : kBackends) {
        names.insert(toString(b));
        EXPECT_EQ(parseBackend(toString(b)), b) << toString(b);
    }
    EXPECT_EQ(names, (std::set<std::string>{"raster", "raytrace", "reference"}));
}

TEST(BackendNames, AnyOtherTextIsNoBackend) {
    for (const char* text : {"", "Raster", "raster ", "ray", "references", "?"})
        EXPECT_FALSE(parseBackend(text).has_value()) << "'" << text << "'";
}

}  // namespace
}  // namespace shadowlab::scene
