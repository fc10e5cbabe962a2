// compare/text.cpp: number formatting and HTML escaping for the report, plots and summaries.
#include "compare/text.h"

#include <cmath>
#include <cstdio>

namespace shadowlab::compare {

namespace {

std::string printf1(const char* format, double value) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, value);
    return buf;
}

}  // namespace

std::string formatCount(std::size_t n) {
    std::string digits = std::to_string(n);
    std::string out;
    const int len = static_cast<int>(digits.size());
    for (int i = 0; i < len; ++i) {
        if (i > 0 && (len - i) % 3 == 0) out += ',';
        out += digits[static_cast<std::size_t>(i)];
    }
    return out;
}

std::string formatPercent(double rate) {
    if (!std::isfinite(rate)) return "n/a";
    if (rate == 0.0) return "0%";
    const double p = rate * 100.0;
    const double a = std::fabs(p);
    if (rate == 1.0) return "100%";
    // Short of all, never "100.0%": as many decimals as show that some pixels are left.
    if (rate < 1.0 && p >= 99.95) {
        for (int d = 2; d < 9; ++d) {
            const std::string format = "%." + std::to_string(d) + "f%%";
            if (const std::string s = printf1(format.c_str(), p); s.rfind("100", 0) != 0) return s;
        }
        return ">99.999999%";
    }
    if (a >= 10.0) return printf1("%.1f%%", p);
    if (a >= 0.01) return printf1("%.2f%%", p);
    // Below 0.01% keep two significant digits so a single wrong pixel in a large image still
    // reads as non-zero.
    return printf1("%.2g%%", p);
}

std::pair<std::string, std::string> formatPercentsApart(double a, double b) {
    std::string x = formatPercent(a), y = formatPercent(b);
    for (const char* format : {"%.2g%%", "%.3g%%"})
        if (x == y && a != b) {
            x = printf1(format, 100.0 * a);
            y = printf1(format, 100.0 * b);
        }
    return {x, y};
}

std::string formatDuration(double ms) {
    if (!std::isfinite(ms)) return "n/a";
    if (ms >= 1000.0) return printf1("%.3g s", ms / 1000.0);
    if (ms >= 100.0) return printf1("%.0f ms", ms);
    return printf1("%.3g ms", ms);
}

std::string formatRunTime(double ms) { return ms > 0.0 ? formatDuration(ms) : "not recorded"; }

std::string formatFixed(double value, int decimals) {
    if (!std::isfinite(value)) return "n/a";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
    return buf;
}

std::string formatShort(double value) {
    if (!std::isfinite(value)) return "n/a";
    return printf1("%.3g", value);
}

std::string escapeHtml(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            default: out += c;
        }
    }
    return out;
}

}  // namespace shadowlab::compare
