// compare/pareto.h: the Pareto front of (run time, error) points: the settings no other setting
// beats in both speed and accuracy. A sweep draws one front per backend.
#pragma once

#include <cstddef>
#include <vector>

namespace shadowlab::compare {

struct TimeErrorPoint {
    double timeMs = 0.0;
    double error = 0.0;  // e.g. mismatch rate
};

// Indices of the non-dominated points, in increasing time (and decreasing error). A point is
// dominated when another is no slower and no less accurate, and strictly better in one.
// Exact duplicates of a front point are all kept (none dominates the other). Points with a
// non-finite time or error (a failed row) are never on the front.
std::vector<std::size_t> paretoFront(const std::vector<TimeErrorPoint>& points);

}  // namespace shadowlab::compare
