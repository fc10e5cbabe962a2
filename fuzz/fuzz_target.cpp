// fuzz/fuzz_target.cpp: the libFuzzer entry point, built once per target with
// SHADOWLAB_FUZZ_TARGET naming it ("scene_json", "obj", "ply", "gltf", "exr"; fuzz/targets.h says what
// each reads). JSON inputs (scenes, .gltf) also get a structure-aware mutator: byte mutations
// rarely keep JSON valid, so it edits the parsed tree instead.
#include <cstring>
#include <random>
#include <string_view>

#include <nlohmann/json.hpp>

#include "fuzz/fuzz_input.h"
#include "fuzz/targets.h"
#include "scene/json_input.h"

extern "C" size_t LLVMFuzzerMutate(std::uint8_t* data, size_t size, size_t maxSize);

namespace {

using Json = nlohmann::json;

// Numbers that break size arithmetic and value checks: zero, negatives, the edges of 8, 16, 32
// and 64 bits, doubles that overflow when multiplied, NaN-producing extremes.
const double kInteresting[] = {0,
                               -1,
                               1,
                               2,
                               3,
                               4,
                               12,
                               255,
                               256,
                               65535,
                               65536,
                               2147483647,
                               2147483648,
                               4294967295,
                               4294967296,
                               9007199254740993.0,
                               9.2233720368547758e18,
                               1.8446744073709552e19,
                               1e15,
                               1e16,
                               1e300,
                               -1e300,
                               1e308,
                               5e-324,
                               0.5};

// Every value of the tree, depth first (the tree is bounded: inputs deeper than
// kMaxJsonDepth are not parsed).
void collect(Json& v, std::vector<Json*>& out) {
    out.push_back(&v);
    if (v.is_structured())
        for (auto& child : v) collect(child, out);
}

// One structural edit of the tree: a number replaced by an interesting one, a value wrapped
// in deep nesting, an array element duplicated, a key renamed to a long one, a string replaced
// by the name of an indirect file (fuzz/targets.h: FIFOs, /dev/zero links, folders).
bool mutateTree(Json& doc, std::mt19937& rng) {
    std::vector<Json*> values;
    collect(doc, values);
    if (values.empty()) return false;
    Json& v = *values[rng() % values.size()];
    switch (rng() % 6) {
        case 0:
        case 1:
            if (!v.is_number()) return false;
            v = kInteresting[rng() % std::size(kInteresting)];
            if (rng() % 2 && v.get<double>() >= 0 && v.get<double>() < 1.8e19) v = std::uint64_t(v.get<double>());
            return true;
        case 2: {  // just past the nesting limit, or just under it
            const int depth = shadowlab::scene::kMaxJsonDepth - 2 + int(rng() % 4);
            for (int i = 0; i < depth; ++i) v = Json::array({v});
            return true;
        }
        case 3:
            if (!v.is_array() || v.empty()) return false;
            v.push_back(v[rng() % v.size()]);
            return true;
        case 4:
            if (!v.is_object() || v.empty()) return false;
            v[std::string(1000 + rng() % 1000, 'k')] = v.begin().value();
            return true;
        default: {
            static const char* kNames[] = {"pipe.bin", "zero.bin", "dir.bin",  "tri.bin",  "pipe.obj",  "zero.obj",
                                           "dir.obj",  "tri.obj",  "pipe.png", "zero.png", "pipe.gltf", "tri.mtl"};
            if (!v.is_string()) return false;
            v = kNames[rng() % std::size(kNames)];
            return true;
        }
    }
}

bool jsonTarget(const std::uint8_t* data, size_t size) {
    const std::string_view target = SHADOWLAB_FUZZ_TARGET;
    return target == "scene_json" || (target == "gltf" && !(size >= 4 && std::memcmp(data, "glTF", 4) == 0));
}

}  // namespace

extern "C" size_t LLVMFuzzerCustomMutator(std::uint8_t* data, size_t size, size_t maxSize, unsigned seed) {
    std::mt19937 rng(seed);
    if (jsonTarget(data, size) && rng() % 2) {
        const std::string_view text(reinterpret_cast<const char*>(data), size);
        if (shadowlab::scene::jsonNestingProblem(text).empty()) {
            Json doc = Json::parse(text, nullptr, false);
            if (!doc.is_discarded())
                for (int tries = 0; tries < 8; ++tries)
                    if (mutateTree(doc, rng)) {
                        const std::string out = doc.dump();
                        if (out.size() > maxSize) break;
                        std::memcpy(data, out.data(), out.size());
                        return out.size();
                    }
        }
    }
    return LLVMFuzzerMutate(data, size, maxSize);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace shadowlab::fuzz;
    const auto file = writeInput(data, size, inputName(SHADOWLAB_FUZZ_TARGET, data, size));
    expectCleanOutcome([&] { readAs(SHADOWLAB_FUZZ_TARGET, file); });
    return 0;
}
