#!/usr/bin/env bash
# tools/real-gpu-check.sh: the raster backend on a real GPU's Vulkan driver, with the validation
# layer on every render. Two halves:
#   on the GPU machine, beside bundle.tar.xz from tools/real-gpu-bundle.sh:
#     real-gpu-check.sh run OUT     unpacks, lists the devices, runs `shadowlab run` (seed, Sponza)
#                                   and `render --backend raster` (seed, AlphaBlendModeTest,
#                                   FlightHelmet), then every Vulkan test in its own process (a crash
#                                   names its test); writes OUT/summary.txt, logs and the EXR masks
#   here, with lavapipe:
#     real-gpu-check.sh compare OUT renders the same frames on lavapipe and counts the pixels whose
#                                   visibility differs from the GPU's by more than 0.25
# The GPU's ICD is taken from VK_DRIVER_FILES, else the first NVIDIA, AMD or Intel manifest found,
# so that lavapipe, where installed there too, is not chosen. Devices.ThisMachineHasLavapipeAsTheDefault
# fails there by design (docs/raster.md, "On a real GPU").
set -uo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
say() { echo "real-gpu check: $*" >&2; }
[ $# -eq 2 ] || { say "usage: real-gpu-check.sh run|compare OUT"; exit 2; }
mode=$1; out=$(realpath -m "$2")
# Each a `render --backend raster` whose frame compare checks against lavapipe's: the default path,
# the alpha-tested and blended casters, the transmittance map, the moment maps and PCSS, the
# cascades of a large ground, and grazing light at far coordinates.
renders=("seed-render:render seed" "alpha-render:render ../shared/scenes/AlphaBlendModeTest/AlphaBlendModeTest.gltf"
         "helmet-render:render ../shared/scenes/FlightHelmet/FlightHelmet.gltf"
         "panes-render:render stacked-panes" "foliage-render:render foliage"
         "msm-render:render seed --filter msm" "evsm4-render:render seed --filter evsm4"
         "pcss-render:render scenes/lesson/spot-light.json --filter pcss"
         "ground-render:render scenes/extreme/large-ground-low-sun.json"
         "far-render:render scenes/extreme/far-1e7.json")

if [ "$mode" = compare ]; then
    root="$(cd "$here/.." && pwd)"; s="${SHADOWLAB_BUILD_DIR:-$root/build}/app/shadowlab"
    mkdir -p "$out/lavapipe"
    for r in "${renders[@]}" "sponza-run:render ../shared/scenes/Sponza/Sponza.gltf"; do
        name=${r%%:*}; [ "$name" = sponza-run ] && gpu=$out/sponza/raster.exr || gpu=$out/$name.exr
        [ -f "$gpu" ] || { say "$gpu missing"; continue; }
        # shellcheck disable=SC2086  # the render's words
        (cd "$root" && "$s" ${r#*:} --backend raster -o "$out/lavapipe/$name.exr" >/dev/null 2>&1) ||
            { say "$name failed on lavapipe"; continue; }
        read -r w h < <(oiiotool --info "$gpu" | awk '{gsub(",", ""); print $3, $5}')
        mean=$(oiiotool "$out/lavapipe/$name.exr" --ch visibility "$gpu" --ch visibility --absdiff --subc 0.25 \
               --clamp:min=0 --mulc 1e9 --clamp:max=1 --printstats 2>&1 | awk '/Stats Avg/ {print $3}')
        echo "$name: $(awk -v m="$mean" -v n=$((w * h)) 'BEGIN {printf "%d of %d pixels", m * n + 0.5, n}') differ by more than 0.25 in visibility"
    done
    exit 0
fi
[ "$mode" = run ] || { say "unknown mode $mode"; exit 2; }

b=$(mktemp -d); mkdir -p "$out/logs"
tar -C "$b" -xJf "$here/bundle.tar.xz" || { say "cannot unpack $here/bundle.tar.xz"; exit 2; }
src=$(cat "$b/source_dir")
if [ ! -e "$src" ]; then mkdir -p "$(dirname "$src")" && ln -s "$b/source" "$src"; fi
if [ ! -e "$src/../shared/scenes" ]; then mkdir -p "$src/../shared" && ln -s "$b/scenes" "$src/../shared/scenes"; fi
if ! ldconfig -p | grep -q libGLdispatch.so.0 && [ "$(id -u)" = 0 ]; then
    for deb in "$b"/debs/*.deb; do [ -f "$deb" ] && dpkg -x "$deb" /; done
    ldconfig
fi
export LD_LIBRARY_PATH="$b/lib" VK_LAYER_PATH="$b/layer" SHADOWLAB_SCENES="$src/scenes"
s="$b/bin/shadowlab"
if [ -z "${VK_DRIVER_FILES:-}" ]; then
    # The first manifest, lavapipe's excepted, whose driver finds a device here.
    for icd in /usr/local/nvidia/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json /usr/share/vulkan/icd.d/*.json; do
        [[ -f $icd && $icd != *lvp* ]] || continue
        VK_DRIVER_FILES=$icd "$s" info 2>/dev/null | grep -q "usable by the raster backend: yes" &&
            { export VK_DRIVER_FILES=$icd; break; }
    done
    [ -n "${VK_DRIVER_FILES:-}" ] || { say "no Vulkan driver but lavapipe finds a device; set VK_DRIVER_FILES"; exit 1; }
fi
quiet() { grep -v "no version information available"; }  # stubbed libraries carry no version table
{
    echo "ICD: ${VK_DRIVER_FILES:-(loader default)}"
    "$s" info --validate 2>&1 | quiet
} | tee "$out/summary.txt"
grep -q "usable by the raster backend: yes" "$out/summary.txt" || { say "no usable device"; exit 1; }

step() {
    local name=$1; shift; local t0; t0=$(date +%s%N)
    (cd "$src" && "$@") >"$out/logs/$name.log" 2>&1; local rc=$?
    echo "$name: exit $rc, $(( ($(date +%s%N) - t0) / 1000000 )) ms" | tee -a "$out/summary.txt"
}
step seed-run "$s" run seed --validate -o "$out/seed"  # with its default sweep: many renders, one device
step sponza-run "$s" run ../shared/scenes/Sponza/Sponza.gltf --validate --no-sweep -o "$out/sponza"
for r in "${renders[@]}"; do step "${r%%:*}" "$s" ${r#*:} --backend raster --validate -o "$out/${r%%:*}.exr"; done

one() {
    local bin=$1 test=$2 log="$3/logs/${1}__${2//\//_}.log"
    (cd "$4" && timeout 120 "$5/bin/$bin" --gtest_filter="$test") >"$log" 2>&1
    local rc=$?; [ $rc -eq 0 ] && { echo "ok $bin $test"; rm -f "$log"; } || echo "FAIL $bin $test (exit $rc)"
}
export -f one
for bin in raster_tests raster_reference_tests alpha_render_tests normal_render_tests; do
    "$b/bin/$bin" --gtest_list_tests 2>/dev/null | awk -v bin="$bin" '/^[^ ]/ {suite = $1} /^  / {print bin, suite $1}'
done | xargs -P "$(nproc)" -L 1 bash -c 'one "$0" "$1" "'"$out"'" "'"$src"'" "'"$b"'"' | sort >"$out/tests.txt"
echo "tests: $(grep -c '^ok' "$out/tests.txt") passed, $(grep -c '^FAIL' "$out/tests.txt") failed" | tee -a "$out/summary.txt"
grep '^FAIL' "$out/tests.txt" | tee -a "$out/summary.txt"
rm -rf "$b"
