// tests/studies/check_shard_test.cpp: the split of `check --shard K/N`: every case in exactly one
// shard, round-robin over the sorted case names, whatever order the suite file lists them in;
// and summary.html, the page of the parts every shard keeps.
#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "studies/check.h"
#include "studies/check_report.h"

namespace shadowlab::studies {
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

TEST(CheckSummaryHtml, OneRowPerCaseWithItsVerdictReasonsAndOnlyTheNamedDifferenceImages) {
    CasePart pass{
        "a.pass",
        CaseVerdict::Passed,
        0.1,
        "",
        "| a.pass | seed | raster | passed | 0% | 0% | 0% | 0% | 1.000 | 0.0000 | within tolerance | 100 ms |\n",
        ""};
    CasePart fail{"b<fail>",
                  CaseVerdict::Failed,
                  0.2,
                  "",
                  "| b<fail> | seed | raytrace | **FAILED** | 6.7% | 6.7% | 0% | 6.7% | 0.279 | 0.0673 | no baseline | "
                  "0.3 ms |\n",
                  "- `b<fail>`: budget --max-false-shadow: 6.7% > limit 0px: BROKEN (cases/b<fail>-diff.png)\n"};
    CasePart error{"c.error",
                   CaseVerdict::Error,
                   0.0,
                   "",
                   "| c.error | seed | raster | **ERROR** | | | | | | | no device | |\n",
                   "- `c.error`: error: no device\n"};
    const std::string h = htmlSummary("t", {pass, fail, error}, false, {"b<fail>"});
    auto count = [&](const std::string& what) {
        std::size_t n = 0;
        for (auto p = h.find(what); p != std::string::npos; p = h.find(what, p + 1)) ++n;
        return n;
    };
    EXPECT_EQ(h.rfind("<!doctype html>", 0), 0u);
    EXPECT_NE(h.find("1 passed, 1 failed, 1 errors."), std::string::npos) << h;
    EXPECT_EQ(count("<tr>"), 4u);  // header + 3
    EXPECT_EQ(count("<td"), 36u);  // 12 cells each, the error row too
    EXPECT_NE(h.find("<td class=\"passed\">passed</td>"), std::string::npos);
    EXPECT_NE(h.find("<td class=\"failed\">failed</td>"), std::string::npos);
    EXPECT_NE(h.find("<td class=\"error\">error</td>"), std::string::npos);
    EXPECT_NE(h.find("<a href=\"cases/a.pass.json\">a.pass</a>"), std::string::npos);
    // Names are escaped everywhere, Markdown code becomes <code>.
    EXPECT_EQ(h.find("b<fail>"), std::string::npos);
    EXPECT_NE(h.find("<li><code>b&lt;fail&gt;</code>: budget --max-false-shadow"), std::string::npos) << h;
    EXPECT_NE(h.find("<li><code>c.error</code>: error: no device</li>"), std::string::npos) << h;
    // The one named difference image, nothing for the error.
    EXPECT_EQ(count("<img "), 1u);
    EXPECT_NE(h.find("<img src=\"cases/b&lt;fail&gt;-diff.png\""), std::string::npos);
    // All passed: no reasons, no images.
    const std::string ok = htmlSummary("t", {pass}, true, {});
    EXPECT_NE(ok.find("All 1 cases passed. The baseline was written from this run."), std::string::npos);
    EXPECT_EQ(ok.find("<h2>Why</h2>"), std::string::npos);
    EXPECT_EQ(ok.find("<img "), std::string::npos);
}

}  // namespace
}  // namespace shadowlab::studies
