#!/usr/bin/env bash
# tools/fuzz.sh: builds the libFuzzer targets of fuzz/ with clang (AddressSanitizer +
# UndefinedBehaviorSanitizer) into build-fuzz/ and runs them.
#
#   tools/fuzz.sh [SECONDS] [TARGET...]     default: 60 s each, all of scene_json obj ply gltf exr
#
# Each target starts from the committed seed corpus fuzz/corpus/TARGET (with fuzz/dict/TARGET.dict,
# the tokens of its format and values that break size arithmetic) and keeps what it learns in
# build-fuzz/corpus/TARGET (reused by later runs). Crashing inputs land in
# build-fuzz/findings/TARGET/; copy each into tests/scene/fuzz_regressions/TARGET/ once fixed, where
# FuzzRegression.* replays it in the normal suite. A summary line per target (executions, new
# coverage, findings) goes to build-fuzz/fuzz-summary.txt. See docs/reliability.md.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(scene_json obj ply gltf exr)
build="${SHADOWLAB_FUZZ_BUILD_DIR:-$root/build-fuzz}"

"$root/tools/setup.sh" --packages-only
# clang and its libFuzzer runtime are needed only here, not for the normal build.
if ! command -v clang++ >/dev/null || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
    if [ "$(id -u)" -ne 0 ]; then
        echo "tools/fuzz.sh: clang and libFuzzer are missing; run as root or: apt-get install clang" >&2
        exit 1
    fi
    apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q clang >&2
fi

flags="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g"
if [ ! -f "$build/build.ninja" ]; then
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DCMAKE_CXX_COMPILER=clang++ -DSHADOWLAB_TESTS=OFF -DSHADOWLAB_FUZZ=ON \
        -DCMAKE_CXX_FLAGS="$flags" \
        -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >&2
fi
cmake --build "$build" -j "$(nproc)" --target $(printf '%s_fuzz ' "${targets[@]}") >&2

export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0
for t in "${targets[@]}"; do
    mkdir -p "$build/corpus/$t" "$build/findings/$t"
    log="$build/fuzz-$t.log"
    echo "fuzz: $t for ${seconds}s (log: $log)" >&2
    # -rss_limit_mb / -malloc_limit_mb: a loader that believes a "2 GB buffer" declared in a file
    # and allocates it is a finding, not an out-of-memory on the machine.
    set +e
    dict=()
    [ -f "$root/fuzz/dict/$t.dict" ] && dict=(-dict="$root/fuzz/dict/$t.dict")
    "$build/fuzz/${t}_fuzz" "$build/corpus/$t" "$root/fuzz/corpus/$t" "${dict[@]}" \
        -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 \
        -max_len=262144 -print_final_stats=1 -artifact_prefix="$build/findings/$t/" >"$log" 2>&1
    rc=$?
    set -e
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1 || echo "?")
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo "?")
    found=$(find "$build/findings/$t" -type f | wc -l)
    line="$(date -u +%FT%TZ) $t: ${seconds}s, $execs executions, coverage $cov edges, exit $rc, $found finding(s) in $build/findings/$t"
    echo "$line" | tee -a "$build/fuzz-summary.txt" >&2
    [ "$rc" -ne 0 ] && status=1
done
exit $status
