#!/usr/bin/env bash
# tools/sanitize.sh: builds the project with AddressSanitizer + UndefinedBehaviorSanitizer (GCC)
# into build-asan/ and runs the whole suite under ctest. Any sanitizer report fails its test
# (halt_on_error, and UBSan made fatal). Extra arguments go to ctest (e.g. -R Scene).
# Usage: tools/sanitize.sh [ctest args...]   (see docs/reliability.md)
#        tools/sanitize.sh --quick             the parsers and the ray tracer only (scene_tests and
#                                              raytrace_tests): what CI runs, a few minutes
set -euo pipefail
quick=0
if [ "${1:-}" = "--quick" ]; then quick=1; shift; fi
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SHADOWLAB_ASAN_BUILD_DIR:-$root/build-asan}"
"$root/tools/setup.sh" --packages-only
if [ ! -f "$build/build.ninja" ]; then
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer" \
        -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
        -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" >&2
fi
if [ "$quick" = 1 ]; then
    cmake --build "$build" -j "$(nproc)" --target scene_tests raytrace_tests >&2
else
    cmake --build "$build" -j "$(nproc)" >&2
fi
# Leaks are reported by LeakSanitizer at exit; Mesa's llvmpipe, the Vulkan loader and the
# validation layer keep a few process-lifetime allocations that are not ours (tools/lsan.supp).
# The loader dlclose()s the driver and the layer before LeakSanitizer runs, which leaves their
# frames as "<unknown module>" that no suppression can name; preloading them keeps them mapped.
preload=""
for lib in libvulkan.so.1 libvulkan_lvp.so libVkLayer_khronos_validation.so; do
    # (no early exit in awk: with pipefail, ldconfig's SIGPIPE would end the script)
    path=$(ldconfig -p | awk -v l="$lib" '$1 == l && !found {print $NF; found = 1}' || true)
    [ -n "$path" ] && preload="$preload $path"
done
export LD_PRELOAD="${preload# }"
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=0:detect_leaks=1:verify_asan_link_order=0"
export LSAN_OPTIONS="suppressions=$root/tools/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd "$build"
if [ "$quick" = 1 ]; then
    tests/scene/scene_tests --gtest_brief=1
    exec tests/raytrace/raytrace_tests --gtest_brief=1
fi
exec ctest --output-on-failure -j "$(nproc)" --timeout 1200 "$@"
