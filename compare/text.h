// compare/text.h: number formatting and escaping shared by the summary line, the HTML report
// and the SVG plots, so one value reads the same everywhere. (GCC 12: no <format>.)
#pragma once

#include <cstddef>
#include <string>
#include <utility>

namespace shadowlab::compare {

// 1234567 -> "1,234,567".
std::string formatCount(std::size_t n);
// A rate in 0..1 as a percentage that never rounds a non-zero rate to "0%":
// 0 -> "0%", 0.0000123 -> "0.0012%", 0.0082 -> "0.82%", 0.5 -> "50.0%", 1 -> "100%".
std::string formatPercent(double rate);
// Two rates as formatPercent prints them, with more significant digits where those print alike
// and the rates differ (so a sentence never ranks two equal-looking numbers).
std::pair<std::string, std::string> formatPercentsApart(double a, double b);
// Milliseconds with a unit that keeps 3 significant digits: "0.412 ms", "87.3 ms", "1.25 s".
std::string formatDuration(double ms);
// A method's run time: "not recorded" where the frame records none (a mask another renderer wrote).
std::string formatRunTime(double ms);
// Fixed decimals: formatFixed(0.98123, 3) -> "0.981". Non-finite -> "n/a".
std::string formatFixed(double value, int decimals);
// Short general form for axis labels: 3 significant digits, no trailing zeros ("0.5", "120", "1e-05").
std::string formatShort(double value);
// Escapes & < > " ' for HTML text and attribute values (SVG too).
std::string escapeHtml(const std::string& text);

}  // namespace shadowlab::compare
