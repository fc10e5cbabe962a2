#!/usr/bin/env bash
# tools/sanitize.sh: builds the project with AddressSanitizer + UndefinedBehaviorSanitizer (GCC)
# into build-asan/ and runs the whole suite under ctest. Any sanitizer report fails its test
# (halt_on_error, and UBSan made fatal). Extra arguments go to ctest (e.g. -R Scene).
# Usage: tools/sanitize.sh [ctest args...]   (see docs/reliability.md)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SHADOWLAB_ASAN_BUILD_DIR:-$root/build-asan}"
"$root/tools/setup.sh" --packages-only
if [ ! -f "$build/build.ninja" ]; then
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer" \
        -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
        -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" >&2
fi
cmake --build "$build" -j "$(nproc)" >&2
# Leaks are reported by LeakSanitizer at exit; Mesa's llvmpipe keeps a few process-lifetime
# allocations (its JIT and shader cache) that are not ours, listed in tools/lsan.supp.
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=0:detect_leaks=1:strict_string_checks=1"
export LSAN_OPTIONS="suppressions=$root/tools/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd "$build"
exec ctest --output-on-failure -j "$(nproc)" --timeout 1200 "$@"
