// tests/shaders/interface_test.cpp: shaders/interface.h read by both languages gives the same
// layout. glslang's reflection of lit.frag (every member of its uniform block, with the offset
// std140 gives it) against the C++ structs' offsetof, member by member: a member on one side
// only, or at another offset, fails.
#include "shaders/interface.h"

#include <cstddef>
#include <cstdio>
#include <map>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace shadowlab::shaders {
namespace {

// glslangValidator's reflection of lit.frag: "u.lights[1].layer: offset 476, ..." for every
// member, and again for the members lit.frag reads, with the array of lights or cascades unindexed
// ("u.lights.layer: offset 188, ..., topLevelArrayStride 288", element 0's offset); the block's
// size ("Uniforms: offset -1, ..., size 3952, ...").
struct Reflection {
    std::map<std::string, std::size_t> offsets;       // indexed names
    std::map<std::string, std::size_t> firstOffsets;  // unindexed names: element 0's offset
    std::map<std::string, std::size_t> strides;       // unindexed names: the array's stride
    std::size_t blockSize = 0;
    std::string output;
};
Reflection reflectLitFrag() {
    const std::string command = std::string(SHADOWLAB_GLSLANG) + " -V --target-env vulkan1.3 -q " +
                                "--reflect-all-block-variables -o /dev/null " SHADOWLAB_SHADERS_DIR "/lit.frag 2>&1";
    Reflection r;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return r;
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe)) r.output += buffer;
    pclose(pipe);
    const std::regex member(R"(^(u\.[^:]+): offset (\d+),)");
    const std::regex unindexed(R"(^u\.(lights|cascades)\.)");
    const std::regex stride(R"(topLevelArrayStride (\d+))");
    const std::regex block(R"(^Uniforms: offset -1, type [0-9a-f]+, size (\d+),)");
    std::size_t start = 0;
    while (start < r.output.size()) {
        std::size_t end = r.output.find('\n', start);
        if (end == std::string::npos) end = r.output.size();
        const std::string line = r.output.substr(start, end - start);
        std::smatch m;
        if (std::regex_search(line, m, member)) {
            const std::string name = m[1];
            const std::size_t offset = std::stoul(m[2]);
            if (!std::regex_search(name, unindexed)) {
                r.offsets[name] = offset;
            } else {
                // "u.lights.x" is element 0's "u.lights[0].x".
                const std::string first = std::regex_replace(name, unindexed, "u.$1[0].");
                r.firstOffsets[first] = offset;
                if (std::regex_search(line, m, stride)) r.strides[first] = std::stoul(m[1]);
            }
        }
        if (std::regex_search(line, m, block)) r.blockSize = std::stoul(m[1]);
        start = end + 1;
    }
    return r;
}

// Every leaf member of LitUniforms as glslang names it, at its C++ offset.
#define SHADOWLAB_MEMBER(Type, name) std::pair<std::string, std::size_t>(#name, offsetof(Type, name))
std::map<std::string, std::size_t> cppOffsets() {
    const std::vector<std::pair<std::string, std::size_t>> light = {
        SHADOWLAB_MEMBER(LightData, toShadow),
        SHADOWLAB_MEMBER(LightData, position),
        SHADOWLAB_MEMBER(LightData, layer),
        SHADOWLAB_MEMBER(LightData, towardLight),
        SHADOWLAB_MEMBER(LightData, cascadeCount),
        SHADOWLAB_MEMBER(LightData, spotDirection),
        SHADOWLAB_MEMBER(LightData, spotCosCone),
        SHADOWLAB_MEMBER(LightData, radiance),
        SHADOWLAB_MEMBER(LightData, visibilityWeight),
        SHADOWLAB_MEMBER(LightData, depthBiasWorld),
        SHADOWLAB_MEMBER(LightData, slopeBiasTexels),
        SHADOWLAB_MEMBER(LightData, texelWorldSize),
        SHADOWLAB_MEMBER(LightData, depthPerWorld),
        SHADOWLAB_MEMBER(LightData, maxSlopeTan),
        SHADOWLAB_MEMBER(LightData, filterCode),
        SHADOWLAB_MEMBER(LightData, normalOffsetTexels),
        SHADOWLAB_MEMBER(LightData, pcfSize),
        SHADOWLAB_MEMBER(LightData, kind),
        SHADOWLAB_MEMBER(LightData, lightSize),
        SHADOWLAB_MEMBER(LightData, mapNear),
        SHADOWLAB_MEMBER(LightData, mapFar),
        SHADOWLAB_MEMBER(LightData, pointFaceTan),
        SHADOWLAB_MEMBER(LightData, spotCosInner),
    };
    const std::vector<std::pair<std::string, std::size_t>> face = {SHADOWLAB_MEMBER(PointFace, near),
                                                                   SHADOWLAB_MEMBER(PointFace, far)};
    const std::vector<std::pair<std::string, std::size_t>> cascade = {
        SHADOWLAB_MEMBER(CascadeData, toShadow), SHADOWLAB_MEMBER(CascadeData, sliceFar),
        SHADOWLAB_MEMBER(CascadeData, texelWorldSize), SHADOWLAB_MEMBER(CascadeData, depthPerWorld),
        SHADOWLAB_MEMBER(CascadeData, depthBiasWorld)};
    const std::vector<std::pair<std::string, std::size_t>> top = {
        SHADOWLAB_MEMBER(LitUniforms, viewProj),         SHADOWLAB_MEMBER(LitUniforms, forward),
        SHADOWLAB_MEMBER(LitUniforms, ambient),          SHADOWLAB_MEMBER(LitUniforms, background),
        SHADOWLAB_MEMBER(LitUniforms, lightCount),       SHADOWLAB_MEMBER(LitUniforms, mapSize),
        SHADOWLAB_MEMBER(LitUniforms, cascadeBlendBand), SHADOWLAB_MEMBER(LitUniforms, cascadeStart)};
    std::map<std::string, std::size_t> all;
    for (const auto& [name, offset] : top) all["u." + name] = offset;
    for (std::size_t i = 0; i < SHADOWLAB_MAX_LIGHTS; ++i) {
        const std::string prefix = "u.lights[" + std::to_string(i) + "].";
        const std::size_t base = offsetof(LitUniforms, lights) + i * sizeof(LightData);
        for (const auto& [name, offset] : light) all[prefix + name] = base + offset;
        for (std::size_t k = 0; k < 6; ++k)
            for (const auto& [name, offset] : face)
                all[prefix + "pointFaces[" + std::to_string(k) + "]." + name] =
                    base + offsetof(LightData, pointFaces) + k * sizeof(PointFace) + offset;
    }
    for (std::size_t i = 0; i < SHADOWLAB_MAX_LIGHTS * SHADOWLAB_MAX_CASCADES; ++i)
        for (const auto& [name, offset] : cascade)
            all["u.cascades[" + std::to_string(i) + "]." + name] =
                offsetof(LitUniforms, cascades) + i * sizeof(CascadeData) + offset;
    return all;
}
#undef SHADOWLAB_MEMBER

TEST(ShaderInterface, GlslangPlacesEveryUniformMemberWhereCxxDoes) {
    const Reflection glsl = reflectLitFrag();
    ASSERT_FALSE(glsl.offsets.empty()) << "no reflection from glslangValidator:\n" << glsl.output;
    const std::map<std::string, std::size_t> cpp = cppOffsets();
    for (const auto& [name, offset] : glsl.offsets) {
        const auto it = cpp.find(name);
        if (it == cpp.end()) {
            ADD_FAILURE() << name << " (GLSL offset " << offset << ") has no C++ counterpart in this test";
            continue;
        }
        EXPECT_EQ(offset, it->second) << name << ": GLSL (std140) against C++";
    }
    for (const auto& [name, offset] : cpp)
        EXPECT_TRUE(glsl.offsets.count(name)) << name << " (C++ offset " << offset << ") is not in GLSL's block";
    // The members lit.frag reads, listed again: the same offset, and the arrays' strides.
    EXPECT_FALSE(glsl.firstOffsets.empty());
    for (const auto& [name, offset] : glsl.firstOffsets) {
        const auto it = cpp.find(name);
        EXPECT_TRUE(it != cpp.end() && it->second == offset) << name << " at GLSL offset " << offset;
        const std::size_t stride = name.starts_with("u.lights") ? sizeof(LightData) : sizeof(CascadeData);
        EXPECT_EQ(glsl.strides.at(name), stride) << name;
    }
    EXPECT_EQ(glsl.blockSize, sizeof(LitUniforms));
}

}  // namespace
}  // namespace shadowlab::shaders
