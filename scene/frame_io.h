// scene/frame_io.h: Frames to and from disk with OpenImageIO. `.exr` holds every AOV and the
// metadata; `.png` holds the sRGB-encoded beauty only. Writes go to a temporary name in the
// same folder and are renamed into place, so a reader never sees a torn file.
#pragma once

#include <cstdint>
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
// `exposure` multiplies the linear values before encoding (displayExposure).
void writePngLinear(const std::filesystem::path& file, int width, int height, const std::vector<float>& linearRgb,
                    double exposure = 1.0);
// The factor that keeps a report's images readable under bright lights: 1, or where more than 1%
// of the frame's visible surface would clip to white, the one that puts that 99th percentile of
// luminance at 1. (A glTF point light of tens of thousands of candela washed out every object and
// shadow; one factor from the reference is used for every image of a report, so they compare.)
double displayExposure(const Frame& frame);
// An 8-bit PNG from already display-encoded RGB floats in 0..1 (diff images, plots).
void writePngDisplay(const std::filesystem::path& file, int width, int height, const std::vector<float>& rgb);

// Writes `text` to `file` through a temporary name and a rename.
void writeTextAtomic(const std::filesystem::path& file, const std::string& text);

// A fresh temporary name beside `file` (".stem.tmp-PID-TOKEN-N.ext", temporaryTag in interrupt.h),
// the scheme every atomic write here uses; a folder gets the same kind of name. Notes the folder
// for removeTemporariesOnInterrupt.
std::filesystem::path temporarySibling(const std::filesystem::path& file);

// Removes the temporaries in `dir` (files or folders named as above) whose writing process is
// gone: what a kill in the middle of an atomic write leaves behind.
void removeStaleTemporaries(const std::filesystem::path& dir);

// Puts the folder `fresh` in place of `target` in one atomic step (Linux renameat2 with
// RENAME_EXCHANGE when `target` exists, then the old one is removed): a reader sees the old
// folder or the new one, never neither nor a mix.
void replaceDirectory(const std::filesystem::path& fresh, const std::filesystem::path& target);

float linearToSrgb(float linear);
// The 8-bit code the PNG writers give a linear value (NaN and infinities as 0).
std::uint8_t linearToSrgbCode(float linear);
// A linear value whose sRGB code (linearToSrgbCode) is `code`: the exact inverse of the sRGB curve
// at code/255, moved by the fewest float steps needed when rounding would give a neighbouring code.
// For frames whose beauty comes from an 8-bit sRGB target (kBeautyForDisplay).
float srgbCodeToLinear(std::uint8_t code);

}  // namespace shadowlab::scene
