// tests/scene/frame_layout_test.cpp: a Frame EXR in every layout OpenEXR allows, written here
// with OpenImageIO: scanline and tiled (tiles that do not divide the image) read back exactly,
// mip-mapped reads its full-size level, multi-part and deep are refused with a clear error.
#include <filesystem>
#include <string>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "scene/error.h"
#include "scene/frame_io.h"
#include "tests/scene/test_files.h"

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

constexpr int kWidth = 37, kHeight = 21;  // primes: no tile size divides them

// Channel c of pixel (x, y): distinct everywhere, so a misplaced tile or row shows.
float value(int x, int y, int c) { return float(c * 10000 + y * 100 + x); }

ImageSpec frameSpec(int width, int height) {
    ImageSpec spec(width, height, 7, TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B", "visibility", "object_id", "ndotl", "Z"};
    spec.alpha_channel = -1;
    spec.z_channel = 6;
    return spec;
}

std::vector<float> pixels(int width, int height) {
    std::vector<float> p(std::size_t(width) * height * 7);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 7; ++c) p[(std::size_t(y) * width + x) * 7 + c] = value(x, y, c);
    return p;
}

// Writes the frame as `layout`: "scanline", "tiled", "mipmap" or "multipart".
fs::path writeLayout(const test::TempDir& dir, const std::string& layout) {
    const fs::path file = dir.path() / (layout + ".exr");
    auto out = ImageOutput::create(file.string());
    EXPECT_TRUE(out);
    ImageSpec spec = frameSpec(kWidth, kHeight);
    if (layout != "scanline") {
        spec.tile_width = 16;
        spec.tile_height = 8;
    }
    const std::vector<float> p = pixels(kWidth, kHeight);
    if (layout == "mipmap") {
        // OpenImageIO's texture maker writes a tiled MIP-map: level 0 the pixels as given, each
        // smaller level a filtered copy (other values: only level 0 is the Frame).
        const OIIO::ImageBuf image(spec, const_cast<float*>(p.data()));
        OIIO::ImageSpec config;
        config.attribute("tile_width", 16);
        config.attribute("tile_height", 8);
        EXPECT_TRUE(OIIO::ImageBufAlgo::make_texture(OIIO::ImageBufAlgo::MakeTxTexture, image, file.string(), config))
            << OIIO::geterror();
        auto in = OIIO::ImageInput::open(file.string());
        EXPECT_TRUE(in && in->seek_subimage(0, 1)) << "no second MIP level was written";
        return file;
    } else if (layout == "multipart") {
        const ImageSpec specs[2] = {spec, spec};
        EXPECT_TRUE(out->supports("multiimage"));
        EXPECT_TRUE(out->open(file.string(), 2, specs));
        EXPECT_TRUE(out->write_image(TypeDesc::FLOAT, p.data()));
        EXPECT_TRUE(out->open(file.string(), specs[1], ImageOutput::AppendSubimage));
        EXPECT_TRUE(out->write_image(TypeDesc::FLOAT, p.data()));
    } else {
        EXPECT_TRUE(out->open(file.string(), spec));
        EXPECT_TRUE(out->write_image(TypeDesc::FLOAT, p.data()));
    }
    EXPECT_TRUE(out->close());
    return file;
}

void expectExactFrame(const scene::Frame& f) {
    ASSERT_EQ(f.width, kWidth);
    ASSERT_EQ(f.height, kHeight);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const std::size_t i = std::size_t(y) * kWidth + x;
            ASSERT_EQ(f.beauty[3 * i], value(x, y, 0)) << x << "," << y;
            ASSERT_EQ(f.beauty[3 * i + 2], value(x, y, 2));
            ASSERT_EQ(f.visibility[i], value(x, y, 3));
            ASSERT_EQ(f.depth[i], value(x, y, 6));
        }
}

TEST(FrameLayout, ScanlineFramesReadExactly) {
    test::TempDir dir;
    expectExactFrame(scene::readFrame(writeLayout(dir, "scanline")));
}

TEST(FrameLayout, TiledFramesReadExactlyWithPartialEdgeTiles) {
    test::TempDir dir;
    expectExactFrame(scene::readFrame(writeLayout(dir, "tiled")));
}

TEST(FrameLayout, MipMappedFramesReadTheirFullSizeLevel) {
    test::TempDir dir;
    expectExactFrame(scene::readFrame(writeLayout(dir, "mipmap")));
}

TEST(FrameLayout, MultiPartFilesAreRefusedClearly) {
    test::TempDir dir;
    const fs::path file = writeLayout(dir, "multipart");
    try {
        scene::readFrame(file);
        FAIL() << "a multi-part file was read as a Frame";
    } catch (const scene::InputError& e) {
        EXPECT_NE(std::string(e.what()).find(file.string() + ": a multi-part OpenEXR file is not a Frame"),
                  std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace shadowlab
