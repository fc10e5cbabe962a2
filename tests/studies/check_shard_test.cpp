// tests/studies/check_shard_test.cpp: the split of `check --shard K/N`: every case in exactly one
// shard, round-robin over the sorted case names, whatever order the suite file lists them in.
#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "studies/check.h"

namespace shadowlab::compare {
namespace {

CheckSuite suiteOf(const std::vector<std::string>& names) {
    CheckSuite s;
    s.name = "t";
    for (const std::string& n : names) {
        CheckCase c;
        c.name = n;
        s.cases.push_back(c);
    }
    return s;
}

TEST(CheckShard, EveryCaseInExactlyOneShardForOneToEightShardsAndMoreShardsThanCases) {
    // Listed out of order on purpose: the split follows the sorted names.
    const std::vector<std::string> names = {"raster-b", "acne", "zeta", "raster-a", "mid"};
    const std::vector<std::string> sorted = {"acne", "mid", "raster-a", "raster-b", "zeta"};
    const CheckSuite suite = suiteOf(names);
    for (int n = 1; n <= 8; ++n) {
        std::map<std::string, int> seen;
        std::size_t smallest = names.size(), largest = 0;
        for (int k = 0; k < n; ++k) {
            const CheckSuite s = shardSuite(suite, {k, n});
            smallest = std::min(smallest, s.cases.size());
            largest = std::max(largest, s.cases.size());
            // In the suite's file order within the shard.
            std::size_t last = 0;
            for (const CheckCase& c : s.cases) {
                ++seen[c.name];
                const std::size_t at = std::find(names.begin(), names.end(), c.name) - names.begin();
                EXPECT_GE(at, last) << c.name;
                last = at;
                // Round-robin: the r-th name in sorted order goes to shard r mod N.
                const std::size_t rank = std::find(sorted.begin(), sorted.end(), c.name) - sorted.begin();
                EXPECT_EQ(int(rank % std::size_t(n)), k) << c.name << " N=" << n;
            }
        }
        ASSERT_EQ(seen.size(), names.size()) << "N=" << n;
        for (const auto& [name, times] : seen) EXPECT_EQ(times, 1) << name << " N=" << n;
        EXPECT_LE(largest - smallest, 1u) << "N=" << n;
        if (n > int(names.size())) {
            EXPECT_EQ(smallest, 0u);  // more shards than cases: some are empty
        }
    }
}

TEST(CheckShard, TheSplitDoesNotDependOnTheFileOrder) {
    const CheckSuite a = suiteOf({"c", "a", "d", "b"});
    const CheckSuite b = suiteOf({"d", "b", "a", "c"});
    for (int k = 0; k < 3; ++k) {
        std::vector<std::string> x, y;
        for (const CheckCase& c : shardSuite(a, {k, 3}).cases) x.push_back(c.name);
        for (const CheckCase& c : shardSuite(b, {k, 3}).cases) y.push_back(c.name);
        std::sort(x.begin(), x.end());
        std::sort(y.begin(), y.end());
        EXPECT_EQ(x, y) << "shard " << k;
    }
    // Sorted a, b, c, d: shard 0 of 3 holds a and d.
    std::vector<std::string> zero;
    for (const CheckCase& c : shardSuite(a, {0, 3}).cases) zero.push_back(c.name);
    EXPECT_EQ(zero, (std::vector<std::string>{"a", "d"}));
}

}  // namespace
}  // namespace shadowlab::compare
