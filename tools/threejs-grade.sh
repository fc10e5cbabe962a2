#!/usr/bin/env bash
# tools/threejs-grade.sh: grades three.js's shadows (the npm package three pinned by
# tools/browser/package-lock.json, WebGLRenderer with PCFShadowMap, PCFSoftShadowMap and
# VSMShadowMap) against shadowlab's reference, end to end (docs/threejs.md):
#   1. `shadowlab export SCENE -o OUT/scene.glb`, validated with tools/gltf-validate.sh;
#   2. `shadowlab render OUT/scene.glb --backend reference` (and `--backend raster`, for comparison);
#   3. tools/browser/threejs-grade.mjs loads the .glb with three's GLTFLoader in headless Chromium
#      (software WebGL: SwiftShader) and writes OUT/threejs-TYPE.png, one shadow mask per type,
#      and OUT/threejs-coverage.png (where three.js sees a mesh);
#   4. the silhouette check: three's coverage against the reference's object_id > 0 (oiiotool),
#      at most 0.5% of the pixels may differ (OUT/silhouette-diff.png): the cameras agree;
#   5. `shadowlab compare` of each mask (and of the raster) with the reference: OUT/diff-TYPE.png,
#      OUT/TYPE.json, and one summary line each.
# Installs chromium, nodejs and npm with apt-get when missing (as root) and the npm packages into
# $SHADOWLAB_NODE_DIR (default BUILD/node) as tools/browser-check.sh does. $SHADOWLAB_EXE names the
# shadowlab binary (default BUILD/app/shadowlab).
# Usage: tools/threejs-grade.sh SCENE [OUT] [--resolution WxH]   (OUT default BUILD/threejs-grade/NAME)
# Exit: 0 the silhouettes agree, 1 they do not (or the export has glTF validator errors),
#       2 bad usage or set-up, or a step that failed.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SHADOWLAB_BUILD_DIR:-$root/build}"
node_dir="${SHADOWLAB_NODE_DIR:-$build/node}"
exe="${SHADOWLAB_EXE:-$build/app/shadowlab}"
say() { echo "threejs-grade: $*" >&2; }
usage() { say "usage: tools/threejs-grade.sh SCENE [OUT] [--resolution WxH] [--bias B] [--normal-bias N] [--map-size N]"; exit 2; }

command="tools/threejs-grade.sh$(printf ' %q' "$@")"
scene="" out="" res=() three=()
while [ $# -gt 0 ]; do
    case "$1" in
        --resolution) [ $# -ge 2 ] || usage; res=(--resolution "$2"); shift 2 ;;
        --bias|--normal-bias|--map-size) [ $# -ge 2 ] || usage; three+=("$1" "$2"); shift 2 ;;
        -*) usage ;;
        *) if [ -z "$scene" ]; then scene="$1"; elif [ -z "$out" ]; then out="$1"; else usage; fi; shift ;;
    esac
done
[ -n "$scene" ] || usage
# Numbers are checked here, before anything renders (the browser script checks them again).
for ((i = 0; i < ${#three[@]}; i += 2)); do
    if [ "${three[i]}" = --map-size ]; then pattern='^[1-9][0-9]*$'; else pattern='^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$'; fi
    [[ "${three[i+1]}" =~ $pattern ]] || { say "error: ${three[i]}: not a number: ${three[i+1]}"; exit 2; }
done
[ -x "$exe" ] || { say "error: $exe is not an executable (build shadowlab, or set SHADOWLAB_EXE)"; exit 2; }
command -v oiiotool >/dev/null || { say "error: oiiotool missing (Debian package openimageio-tools)"; exit 2; }
out="${out:-$build/threejs-grade/$(basename "${scene%.json}")}"
mkdir -p "$out"

. "$root/tools/browser/install.sh"
browser_tools_install

"$exe" export "$scene" -o "$out/scene.glb" >&2 || { say "error: export of $scene failed"; exit 2; }
SHADOWLAB_NODE_DIR="$node_dir" node "$root/tools/browser/gltf-validate.mjs" "$out/scene.glb" >&2 ||
    { say "error: $out/scene.glb has glTF validator errors"; exit 1; }
"$exe" render "$out/scene.glb" --backend reference "${res[@]}" -o "$out/reference.exr" >&2 ||
    { say "error: the reference render failed"; exit 2; }
"$exe" render "$out/scene.glb" --backend raster "${res[@]}" -o "$out/raster.exr" >&2 ||
    { say "error: the raster render failed"; exit 2; }
SHADOWLAB_NODE_DIR="$node_dir" node "$root/tools/browser/threejs-grade.mjs" "$out/scene.glb" "$out" "${res[@]}" "${three[@]}" \
    >"$out/threejs.json" || { say "error: the three.js render failed"; exit 2; }
cat "$out/threejs.json"

# Silhouettes: the reference's coverage is object_id > 0 (ids are whole numbers, so clamping to
# [0, 1] gives 0 or 1); a pixel differs when the two coverages differ.
oiiotool "$out/reference.exr" --ch object_id --clamp:min=0:max=1 -d uint8 -o "$out/reference-coverage.png"
oiiotool "$out/threejs-coverage.png" "$out/reference-coverage.png" --absdiff -o "$out/silhouette-diff.png"
total=$(oiiotool --info -v "$out/reference-coverage.png" | sed -n 's/.*: *\([0-9]*\) x *\([0-9]*\),.*/\1 \2/p' | head -1 | awk '{print $1*$2}')
differ=$({ oiiotool "$out/threejs-coverage.png" "$out/reference-coverage.png" --diff 2>&1 || true; } |
    sed -n 's/^ *\([0-9]*\) pixels ([^)]*) over .*/\1/p' | head -1)
differ="${differ:-0}"
rate=$(awk -v d="$differ" -v t="$total" 'BEGIN { printf "%.4f", 100 * d / t }')
echo "silhouette: $differ of $total pixels differ ($rate%; at most 0.5%)"
echo "{\"differ\": $differ, \"total\": $total}" >"$out/silhouette.json"

# Images for the page: the reference's beauty (sRGB) and visibility, and the raster's visibility
# (both linear, 255 = lit, like three's masks).
oiiotool "$out/reference.exr" --ch R,G,B --colorconvert linear sRGB -d uint8 -o "$out/reference.png"
oiiotool "$out/reference.exr" --ch visibility -d uint8 -o "$out/reference-visibility.png"
oiiotool "$out/raster.exr" --ch visibility -d uint8 -o "$out/raster-visibility.png"

for m in PCFShadowMap PCFSoftShadowMap VSMShadowMap raster; do
    if [ "$m" = raster ]; then method="$out/raster.exr"; else method="$out/threejs-$m.png"; fi
    rc=0
    "$exe" compare "$method" "$out/reference.exr" -o "$out/diff-$m.png" --heat "$out/heat-$m.png" --json >"$out/$m.json" || rc=$?
    [ "$rc" -le 1 ] || { say "error: compare of $method failed (exit $rc)"; exit 2; }
    node -e '
        const m = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8"));
        const pc = (v) => (100 * v).toFixed(2) + "%";
        console.log(`${process.argv[2]}: mismatch ${pc(m.mismatch_rate)}, false shadow ${pc(m.false_shadow_rate)}, ` +
                    `missed shadow ${pc(m.missed_shadow_rate)}, mean |dV| ${m.mean_abs_visibility_error.toFixed(4)}, ` +
                    `shadow IoU ${m.shadow_iou.toFixed(3)} (${m.counted} pixels counted)`);' "$out/$m.json" "$m"
done

version="$("$exe" --version)"
if commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null); then
    git -C "$root" diff --quiet HEAD 2>/dev/null || commit="$commit with local changes"
    version="$version, commit $commit"
fi
node "$root/tools/browser/threejs-report.mjs" "$out" --scene "$scene" --command "$command" --shadowlab "$version" ||
    { say "error: the report page failed"; exit 2; }
echo "report: $out/report.html"
awk -v d="$differ" -v t="$total" 'BEGIN { exit !(d <= 0.005 * t) }' ||
    { say "silhouettes differ on more than 0.5% of the pixels: the cameras disagree"; exit 1; }
