// scene/frame.cpp: Frame allocation and timing queries.
#include "scene/frame.h"

namespace shadowlab::scene {

Frame Frame::allocate(int width, int height, bool withBlockerId) {
    Frame f;
    f.width = width;
    f.height = height;
    const std::size_t n = f.pixelCount();
    f.beauty.assign(3 * n, 0.0f);
    f.visibility.assign(n, 0.0f);
    f.objectId.assign(n, 0.0f);
    f.ndotl.assign(n, 0.0f);
    f.depth.assign(n, 0.0f);
    if (withBlockerId) f.blockerId.assign(n, 0.0f);
    return f;
}

double Frame::timing(const std::string& stage) const {
    for (const auto& [name, ms] : timingsMs)
        if (name == stage) return ms;
    return 0.0;
}

double Frame::totalTimeMs() const {
    double total = 0.0;
    for (const auto& [name, ms] : timingsMs) total += ms;
    return total;
}

}  // namespace shadowlab::scene
