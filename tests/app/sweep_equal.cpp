// tests/app/sweep_equal.cpp: `sweep_equal A B` exits 0 when the sweep folders A and B hold the
// same rows (keys, settings, metrics, errors, in order) and verdicts (bias windows, robust
// offsets), ignoring run times and machines; 1 and one line per difference otherwise; 2 on bad
// input. Two path folders (metrics.json and path.json) are compared by their figures, run times
// left out. tools/slurm-local-check.sh uses it to check a merged sweep and a merged path against
// the unsharded ones.
#include <filesystem>
#include <iostream>

#include "scene/error.h"
#include "studies/merge.h"
#include "studies/path.h"

int main(int argc, char** argv) {
    if (argc != 3) {
        std::cerr << "usage: sweep_equal SWEEP_DIR_A SWEEP_DIR_B\n";
        return 2;
    }
    try {
        using namespace shadowlab::studies;
        namespace fs = std::filesystem;
        if (fs::exists(fs::path(argv[1]) / "path.json") && fs::exists(fs::path(argv[2]) / "path.json")) {
            const auto diffs = pathDifferences(argv[1], argv[2]);
            for (const std::string& d : diffs) std::cout << d << "\n";
            if (!diffs.empty()) return 1;
            std::cout << "sweep_equal: the two paths' metrics and temporal figures are equal\n";
            return 0;
        }
        const auto a = readResults(argv[1]), b = readResults(argv[2]);
        auto diffs = rowDifferences(a, b);
        for (const std::string& d : verdictDifferences(a, b)) diffs.push_back(d);
        for (const std::string& d : diffs) std::cout << d << "\n";
        if (!diffs.empty()) return 1;
        std::cout << "sweep_equal: " << a.size() << " rows, metrics and verdicts equal\n";
        return 0;
    } catch (const shadowlab::scene::InputError& e) {
        std::cerr << "sweep_equal: error: " << e.what() << "\n";
        return 2;
    }
}
