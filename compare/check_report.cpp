// compare/check_report.cpp: JUnit XML, Markdown and per-case JSON of a check suite.
#include "compare/check_report.h"

#include <cstdio>
#include <sstream>

#include "compare/text.h"

namespace shadowlab::compare {

namespace {

std::string seconds(double s) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3f", s);
    return b;
}

std::size_t count(const std::vector<CaseResult>& rs, CaseVerdict v) {
    std::size_t n = 0;
    for (const CaseResult& r : rs) n += r.verdict == v ? 1 : 0;
    return n;
}

// A Markdown table cell: no pipes or newlines.
std::string cell(std::string s) {
    for (char& c : s)
        if (c == '|' || c == '\n') c = ' ';
    return s;
}

}  // namespace

std::string escapeXml(const std::string& text) {
    std::string out;
    for (char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&apos;"; break;
            default:
                // XML 1.0 allows no control characters but tab, newline and carriage return.
                if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r') out += '?';
                else out += c;
        }
    }
    return out;
}

std::string junitXml(const CheckSuite& suite, const std::vector<CaseResult>& results) {
    double total = 0.0;
    for (const CaseResult& r : results) total += r.seconds;
    const std::string counts = "tests=\"" + std::to_string(results.size()) + "\" failures=\"" +
                               std::to_string(count(results, CaseVerdict::Failed)) + "\" errors=\"" +
                               std::to_string(count(results, CaseVerdict::Error)) + "\"";
    std::ostringstream x;
    x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    x << "<testsuites name=\"shadowlab check\" " << counts << " time=\"" << seconds(total) << "\">\n";
    x << "  <testsuite name=\"" << escapeXml(suite.name) << "\" " << counts << " skipped=\"0\" time=\""
      << seconds(total) << "\">\n";
    for (std::size_t i = 0; i < results.size(); ++i) {
        const CaseResult& r = results[i];
        const CheckCase& c = suite.cases[i];
        x << "    <testcase name=\"" << escapeXml(r.name) << "\" classname=\"shadowlab." << escapeXml(suite.name)
          << "\" time=\"" << seconds(r.seconds) << "\">\n";
        if (r.verdict == CaseVerdict::Error) {
            x << "      <error message=\"" << escapeXml(r.error) << "\" type=\"render\">" << escapeXml(r.error)
              << "</error>\n";
        } else if (r.verdict == CaseVerdict::Failed) {
            std::string text;
            for (const std::string& f : r.failures) text += f + "\n";
            x << "      <failure message=\"" << escapeXml(r.failures.front())
              << (r.failures.size() > 1 ? " (+" + std::to_string(r.failures.size() - 1) + " more)" : "")
              << "\" type=\"" << (r.failures.front().rfind("budget", 0) == 0 ? "budget" : "regression") << "\">"
              << escapeXml(text) << "</failure>\n";
        }
        if (r.metrics)
            x << "      <system-out>" << escapeXml(c.sceneFile.filename().string() + " " + c.backend + " " +
                                                   c.resolution + ": " + summaryLine(*r.metrics))
              << "</system-out>\n";
        x << "    </testcase>\n";
    }
    x << "  </testsuite>\n</testsuites>\n";
    return x.str();
}

std::string markdownSummary(const CheckSuite& suite, const std::vector<CaseResult>& results, bool baselineUpdated) {
    std::ostringstream m;
    const std::size_t failed = count(results, CaseVerdict::Failed), errors = count(results, CaseVerdict::Error);
    m << "### shadowlab check: " << suite.name << "\n\n";
    m << (failed + errors == 0 ? "All " + std::to_string(results.size()) + " cases passed."
                               : std::to_string(results.size() - failed - errors) + " passed, " +
                                     std::to_string(failed) + " failed, " + std::to_string(errors) + " errors.")
      << (baselineUpdated ? " The baseline was written from this run." : "") << "\n\n";
    m << "| case | scene | backend | verdict | mismatch | false shadow | missed | self acne | IoU | mean \\|ΔV\\| | "
         "vs baseline | time |\n";
    m << "| --- | --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- | ---: |\n";
    for (std::size_t i = 0; i < results.size(); ++i) {
        const CaseResult& r = results[i];
        const CheckCase& c = suite.cases[i];
        m << "| " << cell(r.name) << " | " << cell(c.sceneFile.stem().string()) << " | " << c.backend << " | "
          << (r.verdict == CaseVerdict::Passed ? "passed" : r.verdict == CaseVerdict::Failed ? "**FAILED**" : "**ERROR**")
          << " | ";
        if (r.metrics) {
            const Metrics& x = *r.metrics;
            m << formatPercent(x.mismatchRate) << " | " << formatPercent(x.falseShadowRate) << " | "
              << formatPercent(x.missedShadowRate) << " | "
              << (x.hasBlockerIds ? formatPercent(x.selfShadowAcneRate) : "n/a") << " | " << formatFixed(x.shadowIoU, 3)
              << " | " << formatFixed(x.meanAbsVisibilityError, 4) << " | ";
            std::string drift;
            for (const MetricDrift& d : r.drift)
                if (d.regressed || d.improved) drift += (drift.empty() ? "" : ", ") + d.metric + (d.regressed ? " worse" : " better");
            m << (!r.hasBaseline ? "no baseline" : drift.empty() ? "within tolerance" : drift) << " | "
              << formatDuration(1000.0 * r.seconds) << " |\n";
        } else {
            m << "| | | | | | " << cell(r.error.substr(0, 120)) << " | |\n";
        }
    }
    bool any = false;
    for (const CaseResult& r : results) {
        if (r.verdict == CaseVerdict::Passed) continue;
        if (!any) m << "\nWhy:\n\n";
        any = true;
        if (r.verdict == CaseVerdict::Error) m << "- `" << r.name << "`: error: " << cell(r.error) << "\n";
        for (const std::string& f : r.failures)
            m << "- `" << r.name << "`: " << cell(f) << " (cases/" << r.name << "-diff.png)\n";
    }
    return m.str();
}

nlohmann::json caseJson(const CheckCase& c, const CaseResult& r) {
    nlohmann::json drift = nlohmann::json::array();
    for (const MetricDrift& d : r.drift)
        drift.push_back({{"metric", d.metric}, {"baseline", d.baseline}, {"current", d.current},
                         {"tolerance", d.tolerance}, {"regressed", d.regressed}, {"improved", d.improved}});
    nlohmann::json j = {{"name", c.name},
                        {"scene", c.sceneFile.string()},
                        {"backend", c.backend},
                        {"resolution", c.resolution},
                        {"settings", c.settings},
                        {"budgets", scene::toJson(c.budgets)},
                        {"verdict", toString(r.verdict)},
                        {"failures", r.failures},
                        {"seconds", r.seconds},
                        {"has_baseline", r.hasBaseline},
                        {"baseline_drift", drift}};
    if (!c.device.empty()) j["device"] = c.device;
    if (r.verdict == CaseVerdict::Error) j["error"] = r.error;
    if (r.metrics) {
        j["metrics"] = toJson(*r.metrics);
        j["budget_checks"] = toJson(r.budgets);
        j["attributes"] = r.attributes;
    }
    if (!r.diffRgb.empty()) j["diff_image"] = c.name + "-diff.png";
    return j;
}

}  // namespace shadowlab::compare
