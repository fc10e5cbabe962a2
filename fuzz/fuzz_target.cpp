// fuzz/fuzz_target.cpp: the libFuzzer entry point, built once per target with
// SHADOWLAB_FUZZ_TARGET naming it ("scene_json", "obj", "gltf", "exr"; fuzz/targets.h says what
// each reads).
#include "fuzz/fuzz_input.h"
#include "fuzz/targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace shadowlab::fuzz;
    const auto file = writeInput(data, size, inputName(SHADOWLAB_FUZZ_TARGET, data, size));
    expectCleanOutcome([&] { readAs(SHADOWLAB_FUZZ_TARGET, file); });
    return 0;
}
