// studies/check_report.cpp: JUnit XML, Markdown and per-case JSON of a check suite.
#include "studies/check_report.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "compare/report.h"
#include "compare/text.h"
#include "scene/error.h"
#include "scene/frame_io.h"
#include "scene/json_input.h"

namespace shadowlab::studies {

namespace {

std::string seconds(double s) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3f", s);
    return b;
}

std::size_t count(const std::vector<CasePart>& ps, CaseVerdict v) {
    std::size_t n = 0;
    for (const CasePart& p : ps) n += p.verdict == v ? 1 : 0;
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
                if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r')
                    out += '?';
                else
                    out += c;
        }
    }
    return out;
}

CasePart casePart(const CheckSuite& suite, const CheckCase& c, const CaseResult& r) {
    CasePart p;
    p.name = r.name;
    p.verdict = r.verdict;
    p.seconds = r.seconds;
    std::ostringstream x;
    x << "    <testcase name=\"" << escapeXml(r.name) << "\" classname=\"shadowlab." << escapeXml(suite.name)
      << "\" time=\"" << seconds(r.seconds) << "\">\n";
    if (r.verdict == CaseVerdict::Error) {
        x << "      <error message=\"" << escapeXml(r.error) << "\" type=\"render\">" << escapeXml(r.error)
          << "</error>\n";
    } else if (r.verdict == CaseVerdict::Failed) {
        std::string text;
        for (const std::string& f : r.failures) text += f + "\n";
        x << "      <failure message=\"" << escapeXml(r.failures.front())
          << (r.failures.size() > 1 ? " (+" + std::to_string(r.failures.size() - 1) + " more)" : "") << "\" type=\""
          << (r.failures.front().rfind("budget", 0) == 0 ? "budget" : "regression") << "\">" << escapeXml(text)
          << "</failure>\n";
    }
    if (r.metrics)
        x << "      <system-out>"
          << escapeXml(c.sceneFile.filename().string() + " " + scene::toString(c.backend) + " " + c.resolution + ": " +
                       compare::summaryLine(*r.metrics))
          << "</system-out>\n";
    x << "    </testcase>\n";
    p.junit = x.str();

    std::ostringstream m;
    m << "| " << cell(r.name) << " | " << cell(c.sceneFile.stem().string()) << " | " << scene::toString(c.backend)
      << " | "
      << (r.verdict == CaseVerdict::Passed   ? "passed"
          : r.verdict == CaseVerdict::Failed ? "**FAILED**"
                                             : "**ERROR**")
      << " | ";
    if (r.metrics) {
        const compare::Metrics& v = *r.metrics;
        m << compare::formatPercent(v.mismatchRate) << " | " << compare::formatPercent(v.falseShadowRate) << " | "
          << compare::formatPercent(v.missedShadowRate) << " | "
          << (v.hasBlockerIds ? compare::formatPercent(v.selfShadowAcneRate) : "n/a") << " | "
          << compare::formatFixed(v.shadowIoU, 3) << " | " << compare::formatFixed(v.meanAbsVisibilityError, 4)
          << " | ";
        std::string drift;
        for (const MetricDrift& d : r.drift)
            if (d.regressed || d.improved)
                drift += (drift.empty() ? "" : ", ") + d.metric + (d.regressed ? " worse" : " better");
        m << (!r.hasBaseline  ? "no baseline"
              : drift.empty() ? "within tolerance"
                              : drift)
          << " | " << compare::formatDuration(1000.0 * r.seconds) << " |\n";
    } else {
        // The error in the row's comment column, cut at a word within 120 characters; "Why" has it whole.
        std::string shown = r.error;
        if (shown.size() > 120) {
            std::size_t cut = shown.rfind(' ', 110);
            if (cut == std::string::npos || cut == 0) {
                cut = 110;  // no word to end on: at a character, not inside a UTF-8 sequence
                while (cut > 0 && (static_cast<unsigned char>(shown[cut]) & 0xC0) == 0x80) --cut;
            }
            shown = shown.substr(0, cut) + " … (see Why)";
        }
        m << "| | | | | | " << cell(shown) << " | |\n";
    }
    p.row = m.str();

    std::ostringstream w;
    if (r.verdict == CaseVerdict::Error) w << "- `" << r.name << "`: error: " << cell(r.error) << "\n";
    for (const std::string& f : r.failures)
        w << "- `" << r.name << "`: " << cell(f) << " (cases/" << r.name << "-diff.png)\n";
    p.why = w.str();
    return p;
}

std::vector<CasePart> caseParts(const CheckSuite& suite, const std::vector<CaseResult>& results) {
    std::vector<CasePart> parts;
    for (std::size_t i = 0; i < results.size(); ++i) parts.push_back(casePart(suite, suite.cases[i], results[i]));
    return parts;
}

std::string junitXml(const std::string& suiteName, const std::vector<CasePart>& parts) {
    double total = 0.0;
    for (const CasePart& p : parts) total += p.seconds;
    const std::string counts = "tests=\"" + std::to_string(parts.size()) + "\" failures=\"" +
                               std::to_string(count(parts, CaseVerdict::Failed)) + "\" errors=\"" +
                               std::to_string(count(parts, CaseVerdict::Error)) + "\"";
    std::ostringstream x;
    x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    x << "<testsuites name=\"shadowlab check\" " << counts << " time=\"" << seconds(total) << "\">\n";
    x << "  <testsuite name=\"" << escapeXml(suiteName) << "\" " << counts << " skipped=\"0\" time=\"" << seconds(total)
      << "\">\n";
    for (const CasePart& p : parts) x << p.junit;
    x << "  </testsuite>\n</testsuites>\n";
    return x.str();
}

std::string junitXml(const CheckSuite& suite, const std::vector<CaseResult>& results) {
    return junitXml(suite.name, caseParts(suite, results));
}

std::string markdownSummary(const std::string& suiteName, const std::vector<CasePart>& parts, bool baselineUpdated) {
    std::ostringstream m;
    const std::size_t failed = count(parts, CaseVerdict::Failed), errors = count(parts, CaseVerdict::Error);
    m << "### shadowlab check: " << suiteName << "\n\n";
    m << (failed + errors == 0 ? "All " + std::to_string(parts.size()) + " cases passed."
                               : std::to_string(parts.size() - failed - errors) + " passed, " + std::to_string(failed) +
                                     " failed, " + std::to_string(errors) + " errors.")
      << (baselineUpdated ? " The baseline was written from this run." : "") << "\n\n";
    m << "| case | scene | backend | verdict | mismatch | false shadow | missed | self acne | IoU | mean \\|ΔV\\| | "
         "vs baseline | time |\n";
    m << "| --- | --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- | ---: |\n";
    for (const CasePart& p : parts) m << p.row;
    bool any = false;
    for (const CasePart& p : parts) {
        if (p.verdict == CaseVerdict::Passed) continue;
        if (!any) m << "\nWhy:\n\n";
        any = true;
        m << p.why;
    }
    return m.str();
}

namespace {

// The Markdown the parts hold (`code`, **bold**), as HTML; everything else escaped.
std::string inlineHtml(const std::string& md) {
    std::string out;
    bool code = false, bold = false;
    for (std::size_t i = 0; i < md.size(); ++i) {
        if (md[i] == '`') {
            out += code ? "</code>" : "<code>";
            code = !code;
        } else if (!code && md.compare(i, 2, "**") == 0) {
            out += bold ? "</b>" : "<b>";
            bold = !bold;
            ++i;
        } else {
            out += compare::escapeHtml(std::string(1, md[i]));
        }
    }
    if (code) out += "</code>";
    if (bold) out += "</b>";
    return out;
}

// The cells of a Markdown table row "| a | b |" (the parts' cells hold no pipe: cell() drops them).
std::vector<std::string> rowCells(const std::string& row) {
    std::vector<std::string> cells;
    std::string r = row;
    while (!r.empty() && (r.back() == '\n' || r.back() == ' ')) r.pop_back();
    if (r.size() < 2 || r.front() != '|' || r.back() != '|') return cells;
    std::istringstream in(r.substr(1, r.size() - 2));
    for (std::string c; std::getline(in, c, '|');) {
        const auto a = c.find_first_not_of(' '), b = c.find_last_not_of(' ');
        cells.push_back(a == std::string::npos ? "" : c.substr(a, b - a + 1));
    }
    return cells;
}

}  // namespace

std::string htmlSummary(const std::string& suiteName, const std::vector<CasePart>& parts, bool baselineUpdated,
                        const std::set<std::string>& withDiff) {
    const std::size_t failed = count(parts, CaseVerdict::Failed), errors = count(parts, CaseVerdict::Error);
    std::ostringstream h;
    h << "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>shadowlab check: "
      << compare::escapeHtml(suiteName) << "</title>\n<style>" << compare::html::css()
      << " td.passed{color:#1b5e20} td.failed,td.error{color:#a51111;font-weight:600}"
         " .diffs{grid-template-columns:repeat(auto-fill,minmax(300px,1fr))} .why li{margin-bottom:4px}"
         " .scroll{overflow-x:auto} table.cases td{white-space:nowrap} table.cases :is(td,th){padding:6px 8px}"
         " table.cases "
         ":is(td,th):is(:nth-child(-n+4),:nth-child(11)){text-align:left}</style>\n</head>\n<body>\n<main>\n";
    h << "<header><h1>shadowlab check: " << compare::escapeHtml(suiteName) << "</h1><div class=\"sub\">"
      << (failed + errors == 0 ? "All " + std::to_string(parts.size()) + " cases passed."
                               : std::to_string(parts.size() - failed - errors) + " passed, " + std::to_string(failed) +
                                     " failed, " + std::to_string(errors) + " errors.")
      << (baselineUpdated ? " The baseline was written from this run." : "")
      << " JUnit: <a href=\"junit.xml\">junit.xml</a>; Markdown: <a "
         "href=\"summary.md\">summary.md</a>.</div></header>\n";
    h << "<h2>Cases</h2>\n<div class=\"scroll\"><table "
         "class=\"cases\"><thead><tr><th>case</th><th>scene</th><th>backend</th>"
         "<th>verdict</th><th>mismatch</th><th>false shadow</th><th>missed</th><th>self acne</th><th>IoU</th>"
         "<th>mean |ΔV|</th><th>vs baseline</th><th>time</th></tr></thead><tbody>\n";
    for (const CasePart& p : parts) {
        const std::vector<std::string> cells = rowCells(p.row);
        const char* verdict = p.verdict == CaseVerdict::Passed   ? "passed"
                              : p.verdict == CaseVerdict::Failed ? "failed"
                                                                 : "error";
        h << "<tr>";
        for (std::size_t i = 0; i < cells.size(); ++i) {
            if (i == 0)
                h << "<td><a href=\"cases/" << compare::escapeHtml(p.name) << ".json\">" << compare::escapeHtml(p.name)
                  << "</a></td>";
            else if (i == 3)
                h << "<td class=\"" << verdict << "\">" << verdict << "</td>";
            else
                h << "<td>" << inlineHtml(cells[i]) << "</td>";
        }
        h << "</tr>\n";
    }
    h << "</tbody></table></div>\n";
    if (failed + errors) {
        h << "<h2>Why</h2>\n<ul class=\"why\">\n";
        for (const CasePart& p : parts) {
            std::istringstream lines(p.why);
            for (std::string l; std::getline(lines, l);)
                if (l.rfind("- ", 0) == 0) h << "<li>" << inlineHtml(l.substr(2)) << "</li>\n";
        }
        h << "</ul>\n";
    }
    bool any = false;
    for (const CasePart& p : parts) {
        if (!withDiff.count(p.name)) continue;
        if (!any) {
            // No hotspot zooms here: the legend's sentence about them goes.
            std::string legend = compare::html::diffLegend();
            const auto a = legend.find(" The yellow square"), b = legend.find("</p>", a);
            if (a != std::string::npos && b != std::string::npos) legend.erase(a, b - a);
            h << "<h2>Difference images of the failing cases</h2>\n" << legend << "\n<div class=\"grid diffs\">\n";
        }
        any = true;
        const std::string png = "cases/" + p.name + "-diff.png";
        h << "<figure><figcaption>" << compare::escapeHtml(p.name) << "</figcaption><a href=\""
          << compare::escapeHtml(png) << "\"><img src=\"" << compare::escapeHtml(png) << "\" alt=\""
          << compare::escapeHtml(p.name) << " difference\" class=\"upscale\"></a></figure>\n";
    }
    if (any) h << "</div>\n";
    h << "</main>\n</body>\n</html>\n";
    return h.str();
}

std::string markdownSummary(const CheckSuite& suite, const std::vector<CaseResult>& results, bool baselineUpdated) {
    return markdownSummary(suite.name, caseParts(suite, results), baselineUpdated);
}

nlohmann::json toJson(const CasePart& p) {
    return {{"name", p.name},       {"verdict", toString(p.verdict)},
            {"seconds", p.seconds}, {"junit", p.junit},
            {"row", p.row},         {"why", p.why}};
}

CasePart casePartFromJson(const nlohmann::json& j) {
    CasePart p;
    p.name = j.at("name").get<std::string>();
    const std::string v = j.at("verdict").get<std::string>();
    if (v == "passed")
        p.verdict = CaseVerdict::Passed;
    else if (v == "failed")
        p.verdict = CaseVerdict::Failed;
    else if (v == "error")
        p.verdict = CaseVerdict::Error;
    else
        throw std::runtime_error("verdict '" + v + "' is not passed, failed or error");
    p.seconds = j.at("seconds").get<double>();
    p.junit = j.at("junit").get<std::string>();
    p.row = j.at("row").get<std::string>();
    p.why = j.at("why").get<std::string>();
    return p;
}

nlohmann::json caseJson(const CheckCase& c, const CaseResult& r) {
    nlohmann::json drift = nlohmann::json::array();
    for (const MetricDrift& d : r.drift)
        drift.push_back({{"metric", d.metric},
                         {"baseline", d.baseline},
                         {"current", d.current},
                         {"tolerance", d.tolerance},
                         {"regressed", d.regressed},
                         {"improved", d.improved}});
    nlohmann::json j = {{"name", c.name},
                        {"scene", c.sceneFile.string()},
                        {"backend", scene::toString(c.backend)},
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

namespace {

namespace fs = std::filesystem;

nlohmann::json readJson(const fs::path& file, const std::string& what) {
    try {
        return scene::readJsonFile(file);
    } catch (const scene::SceneError& e) {
        throw scene::InputError(std::string(e.what()) + " (the " + what + ")");
    }
}

// The shard folders of one input: itself when it holds shard.json, else its shard-K-of-N folders.
std::vector<fs::path> shardFolders(const fs::path& input) {
    std::error_code ec;
    if (!fs::is_directory(input, ec)) throw scene::InputError(input.string() + ": no such folder");
    if (fs::exists(input / "shard.json", ec)) return {input};
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(input)) {
        const std::string n = e.path().filename().string();
        if (e.is_directory() && n.rfind("shard-", 0) == 0 && fs::exists(e.path() / "shard.json", ec))
            out.push_back(e.path());
    }
    std::sort(out.begin(), out.end());
    return out;
}

}  // namespace

nlohmann::json toJson(const CheckShardManifest& m) {
    return {{"program", "shadowlab"},
            {"command", commandLine()},
            {"cwd", commandDirectory()},
            {"version", m.version},
            {"check_suite", m.suite},
            {"check_suite_name", m.suiteName},
            {"check_suite_hash", m.suiteHash},
            {"baseline_hash", m.baselineHash},
            {"shard", {{"index", m.shard.index}, {"count", m.shard.count}}},
            {"suite_cases", m.suiteCases},
            {"cases", m.cases}};
}

CheckShardManifest readCheckShardManifest(const fs::path& file) {
    const nlohmann::json j = readJson(file, "check shard manifest");
    CheckShardManifest m;
    const char* field = "";
    try {
        field = "program";
        if (j.at(field).get<std::string>() != "shadowlab") throw std::runtime_error("not shadowlab");
        field = "version";
        m.version = j.at(field).get<std::string>();
        field = "check_suite";
        m.suite = j.at(field).get<std::string>();
        field = "check_suite_name";
        m.suiteName = j.at(field).get<std::string>();
        field = "check_suite_hash";
        m.suiteHash = j.at(field).get<std::string>();
        field = "baseline_hash";
        m.baselineHash = j.at(field).get<std::string>();
        field = "shard";
        m.shard.index = j.at(field).at("index").get<int>();
        m.shard.count = j.at(field).at("count").get<int>();
        field = "suite_cases";
        m.suiteCases = j.at(field).get<std::vector<std::string>>();
        field = "cases";
        m.cases = j.at(field).get<std::vector<std::string>>();
    } catch (const std::exception&) {
        throw scene::InputError(file.string() + ": " + field + ": missing or wrong type in the check shard manifest");
    }
    if (m.shard.count < 1 || m.shard.index < 0 || m.shard.index >= m.shard.count)
        throw scene::InputError(file.string() + ": shard: index " + std::to_string(m.shard.index) + " of " +
                                std::to_string(m.shard.count) + " is out of range");
    return m;
}

bool holdsCheckShards(const std::vector<fs::path>& inputs) {
    for (const fs::path& input : inputs) {
        std::error_code ec;
        if (!fs::is_directory(input, ec)) continue;
        for (const fs::path& d : shardFolders(input)) {
            const nlohmann::json j = scene::readJsonFileOrNull(d / "shard.json");
            return j.is_object() && j.contains("check_suite_hash");
        }
    }
    return false;
}

MergedCheck readCheckShards(const std::vector<fs::path>& inputs) {
    if (inputs.empty()) throw scene::InputError("merge: no input folder");
    MergedCheck merged;
    std::map<int, std::pair<fs::path, CheckShardManifest>> byIndex;
    fs::path firstDir;
    fs::path outputDir;  // the -o the shards were written with, for the commands of missing ones
    for (const fs::path& input : inputs) {
        const std::vector<fs::path> dirs = shardFolders(input);
        if (dirs.empty()) throw scene::InputError(input.string() + ": holds no check shard (shard-K-of-N/shard.json)");
        if (outputDir.empty()) outputDir = dirs.size() == 1 && dirs.front() == input ? input.parent_path() : input;
        for (const fs::path& d : dirs) {
            const fs::path file = d / "shard.json";
            CheckShardManifest m = readCheckShardManifest(file);
            if (byIndex.empty()) {
                merged.identity = m;
                firstDir = d;
            } else {
                const CheckShardManifest& a = merged.identity;
                std::string diff;
                if (m.version != a.version)
                    diff = "program version " + m.version + " vs " + a.version;
                else if (m.suiteHash != a.suiteHash || m.suiteCases != a.suiteCases)
                    diff = "suite hash " + m.suiteHash + " (" + m.suite + ") vs " + a.suiteHash + " (" + a.suite +
                           ") (another suite file)";
                else if (m.baselineHash != a.baselineHash)
                    diff = "baseline hash " + m.baselineHash + " vs " + a.baselineHash + " (another baseline)";
                else if (m.shard.count != a.shard.count)
                    diff =
                        "split into " + std::to_string(m.shard.count) + " shards vs " + std::to_string(a.shard.count);
                if (!diff.empty())
                    throw scene::InputError(d.string() + ": a shard of another check than " + firstDir.string() + " (" +
                                            diff + "); merge the shards of one run");
            }
            const auto [it, fresh] = byIndex.emplace(m.shard.index, std::make_pair(d, m));
            if (!fresh && fs::weakly_canonical(it->second.first) != fs::weakly_canonical(d))
                throw scene::InputError(d.string() + ": shard " + std::to_string(m.shard.index) + "/" +
                                        std::to_string(m.shard.count) + " again (also " + it->second.first.string() +
                                        "); give each shard once");
        }
    }
    const CheckShardManifest& id = merged.identity;
    std::vector<fs::path> dirs;
    for (const auto& [k, entry] : byIndex) dirs.push_back(entry.first);
    const RecordedCommand recorded = recordedShardCommand(dirs);
    std::string missing;
    for (int k = 0; k < id.shard.count; ++k) {
        if (byIndex.count(k)) continue;
        const Shard s{k, id.shard.count};
        std::string command = shardCommandText(recorded.args, s, false, recorded.cwd);
        if (command.empty())
            command = "shadowlab check " + quoteArg(id.suite) + " --shard " + std::to_string(k) + "/" +
                      std::to_string(s.count) + " -o " + quoteArg(outputDir.string());
        missing += "\n  shard " + std::to_string(k) + "/" + std::to_string(s.count) + " (" +
                   (outputDir / shardFolderName(s)).string() + "): " + command;
    }
    if (!missing.empty())
        throw scene::InputError("merge: " + std::to_string(id.shard.count - int(byIndex.size())) + " of " +
                                std::to_string(id.shard.count) + " shards of " + id.suite + " are missing:" + missing);
    // Every case exactly once: each shard holds what its K/N deals it, no more, no less.
    const std::vector<int> of = assignShards(id.suiteCases, id.shard.count);
    std::map<std::string, std::pair<CasePart, fs::path>> parts;
    for (const auto& [k, entry] : byIndex) {
        const auto& [dir, m] = entry;
        merged.shardDirs.push_back(dir);
        std::vector<std::string> expected;
        for (std::size_t i = 0; i < id.suiteCases.size(); ++i)
            if (of[i] == k) expected.push_back(id.suiteCases[i]);
        if (m.cases != expected)
            throw scene::InputError((dir / "shard.json").string() + ": cases: not the cases shard " +
                                    std::to_string(k) + "/" + std::to_string(id.shard.count) + " of this suite holds");
        const fs::path file = dir / "shard-parts.json";
        const nlohmann::json j = readJson(file, "check shard's results");
        if (!j.is_array() || j.size() != expected.size())
            throw scene::InputError(file.string() + ": expected an array of " + std::to_string(expected.size()) +
                                    " cases");
        for (std::size_t i = 0; i < j.size(); ++i) {
            CasePart p;
            try {
                p = casePartFromJson(j[i]);
            } catch (const std::exception& e) {
                throw scene::InputError(file.string() + ": [" + std::to_string(i) + "]: " + e.what());
            }
            if (p.name != expected[i])
                throw scene::InputError(file.string() + ": [" + std::to_string(i) + "]: case '" + p.name +
                                        "', expected '" + expected[i] + "'");
            std::error_code ec;
            if (!fs::exists(dir / "cases" / (p.name + ".json"), ec))
                throw scene::InputError((dir / "cases" / (p.name + ".json")).string() + ": missing");
            // Read before anything is written: a case file cut short (a copy that stopped) is
            // refused here rather than copied into the merged folder as broken JSON.
            readJson(dir / "cases" / (p.name + ".json"), "case result");
            parts.emplace(p.name, std::make_pair(p, dir / "cases"));
        }
    }
    for (const std::string& name : id.suiteCases) {
        merged.parts.push_back(parts.at(name).first);
        merged.caseDirs.push_back(parts.at(name).second);
    }
    return merged;
}

void writeMergedCheck(const MergedCheck& merged, const fs::path& out) {
    std::error_code ec;
    if (fs::exists(out / "shard.json", ec))
        throw scene::InputError(out.string() + ": is a shard folder; merge into the folder that holds the shards");
    fs::create_directories(out);
    scene::removeStaleTemporaries(out);
    const fs::path tmp = scene::temporarySibling(out / "cases");
    fs::create_directories(tmp);
    for (std::size_t i = 0; i < merged.parts.size(); ++i) {
        const std::string& name = merged.parts[i].name;
        for (const std::string& f : {name + ".json", name + "-diff.png"})
            if (fs::exists(merged.caseDirs[i] / f, ec)) fs::copy_file(merged.caseDirs[i] / f, tmp / f);
    }
    scene::replaceDirectory(tmp, out / "cases");
    scene::writeTextAtomic(out / "junit.xml", junitXml(merged.identity.suiteName, merged.parts));
    scene::writeTextAtomic(out / "summary.md", markdownSummary(merged.identity.suiteName, merged.parts, false));
    std::set<std::string> withDiff;
    for (const CasePart& p : merged.parts)
        if (fs::exists(out / "cases" / (p.name + "-diff.png"), ec)) withDiff.insert(p.name);
    scene::writeTextAtomic(out / "summary.html", htmlSummary(merged.identity.suiteName, merged.parts, false, withDiff));
}

}  // namespace shadowlab::studies
