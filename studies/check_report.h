// studies/check_report.h: what `shadowlab check` writes: JUnit XML (testsuites / testsuite /
// testcase with failure and error elements, as Jenkins, GitLab and GitHub test reporters read
// it), a Markdown table for a CI job summary, and one JSON per case.
#pragma once

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "studies/check.h"

namespace shadowlab::studies {

std::string junitXml(const CheckSuite& suite, const std::vector<CaseResult>& results);

// One case's share of junit.xml and summary.md, rendered once: the shards of a sharded check
// keep their cases' parts (shard-parts.json) and `merge` joins them in suite order, so the
// merged files are the ones an unsharded run writes from the same results.
struct CasePart {
    std::string name;
    CaseVerdict verdict = CaseVerdict::Passed;
    double seconds = 0.0;
    std::string junit;  // the <testcase> element
    std::string row;    // the Markdown table row
    std::string why;    // the Markdown "Why:" lines (empty when it passed)
};
CasePart casePart(const CheckSuite& suite, const CheckCase& c, const CaseResult& r);
std::vector<CasePart> caseParts(const CheckSuite& suite, const std::vector<CaseResult>& results);
std::string junitXml(const std::string& suiteName, const std::vector<CasePart>& parts);
std::string markdownSummary(const std::string& suiteName, const std::vector<CasePart>& parts, bool baselineUpdated);
// summary.html: the same table and reasons as summary.md, as a page for a CI artifact, with the
// difference image of each case named in `withDiff` (cases/NAME-diff.png) and links to the
// cases' JSON.
std::string htmlSummary(const std::string& suiteName, const std::vector<CasePart>& parts, bool baselineUpdated,
                        const std::set<std::string>& withDiff);
nlohmann::json toJson(const CasePart& part);
// Throws std::exception on a missing field or an unknown verdict.
CasePart casePartFromJson(const nlohmann::json& j);
// `diffLinks`: the difference images written, by case (failing cases only).
std::string markdownSummary(const CheckSuite& suite, const std::vector<CaseResult>& results, bool baselineUpdated);
nlohmann::json caseJson(const CheckCase& c, const CaseResult& r);
// Escapes & < > " ' for XML text and attribute values.
std::string escapeXml(const std::string& text);

// DIR/shard-K-of-N/shard.json of `check --shard K/N`: which suite (a hash of the suite file's
// bytes, and of the baseline's), which split, and which cases. "check_suite_hash" tells it from
// a sweep shard's manifest.
struct CheckShardManifest {
    std::string version;
    std::string suite;  // the suite file, as given on the machine that wrote it (messages only)
    std::string suiteName;
    std::string suiteHash;
    std::string baselineHash;  // "none": no regression check
    Shard shard;
    std::vector<std::string> suiteCases;  // every case of the suite, in file order
    std::vector<std::string> cases;       // this shard's, in file order
};
nlohmann::json toJson(const CheckShardManifest& manifest);
// Throws scene::InputError naming the file and the field.
CheckShardManifest readCheckShardManifest(const std::filesystem::path& file);
// True when an input of `merge` (a shard folder, or a folder of shard-K-of-N folders) holds
// check shards rather than sweep shards.
bool holdsCheckShards(const std::vector<std::filesystem::path>& inputs);

struct MergedCheck {
    CheckShardManifest identity;                   // the first shard's (shard and cases: unused)
    std::vector<CasePart> parts;                   // suite order, every case once
    std::vector<std::filesystem::path> caseDirs;   // the cases/ folder each part comes from
    std::vector<std::filesystem::path> shardDirs;  // K order
};
// Reads and checks every shard before anything is written. Throws scene::InputError naming the
// folder when an input holds no check shard, shards are of another suite, baseline, program
// version or N, one shard comes twice, a shard does not hold the cases its K/N deals it, or
// shards are missing (each named with the command that writes it).
MergedCheck readCheckShards(const std::vector<std::filesystem::path>& inputs);
// Writes out/junit.xml, out/summary.md and out/cases/ (replaced as a whole), each atomically.
// Refuses a shard folder as `out`.
void writeMergedCheck(const MergedCheck& merged, const std::filesystem::path& out);

}  // namespace shadowlab::studies
