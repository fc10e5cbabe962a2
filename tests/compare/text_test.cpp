// tests/compare/text_test.cpp: number formatting and HTML escaping read the way the report needs.
#include "compare/text.h"

#include <cmath>

#include <gtest/gtest.h>

namespace shadowlab::compare {
namespace {

TEST(FormatCount, GroupsThousands) {
    EXPECT_EQ(formatCount(0), "0");
    EXPECT_EQ(formatCount(999), "999");
    EXPECT_EQ(formatCount(1000), "1,000");
    EXPECT_EQ(formatCount(1234567), "1,234,567");
}

TEST(FormatPercent, NeverRoundsANonZeroRateToZero) {
    EXPECT_EQ(formatPercent(0.0), "0%");
    EXPECT_EQ(formatPercent(1.0), "100%");
    EXPECT_EQ(formatPercent(0.5), "50.0%");
    EXPECT_EQ(formatPercent(0.0082), "0.82%");
    // One wrong pixel in a 1280×720 image: 1/921600 = 1.085e-6 = 0.0001085%.
    EXPECT_EQ(formatPercent(1.0 / 921600.0), "0.00011%");
    EXPECT_EQ(formatPercent(std::nan("")), "n/a");
}

TEST(FormatPercent, NeverRoundsARateShortOfAllToAHundred) {
    // 36,742 of 36,744 pixels: 99.99456%, which "%.1f" would print as 100.0%.
    EXPECT_EQ(formatPercent(36742.0 / 36744.0), "99.99%");
    // One pixel short of a 1280x720 image: 99.999891%.
    EXPECT_EQ(formatPercent(921599.0 / 921600.0), "99.9999%");
    EXPECT_EQ(formatPercent(0.9994), "99.9%");
}

TEST(FormatDuration, PicksAUnitWithThreeSignificantDigits) {
    EXPECT_EQ(formatDuration(0.4123), "0.412 ms");
    EXPECT_EQ(formatDuration(87.34), "87.3 ms");
    EXPECT_EQ(formatDuration(456.7), "457 ms");
    EXPECT_EQ(formatDuration(1250.0), "1.25 s");
}

TEST(FormatFixed, RoundsAndRejectsNonFinite) {
    EXPECT_EQ(formatFixed(0.98123, 3), "0.981");
    EXPECT_EQ(formatFixed(INFINITY, 2), "n/a");
}

TEST(EscapeHtml, EscapesEveryMarkupCharacter) {
    EXPECT_EQ(escapeHtml("<a href=\"x\">Tom & Jerry's</a>"),
              "&lt;a href=&quot;x&quot;&gt;Tom &amp; Jerry&#39;s&lt;/a&gt;");
}

}  // namespace
}  // namespace shadowlab::compare
