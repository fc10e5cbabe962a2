// scene/mask_io.h: another engine's shadows as a method frame: a shadow mask read from an image
// (an EXR channel chosen by name, or a single-channel PNG/EXR), placed over a shadowlab reference
// Frame, which supplies the object ids, N·L and depths (docs/external-masks.md is the contract).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scene/frame.h"

namespace shadowlab::scene {

struct MaskOptions {
    std::optional<std::string> channel;         // the channel to read; none: the file must have exactly one
    bool invert = false;                        // the file stores 1 = shadowed, 0 = lit
    bool srgb = false;                          // values are sRGB-encoded (decoded to linear before use)
    int expectedWidth = 0, expectedHeight = 0;  // the reference's size, checked before the values; 0: any
};

struct ShadowMask {
    int width = 0, height = 0;
    std::vector<float> visibility;  // 0..1, 1 = fully lit, row 0 on top
    std::string channel;            // the channel read
};

// True when `file` is not a Frame, so a mask: a PNG, or an EXR with one channel (whatever its
// name) or without a Frame's "visibility" and "object_id" channels. False for a file that cannot
// be opened (readFrame then says why).
bool looksLikeMask(const std::filesystem::path& file);

// Throws InputError unless `file` is a .png or an .exr, the formats a mask is read from.
void checkMaskFileType(const std::filesystem::path& file);

// Throws InputError naming the file and what is wrong: unreadable, no such channel (listing the
// channels), several channels and none chosen, a value outside 0..1 or not finite (its pixel).
ShadowMask readShadowMask(const std::filesystem::path& file, const MaskOptions& options);

// The reference with its visibility replaced by the mask's: ids, N·L, depth and beauty are the
// reference's, so every pixel counts where the reference's does; no blocker ids, per-light
// visibility or camera attributes (the mask carries none). Throws InputError on a size mismatch.
Frame frameFromMask(const ShadowMask& mask, const Frame& reference, const std::filesystem::path& maskFile);

}  // namespace shadowlab::scene
