// compare/check_report.h: what `shadowlab check` writes: JUnit XML (testsuites / testsuite /
// testcase with failure and error elements, as Jenkins, GitLab and GitHub test reporters read
// it), a Markdown table for a CI job summary, and one JSON per case.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/check.h"

namespace shadowlab::compare {

std::string junitXml(const CheckSuite& suite, const std::vector<CaseResult>& results);
// `diffLinks`: the difference images written, by case (failing cases only).
std::string markdownSummary(const CheckSuite& suite, const std::vector<CaseResult>& results, bool baselineUpdated);
nlohmann::json caseJson(const CheckCase& c, const CaseResult& r);
// Escapes & < > " ' for XML text and attribute values.
std::string escapeXml(const std::string& text);

}  // namespace shadowlab::compare
