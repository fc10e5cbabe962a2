#!/usr/bin/env bash
# tools/real-gpu-bundle.sh: packs what tools/real-gpu-check.sh runs into DEST (default
# build/real-gpu), for a machine that has a GPU and its Vulkan driver but not Debian 12's packages
# (a lent accelerator machine, a colleague's workstation): the shadowlab binary and the Vulkan test
# binaries with every shared library they load (glibc's own excepted), Debian's Vulkan loader and
# validation layer, glvnd's packages, and the models of ../shared/scenes the check renders.
# Libraries OpenImageIO links for formats shadowlab never reads are replaced by stubs
# (tools/stub_library.py): the whole set is about 380 MB, the stubbed one about 100 MB, 28 MB as xz.
# Usage: tools/real-gpu-bundle.sh [DEST]    (after a build in build/)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SHADOWLAB_BUILD_DIR:-$root/build}"
dest="${1:-$build/real-gpu}"
say() { echo "real-gpu bundle: $*" >&2; }
binaries=("$build/app/shadowlab" "$build/tests/raster/raster_tests" "$build/tests/raster/raster_reference_tests"
          "$build/tests/backends/alpha_render_tests" "$build/tests/backends/normal_render_tests")
for b in "${binaries[@]}"; do [ -x "$b" ] || { say "$b is not built; build first (cmake --build build)"; exit 2; }; done

# What the renders and tests call: image formats, the C++ runtime, TBB, the model loaders. The
# C++ runtime and glvnd stay out: the target's are newer and its GPU driver needs them.
keep='^lib(OpenImageIO|OpenImageIO_Util|OpenEXR|OpenEXRCore|Iex|IlmThread|Imath|png16|z|jpeg|tiff|tbb|deflate|zstd|lzma|webp|jbig|Lerc|shadowlab|tinygltf|tinyobjloader|meshoptimizer|boost|bz2|X11|OpenColorIO|yaml|expat|pystring|gomp)[-._]'
skip='^(libc|libm|libpthread|libdl|librt|libresolv|ld-linux-x86-64|libstdc\+\+|libgcc_s|libGLX|libGLdispatch)\.so'

work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bin" "$work/lib" "$work/layer" "$work/scenes"
cp "${binaries[@]}" "$work/bin/"
for b in "${binaries[@]}"; do ldd "$b" | awk '/=> \// {print $1, $3}'; done | sort -u | while read -r name path; do
    [[ $name =~ $skip ]] && continue
    if [[ $(stat -Lc %s "$path") -gt 300000 && ! $name =~ $keep ]]; then
        python3 "$root/tools/stub_library.py" "$path" "$work/lib/$name"
    else
        cp -L "$path" "$work/lib/$name"
    fi
done
cp -L /usr/lib/x86_64-linux-gnu/libvulkan.so.1 "$work/lib/"
cp -L /usr/lib/x86_64-linux-gnu/libVkLayer_khronos_validation.so "$work/layer/"
sed 's#"library_path": "libVkLayer_khronos_validation.so"#"library_path": "./libVkLayer_khronos_validation.so"#' \
    /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json >"$work/layer/VkLayer_khronos_validation.json"
# glvnd, which NVIDIA's Vulkan driver loads through and a bare image may lack; real-gpu-check.sh
# unpacks these into / only where the machine has none of its own.
mkdir -p "$work/debs"
(cd "$work/debs" && apt-get download libglvnd0 libglx0 libegl1 >/dev/null 2>&1) || say "glvnd packages not downloaded (apt-get download failed); the target must have its own"
# The test binaries read scenes below the source folder they were built from.
mkdir -p "$work/source"; cp -r "$root/scenes" "$work/source/"; echo "$root" >"$work/source_dir"
for m in Sponza AlphaBlendModeTest FlightHelmet; do
    [ -d "$root/../shared/scenes/$m" ] && cp -r "$root/../shared/scenes/$m" "$work/scenes/"
done
mkdir -p "$dest"
tar -C "$work" -cf - . | xz -6 -T2 >"$dest/bundle.tar.xz.tmp" && mv "$dest/bundle.tar.xz.tmp" "$dest/bundle.tar.xz"
cp "$root/tools/real-gpu-check.sh" "$dest/"
say "wrote $dest/bundle.tar.xz ($(du -h "$dest/bundle.tar.xz" | cut -f1)) and $dest/real-gpu-check.sh"
