// scene/frame_io.h: Frames to and from disk with OpenImageIO. `.exr` holds every AOV and the
// metadata; `.png` holds the sRGB-encoded beauty only. Writes go to a temporary name in the
// same folder and are renamed into place, so a reader never sees a torn file.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "scene/frame.h"

namespace shadowlab::scene {

// An EXR needs every AOV (beauty, visibility, object id, N·L, Z; blocker ids and per-light
// visibility when present); a frame rendered with fewer channels is std::invalid_argument.
void writeFrame(const Frame& frame, const std::filesystem::path& file);
// The EXR channel of light `light`'s visibility: "visibility.<light>".
std::string lightVisibilityChannel(std::size_t light);
// Throws InputError naming the file and what is wrong (missing channel, unreadable...).
Frame readFrame(const std::filesystem::path& file);

// An 8-bit sRGB PNG from linear RGB floats (3 per pixel), written atomically.
void writePngLinear(const std::filesystem::path& file, int width, int height,
                    const std::vector<float>& linearRgb);
// An 8-bit PNG from already display-encoded RGB floats in 0..1 (diff images, plots).
void writePngDisplay(const std::filesystem::path& file, int width, int height,
                     const std::vector<float>& rgb);

// Writes `text` to `file` through a temporary name and a rename.
void writeTextAtomic(const std::filesystem::path& file, const std::string& text);

float linearToSrgb(float linear);

}  // namespace shadowlab::scene
