// compare/pareto.cpp: Pareto front by one sort and a sweep (O(n log n)).
#include "compare/pareto.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace shadowlab::compare {

std::vector<std::size_t> paretoFront(const std::vector<TimeErrorPoint>& points) {
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < points.size(); ++i)
        if (std::isfinite(points[i].timeMs) && std::isfinite(points[i].error)) order.push_back(i);
    // By time, then error, then index so equal points keep their input order.
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        if (points[a].timeMs != points[b].timeMs) return points[a].timeMs < points[b].timeMs;
        if (points[a].error != points[b].error) return points[a].error < points[b].error;
        return a < b;
    });
    std::vector<std::size_t> front;
    for (const std::size_t i : order) {
        if (front.empty() || points[i].error < points[front.back()].error) {
            front.push_back(i);
        } else if (points[i].error == points[front.back()].error && points[i].timeMs == points[front.back()].timeMs) {
            front.push_back(i);  // an exact duplicate of a front point
        }
        // Otherwise an earlier (no slower) point is at least as accurate: dominated.
    }
    return front;
}

}  // namespace shadowlab::compare
