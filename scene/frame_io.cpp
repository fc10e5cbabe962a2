// scene/frame_io.cpp: EXR/PNG Frame I/O with OpenImageIO, always through a temporary file
// and a rename so an interrupted write never leaves a torn file behind.
#include "scene/frame_io.h"

#include <fcntl.h>
#include <unistd.h>
#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <system_error>

#include <OpenImageIO/imageio.h>

#include "scene/error.h"
#include "scene/input_file.h"
#include "scene/interrupt.h"
#include "scene/loader.h"

namespace shadowlab::scene {

namespace {

namespace fs = std::filesystem;
using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

constexpr const char* kAttrPrefix = "shadowlab:";
constexpr const char* kTimingsAttr = "shadowlab:timings_ms";

// Checks an OpenEXR header's structure before OpenEXR reads it: OpenEXR 3.1 believes the size an
// attribute declares and allocates it (a 1.6 GB "opaque attribute" in a 2 kB file, found by
// fuzzing). Layout from "The OpenEXR File Layout" (openexr.com): magic 20000630, a version word
// (bit 9: single-part tiled, bit 11: deep data, bit 12: multi-part), then attributes (name\0
// type\0 int32 size, value) until an empty name. A Frame is a single-part scanline or tiled
// (possibly mip-mapped: level 0 is read) image; deep and multi-part files are refused.
void checkExrHeader(const fs::path& file) {
    const auto fileSize = static_cast<std::int64_t>(checkInputFile(file, kMaxFrameFileBytes));
    std::ifstream in(file, std::ios::binary);
    auto readU32 = [&](std::uint32_t& v) {
        unsigned char b[4];
        if (!in.read(reinterpret_cast<char*>(b), 4)) return false;
        v = b[0] | (b[1] << 8) | (b[2] << 16) | (std::uint32_t(b[3]) << 24);
        return true;
    };
    std::uint32_t magic = 0, version = 0;
    if (!readU32(magic) || magic != 20000630u)
        throw InputError(file.string() +
                         ": not an OpenEXR file, so it has no 'visibility' channel "
                         "(missing channel 'visibility': is this a Frame written by "
                         "`shadowlab render -o X.exr`?)");
    auto bad = [&](const std::string& what) { return InputError(file.string() + ": damaged OpenEXR header: " + what); };
    if (!readU32(version)) throw bad("truncated");
    if (version & 0x1800u)
        throw InputError(file.string() + ": a " + ((version & 0x1000u) ? "multi-part" : "deep") +
                         " OpenEXR file is not a Frame (a Frame is one part of flat scanline or tiled pixels, as "
                         "`shadowlab render -o X.exr` writes it)");
    const std::size_t maxName = (version & 0x400u) ? 255 : 31;
    auto readName = [&](std::string& name) {
        name.clear();
        for (char c; in.get(c);) {
            if (c == '\0') return true;
            if (name.size() == maxName)
                throw bad("an attribute name is longer than " + std::to_string(maxName) + " bytes");
            name.push_back(c);
        }
        throw bad("truncated");
    };
    auto printable = [](std::string t) {  // a damaged name may hold any byte
        for (char& ch : t)
            if (ch < 0x20 || ch > 0x7e) ch = '?';
        return t;
    };
    constexpr int kMaxChannels = 32;
    int channels = 0;
    for (int count = 0;; ++count) {
        std::string name, type;
        readName(name);
        if (name.empty()) return;  // the end of the header
        if (count == 10000) throw bad("more than 10000 attributes");
        readName(type);
        std::uint32_t size = 0;
        if (!readU32(size)) throw bad("truncated");
        const std::int64_t start = std::int64_t(in.tellg());
        const std::int64_t end = start + std::int64_t(std::int32_t(size));
        if (std::int32_t(size) < 0 || end > fileSize)
            throw bad("attribute '" + printable(name) + "' declares " + std::to_string(std::int32_t(size)) +
                      " bytes, more than the file holds");
        // OpenEXR reads these by their contents rather than their declared size, so their
        // contents must agree with it (a channel name longer than allowed misaligned the rest
        // of a fuzzed header into another 1.8 GB attribute).
        auto mismatch = [&] {
            return bad("attribute '" + printable(name) + "' (" + printable(type) +
                       ") does not match its declared size");
        };
        // Types of a fixed size, which OpenEXR reads whatever size is declared (a v2f declared as
        // 12 bytes misaligned a fuzzed header). Sizes from OpenEXR's attribute types.
        static const std::map<std::string, std::uint32_t> kFixedSize = {
            {"box2i", 16},      {"box2f", 16},   {"chromaticities", 32},
            {"compression", 1}, {"double", 8},   {"envmap", 1},
            {"float", 4},       {"int", 4},      {"keycode", 28},
            {"lineOrder", 1},   {"m33f", 36},    {"m33d", 72},
            {"m44f", 64},       {"m44d", 128},   {"rational", 8},
            {"tiledesc", 9},    {"timecode", 8}, {"v2i", 8},
            {"v2f", 8},         {"v2d", 16},     {"v3i", 12},
            {"v3f", 12},        {"v3d", 24},     {"deepImageState", 1}};
        if (const auto fixed = kFixedSize.find(type); fixed != kFixedSize.end() && fixed->second != size)
            throw mismatch();
        if (type == "chlist") {
            for (std::string channel;;) {
                readName(channel);
                if (channel.empty()) break;
                if (++channels > kMaxChannels)
                    throw bad("more than " + std::to_string(kMaxChannels) + " channels (a Frame has about ten)");
                char fields[16];  // pixel type, pLinear + 3 reserved bytes, x and y sampling
                if (!in.read(fields, 16) || std::int64_t(in.tellg()) > end) throw mismatch();
            }
            if (std::int64_t(in.tellg()) != end) throw mismatch();
        } else if (name == "dataWindow" && type == "box2i") {
            // The image size, bounded as a render's is before OpenEXR sizes its line buffers from
            // it (a fuzzed 500-byte file made it allocate 1.2 GB for one chunk).
            std::uint32_t box[4];
            for (std::uint32_t& v : box)
                if (!readU32(v)) throw mismatch();
            const std::int64_t w = std::int64_t(std::int32_t(box[2])) - std::int32_t(box[0]) + 1;
            const std::int64_t h = std::int64_t(std::int32_t(box[3])) - std::int32_t(box[1]) + 1;
            if (w < 1 || h < 1 || w > kMaxResolution || h > kMaxResolution || w * h > kMaxPixels)
                throw InputError(file.string() + ": image too large for a Frame (" + std::to_string(w) + "x" +
                                 std::to_string(h) + "; at most " + std::to_string(kMaxResolution) + " a side and " +
                                 std::to_string(kMaxPixels) + " pixels)");
        } else if (type == "tiledesc") {
            // Tile sizes bound the buffers OpenEXR and OpenImageIO allocate for one tile, as the data
            // window bounds a line's (a 0 size would divide by zero when tiles are counted).
            std::uint32_t tw = 0, th = 0;
            if (!readU32(tw) || !readU32(th)) throw mismatch();
            if (tw < 1 || th < 1 || tw > std::uint32_t(kMaxResolution) || th > std::uint32_t(kMaxResolution))
                throw bad("tiles of " + std::to_string(tw) + "x" + std::to_string(th) + " pixels (at most " +
                          std::to_string(kMaxResolution) + " a side)");
        } else if (type == "preview") {  // width, height, then width * height RGBA bytes
            std::uint32_t w = 0, h = 0;
            if (size < 8 || !readU32(w) || !readU32(h) || std::uint64_t(w) * h * 4 + 8 != size) throw mismatch();
        } else if (type == "stringvector") {  // (int32 length, bytes) pairs
            while (std::int64_t(in.tellg()) < end) {
                std::uint32_t length = 0;
                if (!readU32(length) || std::int32_t(length) < 0 || std::int64_t(in.tellg()) + length > end)
                    throw mismatch();
                in.seekg(length, std::ios::cur);
            }
        }
        in.seekg(end);
    }
}

// Frames are read and written a band of this many rows at a time, so that a file costs one band of
// memory beside the Frame.
constexpr int kFrameBandRows = 64;

// OpenEXR's standard camera attributes go by other names inside OpenImageIO, which renames them
// on reading and writing ("worldToCamera" is OIIO's "worldtocamera").
std::optional<std::string> exrStandardToOiio(const std::string& exrName) {
    if (exrName == "worldToCamera") return "worldtocamera";
    if (exrName == "worldToNDC") return "worldtoNDC";
    return std::nullopt;
}
std::optional<std::string> exrStandardFromOiio(const std::string& oiioName) {
    if (oiioName == "worldtocamera" || oiioName == "worldToCamera") return "worldToCamera";
    if (oiioName == "worldtoNDC" || oiioName == "worldToNDC") return "worldToNDC";
    return std::nullopt;
}

// Runs `write(tmp)` and renames tmp onto `file`; removes tmp if anything fails.
template <typename WriteFn>
void writeAtomically(const fs::path& file, WriteFn&& write) {
    const fs::path tmp = temporarySibling(file);
    try {
        write(tmp);
        fs::rename(tmp, file);
    } catch (...) {
        std::error_code ignored;
        fs::remove(tmp, ignored);
        throw;
    }
}

// Opens `tmp` (the temporary name `file` is written under) for an image of `spec`, runs write(out),
// and closes it; each step's failure is an OutputError naming `file`, the name the user gave (the
// temporary is gone by the time the message is read).
template <typename WriteFn>
void writeImageWith(const fs::path& file, const fs::path& tmp, const ImageSpec& spec, WriteFn&& write) {
    auto out = ImageOutput::create(tmp.string());
    if (!out) throw InputError(file.string() + ": cannot write this image format (" + OIIO::geterror() + ")");
    if (!out->open(tmp.string(), spec))
        throw OutputError(file.string() + ": cannot open for writing: " + out->geterror());
    if (!write(*out)) throw OutputError(file.string() + ": write failed: " + out->geterror());
    if (!out->close()) throw OutputError(file.string() + ": close failed: " + out->geterror());
}

void writeImage(const fs::path& file, const fs::path& tmp, const ImageSpec& spec, const void* pixels, TypeDesc type) {
    writeImageWith(file, tmp, spec, [&](ImageOutput& out) { return out.write_image(type, pixels); });
}

std::string encodeTimings(const std::vector<std::pair<std::string, double>>& timings) {
    std::ostringstream s;
    s.precision(17);
    for (std::size_t i = 0; i < timings.size(); ++i)
        s << (i ? ";" : "") << timings[i].first << "=" << timings[i].second;
    return s.str();
}

std::vector<std::pair<std::string, double>> decodeTimings(const std::string& text) {
    std::vector<std::pair<std::string, double>> out;
    std::istringstream s(text);
    std::string item;
    while (std::getline(s, item, ';')) {
        const auto eq = item.find('=');
        if (eq == std::string::npos) continue;
        try {
            out.emplace_back(item.substr(0, eq), std::stod(item.substr(eq + 1)));
        } catch (const std::exception&) {
            // A malformed timing is metadata only: skip it rather than reject the frame.
        }
    }
    return out;
}

void writePng8(const fs::path& file, int width, int height, const std::vector<float>& rgb, bool encodeSrgb) {
    if (rgb.size() != std::size_t(width) * std::size_t(height) * 3)
        throw std::invalid_argument("writePng: pixel count does not match the size");
    std::vector<unsigned char> bytes(rgb.size());
    for (std::size_t i = 0; i < rgb.size(); ++i) {
        float v = rgb[i];
        if (!std::isfinite(v)) v = 0.0f;
        bytes[i] = encodeSrgb ? linearToSrgbCode(v)
                              : static_cast<unsigned char>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
    }
    ImageSpec spec(width, height, 3, TypeDesc::UINT8);
    writeAtomically(file, [&](const fs::path& tmp) { writeImage(file, tmp, spec, bytes.data(), TypeDesc::UINT8); });
}

}  // namespace

fs::path temporarySibling(const fs::path& file) {
    static std::atomic<unsigned> counter{0};
    const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
    noteTemporaryFolder(dir);
    // (appended piece by piece: GCC 12 warns falsely, -Wrestrict, on the chained operator+)
    std::string name = ".";
    name += file.stem().string();
    name += ".tmp-";
    name += temporaryTag();
    name += std::to_string(counter++);
    name += file.extension().string();
    return dir / name;
}

void removeStaleTemporaries(const fs::path& dir) {
    std::error_code ec;
    for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
        const std::string name = it->path().filename().string();
        const auto mark = name.find(".tmp-");
        if (name.empty() || name[0] != '.' || mark == std::string::npos) continue;
        const long pid = std::strtol(name.c_str() + mark + 5, nullptr, 10);
        std::error_code ignored;
        if (pid > 0 && ::kill(pid_t(pid), 0) != 0 && errno == ESRCH) fs::remove_all(it->path(), ignored);
    }
}

void replaceDirectory(const fs::path& fresh, const fs::path& target) {
    if (!fs::exists(target)) {
        fs::rename(fresh, target);
        return;
    }
    if (::renameat2(AT_FDCWD, fresh.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) != 0)
        throw std::system_error(errno, std::generic_category(),
                                "cannot put " + fresh.string() + " in place of " + target.string());
    fs::remove_all(fresh);  // now the old folder
}

std::string lightVisibilityChannel(std::size_t light) { return "visibility." + std::to_string(light); }

float linearToSrgb(float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

std::uint8_t linearToSrgbCode(float linear) {
    if (!std::isfinite(linear)) linear = 0.0f;
    return static_cast<std::uint8_t>(std::lround(std::clamp(linearToSrgb(linear), 0.0f, 1.0f) * 255.0f));
}

float srgbCodeToLinear(std::uint8_t code) {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int k = 0; k < 256; ++k) {
            const double e = k / 255.0;  // IEC 61966-2-1 decoding, in double
            float v = float(e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4));
            // The float encoder rounds differently from the exact curve by a few ulps at most:
            // step toward the code until it is the one encoded (a handful of steps, once).
            for (int guard = 0; guard < 1 << 16 && linearToSrgbCode(v) != k; ++guard)
                v = std::nextafter(v, linearToSrgbCode(v) < k ? 2.0f : -1.0f);
            t[std::size_t(k)] = v;
        }
        return t;
    }();
    return table[code];
}

void writePngLinear(const fs::path& file, int width, int height, const std::vector<float>& rgb, double exposure) {
    if (exposure == 1.0) {
        writePng8(file, width, height, rgb, true);
        return;
    }
    std::vector<float> scaled(rgb.size());
    for (std::size_t i = 0; i < rgb.size(); ++i) scaled[i] = float(double(rgb[i]) * exposure);
    writePng8(file, width, height, scaled, true);
}

double displayExposure(const Frame& frame) {
    std::vector<float> luminance;
    for (std::size_t i = 0; i < frame.pixelCount() && 3 * i + 2 < frame.beauty.size(); ++i)
        if (i < frame.objectId.size() && frame.objectId[i] > 0.0f) {
            const float y =
                0.2126f * frame.beauty[3 * i] + 0.7152f * frame.beauty[3 * i + 1] + 0.0722f * frame.beauty[3 * i + 2];
            if (std::isfinite(y)) luminance.push_back(y);
        }
    if (luminance.empty()) return 1.0;
    const auto p99 = luminance.begin() + std::ptrdiff_t(0.99 * double(luminance.size() - 1));
    std::nth_element(luminance.begin(), p99, luminance.end());
    return *p99 > 1.0f ? 1.0 / double(*p99) : 1.0;
}

void writePngDisplay(const fs::path& file, int width, int height, const std::vector<float>& rgb) {
    writePng8(file, width, height, rgb, false);
}

void writeTextAtomic(const fs::path& file, const std::string& text) {
    writeAtomically(file, [&](const fs::path& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        out << text;
        out.close();
        if (!out) throw OutputError(file.string() + ": cannot write");
    });
}

void writeFrame(const Frame& frame, const fs::path& file) {
    const std::string ext = lowercaseExtension(file);
    if (ext == ".png") {
        writePngLinear(file, frame.width, frame.height, frame.beauty);
        return;
    }
    if (ext != ".exr") throw InputError(file.string() + ": unknown output type '" + ext + "' (use .exr or .png)");

    const bool withBlocker = !frame.blockerId.empty();
    const std::size_t n = frame.pixelCount();
    for (const std::vector<float>* v : {&frame.visibility, &frame.objectId, &frame.ndotl, &frame.depth})
        if (v->size() != n)
            throw std::invalid_argument(file.string() + ": the frame lacks an AOV an EXR needs (rendered for a PNG?)");
    for (const std::vector<float>& v : frame.lightVisibility)
        if (v.size() != n) throw std::invalid_argument(file.string() + ": a per-light visibility has the wrong size");
    const std::size_t lights = frame.lightVisibility.size();
    const bool withDistance = frame.blockerDistance.size() == n;
    const int channels = (withBlocker ? 8 : 7) + int(lights) + (withDistance ? 1 : 0);
    ImageSpec spec(frame.width, frame.height, channels, TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B", "visibility", "object_id", "ndotl", "Z"};
    if (withBlocker) spec.channelnames.push_back("blocker_id");
    // Per-light visibility, light i as "visibility.<i>" (an EXR layer "visibility").
    for (std::size_t l = 0; l < lights; ++l) spec.channelnames.push_back(lightVisibilityChannel(l));
    if (withDistance) spec.channelnames.push_back("blocker_distance");  // last: optional, found by name
    spec.alpha_channel = -1;
    spec.z_channel = 6;
    // Lossless ZIP of one scanline a block at zlib level 1: a 1080p Frame is written in ~0.4 s of
    // CPU instead of ~0.6 s with OpenEXR's default ZIP, 3% larger (docs/performance.md, "run").
    spec.attribute("compression", "zips:1");
    for (const auto& [key, value] : frame.attributes) spec.attribute(kAttrPrefix + key, value);
    spec.attribute(kTimingsAttr, encodeTimings(frame.timingsMs));
    for (const auto& [key, value] : frame.typedAttributes) {
        const std::string name = exrStandardToOiio(key).value_or(kAttrPrefix + key);
        if (const int* i = std::get_if<int>(&value))
            spec.attribute(name, TypeDesc::INT, i);
        else if (const float* f = std::get_if<float>(&value))
            spec.attribute(name, TypeDesc::FLOAT, f);
        else if (const glm::vec3* v = std::get_if<glm::vec3>(&value))
            spec.attribute(name, OIIO::TypeVector, v);
        // GLM's memory order is the transpose of the matrix it means: the row-vector m44f EXR wants.
        else
            spec.attribute(name, OIIO::TypeMatrix44, &std::get<glm::mat4>(value));
    }

    // Interleaved a band of rows at a time: a whole interleaved copy of a 1080p Frame is 66 MB of
    // fresh memory to fault in for each file, and a Frame more at the peak; the file is the same.
    const int firstLight = withBlocker ? 8 : 7;
    const int bandRows = std::min(kFrameBandRows, frame.height);
    std::vector<float> band(std::size_t(frame.width) * std::size_t(bandRows) * std::size_t(channels));
    auto writeBands = [&](ImageOutput& out) {
        for (int y0 = 0; y0 < frame.height; y0 += bandRows) {
            const int y1 = std::min(frame.height, y0 + bandRows);
            const std::size_t first = std::size_t(y0) * std::size_t(frame.width);
            const std::size_t count = std::size_t(y1 - y0) * std::size_t(frame.width);
            for (std::size_t k = 0; k < count; ++k) {
                const std::size_t i = first + k;
                float* p = &band[k * channels];
                p[0] = frame.beauty[3 * i];
                p[1] = frame.beauty[3 * i + 1];
                p[2] = frame.beauty[3 * i + 2];
                p[3] = frame.visibility[i];
                p[4] = frame.objectId[i];
                p[5] = frame.ndotl[i];
                p[6] = frame.depth[i];
                if (withBlocker) p[7] = frame.blockerId[i];
                for (std::size_t l = 0; l < lights; ++l) p[firstLight + l] = frame.lightVisibility[l][i];
                if (withDistance) p[channels - 1] = frame.blockerDistance[i];
            }
            if (!out.write_scanlines(y0, y1, 0, TypeDesc::FLOAT, band.data())) return false;
        }
        return true;
    };
    writeAtomically(file, [&](const fs::path& tmp) { writeImageWith(file, tmp, spec, writeBands); });
}

Frame readFrame(const fs::path& file) {
    checkExrHeader(file);  // first of all: a regular file of a bounded size (checkInputFile)
    auto in = ImageInput::open(file.string());
    if (!in) throw InputError(file.string() + ": not a readable image: " + OIIO::geterror());
    const ImageSpec spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.depth > 1) throw InputError(file.string() + ": not a 2D image");
    // The same bound as a render's (kMaxPixels), and reading by bands of rows below, keep the
    // memory a Frame file can make us allocate to the Frame itself plus one band.
    if (spec.width > kMaxResolution || spec.height > kMaxResolution ||
        std::int64_t(spec.width) * spec.height > kMaxPixels || spec.nchannels > 32)
        throw InputError(file.string() + ": image too large for a Frame (" + std::to_string(spec.width) + "x" +
                         std::to_string(spec.height) + ", " + std::to_string(spec.nchannels) + " channels; at most " +
                         std::to_string(kMaxResolution) + " a side, " + std::to_string(kMaxPixels) +
                         " pixels and 32 channels)");

    auto channelIndex = [&](const std::string& name, bool required) {
        const auto it = std::find(spec.channelnames.begin(), spec.channelnames.end(), name);
        if (it == spec.channelnames.end()) {
            if (!required) return -1;
            throw InputError(file.string() + ": missing channel '" + name +
                             "' (is this a Frame written by `shadowlab render -o X.exr`?)");
        }
        return int(it - spec.channelnames.begin());
    };
    const int iR = channelIndex("R", true), iG = channelIndex("G", true), iB = channelIndex("B", true),
              iV = channelIndex("visibility", true), iId = channelIndex("object_id", true),
              iN = channelIndex("ndotl", true), iZ = channelIndex("Z", true), iBl = channelIndex("blocker_id", false),
              iBd = channelIndex("blocker_distance", false);

    // visibility.0, visibility.1, ... up to the first index that is missing.
    std::vector<int> iLights;
    for (std::size_t l = 0;; ++l) {
        const int idx = channelIndex(lightVisibilityChannel(l), false);
        if (idx < 0) break;
        iLights.push_back(idx);
    }

    // The Frame is allocated once the first band has been read: a small damaged file that
    // declares a huge image fails there, before gigabytes are allocated (found by fuzzing).
    Frame f;
    const int c = spec.nchannels;
    // A tiled file is read a row of tiles at a time (read_tiles needs whole tiles; a band of a
    // tiled file's scanlines crashed OpenImageIO), level 0 of a mip-mapped one.
    const bool tiled = spec.tile_width > 0;
    const int bandRows = tiled ? std::max(1, spec.tile_height) : kFrameBandRows;
    std::vector<float> band(std::size_t(spec.width) * std::min(bandRows, spec.height) * c);
    for (int y0 = 0; y0 < spec.height; y0 += bandRows) {
        const int y1 = std::min(spec.height, y0 + bandRows);
        const bool read =
            tiled ? in->read_tiles(0, 0, spec.x, spec.x + spec.width, spec.y + y0, spec.y + y1, spec.z, spec.z + 1, 0,
                                   c, TypeDesc::FLOAT, band.data())
                  : in->read_scanlines(0, 0, spec.y + y0, spec.y + y1, 0, 0, c, TypeDesc::FLOAT, band.data());
        if (!read) throw InputError(file.string() + ": read failed: " + excerpt(in->geterror(), 300));
        if (y0 == 0) {
            f = Frame::allocate(spec.width, spec.height, iBl >= 0);
            f.lightVisibility.assign(iLights.size(), std::vector<float>(f.pixelCount()));
            if (iBd >= 0) f.blockerDistance.assign(f.pixelCount(), 0.0f);
        }
        const std::size_t first = std::size_t(y0) * spec.width;
        const std::size_t count = std::size_t(y1 - y0) * spec.width;
        for (std::size_t k = 0; k < count; ++k) {
            const std::size_t i = first + k;
            const float* p = &band[k * c];
            f.beauty[3 * i] = p[iR];
            f.beauty[3 * i + 1] = p[iG];
            f.beauty[3 * i + 2] = p[iB];
            f.visibility[i] = p[iV];
            f.objectId[i] = p[iId];
            f.ndotl[i] = p[iN];
            f.depth[i] = p[iZ];
            if (iBl >= 0) f.blockerId[i] = p[iBl];
            for (std::size_t l = 0; l < iLights.size(); ++l) f.lightVisibility[l][i] = p[iLights[l]];
            if (iBd >= 0) f.blockerDistance[i] = p[iBd];
        }
    }
    const std::string prefix = kAttrPrefix;
    for (const auto& attr : spec.extra_attribs) {
        const std::string name = attr.name().string();
        const TypeDesc t = attr.type();
        const std::optional<std::string> standard = exrStandardFromOiio(name);
        const bool ours = name.rfind(prefix, 0) == 0;
        if (name == kTimingsAttr) {
            f.timingsMs = decodeTimings(attr.get_string());
        } else if ((ours || standard) && t == TypeDesc::INT) {
            f.typedAttributes[standard.value_or(name.substr(prefix.size()))] = attr.get_int();
        } else if ((ours || standard) && t == TypeDesc::FLOAT) {
            f.typedAttributes[standard.value_or(name.substr(prefix.size()))] = attr.get_float();
        } else if ((ours || standard) && t.basetype == TypeDesc::FLOAT && t.aggregate == TypeDesc::VEC3 &&
                   !t.arraylen) {
            glm::vec3 v;
            std::memcpy(&v, attr.data(), sizeof v);
            f.typedAttributes[standard.value_or(name.substr(prefix.size()))] = v;
        } else if ((ours || standard) && t.basetype == TypeDesc::FLOAT && t.aggregate == TypeDesc::MATRIX44 &&
                   !t.arraylen) {
            glm::mat4 m;
            std::memcpy(&m, attr.data(), sizeof m);
            f.typedAttributes[standard.value_or(name.substr(prefix.size()))] = m;
        } else if (ours) {
            f.attributes[name.substr(prefix.size())] = attr.get_string();
        }
    }
    return f;
}

}  // namespace shadowlab::scene
