// Image I/O: EXR and PNG round trips, header attributes, and failures that
// must throw InputError naming the path and leave nothing behind.
#include <gtest/gtest.h>

#include "input_error.h"
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/image_io.h"
#include "../support/skip.h"

namespace fs = std::filesystem;
using atonlab::InputError;
using namespace atonlab::stimuli;

namespace {

/// A fresh directory per test, removed afterwards.
class ImageIo : public ::testing::Test {
protected:
    void SetUp() override {
        std::random_device rd;
        dir_ =
            fs::temp_directory_path() / ("atonlab-image-io-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ec);
        fs::remove_all(dir_, ec);
    }
    /// Names of everything in the test directory (to prove no temporary is left).
    std::vector<std::string> listing() const {
        std::vector<std::string> names;
        for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }
    fs::path dir_;
};

/// A small image whose values span what a scene-referred frame holds: zero,
/// starlight-dark sky, a light's core at 1e9 cd/m², negatives from
/// out-of-gamut colours, and values with every mantissa bit set.
ImageRGBA32F test_image(int w, int h) {
    ImageRGBA32F im;
    im.width = w;
    im.height = h;
    im.rgba.resize(static_cast<std::size_t>(w * h * 4));
    const float specials[] = {0.0f, 1e-30f, 1e-3f, 3.14159265f, 1e9f, -0.25f, 0.1f, 65504.0f};
    for (std::size_t i = 0; i < im.rgba.size(); ++i) {
        im.rgba[i] = i < 8 ? specials[i] : static_cast<float>(i) * 1.000001f + 1.0f / static_cast<float>(i + 3);
    }
    return im;
}

std::string what_of(const std::function<void()>& f) { return atonlab::test::input_error_of(f); }

TEST_F(ImageIo, FloatRoundTripIsExact) {
    const ImageRGBA32F im = test_image(7, 5);
    const fs::path p = dir_ / "float.exr";
    write_exr(p, im, ExrMetadata{}, ExrPixelType::float32, /*write_alpha=*/true);
    const ExrImage back = read_exr(p);
    ASSERT_EQ(back.image.width, 7);
    ASSERT_EQ(back.image.height, 5);
    ASSERT_EQ(back.image.rgba.size(), im.rgba.size());
    for (std::size_t i = 0; i < im.rgba.size(); ++i) EXPECT_EQ(back.image.rgba[i], im.rgba[i]) << "float " << i;
    // Row 0 is the top row: pixel (2, 1) sits at index (1*7 + 2)*4.
    EXPECT_EQ(back.image.pixel(2, 1)[0], im.rgba[(1 * 7 + 2) * 4]);
}

TEST_F(ImageIo, WithoutAlphaReadsAlphaAsOne) {
    const ImageRGBA32F im = test_image(3, 2);
    const fs::path p = dir_ / "rgb.exr";
    write_exr(p, im, ExrMetadata{});
    const ExrImage back = read_exr(p);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 3; ++x) {
            for (int c = 0; c < 3; ++c) EXPECT_EQ(back.image.pixel(x, y)[c], im.pixel(x, y)[c]);
            EXPECT_EQ(back.image.pixel(x, y)[3], 1.0f);
        }
}

TEST_F(ImageIo, HalfRoundTripHasHalfPrecision) {
    ImageRGBA32F im;
    im.width = 4;
    im.height = 2;
    // Hand-derived half values: 0.1 is 0x2E66 = 1638/16384 = 0.0999755859375;
    // 1/3 is 0x3555 = 1365/4096 = 0.333251953125; 2049 rounds to even, 2048;
    // 65504 is the largest half; 1e5 overflows to +inf; 1.0 and 0.5 are exact.
    im.rgba = {0.1f, 1.0f / 3.0f, 2049.0f, 1.0f, 0.5f, 65504.0f, 1e5f, 0.25f, -2.0f, 0.0f, 1e-3f,
               1.0f, 7.0f,        1000.0f, 0.7f, 1.0f, 0.1f,     0.1f, 0.1f,  0.1f,  0.2f, 0.3f,
               0.4f, 0.5f,        3.0f,    4.0f, 5.0f, 6.0f,     9.0f, 10.0f, 11.0f, 12.0f};
    const fs::path p = dir_ / "half.exr";
    write_exr(p, im, ExrMetadata{}, ExrPixelType::half, /*write_alpha=*/true);
    const ExrImage back = read_exr(p);
    ASSERT_EQ(back.image.rgba.size(), im.rgba.size());
    EXPECT_EQ(back.image.rgba[0], 0.0999755859375f);
    EXPECT_EQ(back.image.rgba[1], 0.333251953125f);
    EXPECT_EQ(back.image.rgba[2], 2048.0f);
    EXPECT_EQ(back.image.rgba[3], 1.0f);
    EXPECT_EQ(back.image.rgba[4], 0.5f);
    EXPECT_EQ(back.image.rgba[5], 65504.0f);
    EXPECT_TRUE(std::isinf(back.image.rgba[6]) && back.image.rgba[6] > 0);
    for (std::size_t i = 0; i < im.rgba.size(); ++i) {
        if (i == 6) continue;
        // Half has an 11-bit significand: round-to-nearest error <= 2^-11 relative
        // for normal values (1e-3 is normal in half: the smallest normal is 6.1e-5).
        EXPECT_NEAR(back.image.rgba[i], im.rgba[i], std::abs(im.rgba[i]) * 0x1p-11f) << "half " << i;
    }
}

TEST_F(ImageIo, AttributesSurvive) {
    ExrMetadata meta;
    meta.units = "relative";
    meta.degrees_per_pixel = 0.015625;  // 2^-6: exact in float
    meta.adaptation_cd_m2 = 0.001;
    meta.wavelength_nm = 555.0;
    meta.strings = {{"scene", "harbour.toml"}, {"camera", "yaw 45"}};
    const fs::path p = dir_ / "attrs.exr";
    write_exr(p, test_image(2, 2), meta);
    const ExrMetadata back = read_exr(p).meta;
    EXPECT_EQ(back.units, "relative");
    EXPECT_EQ(back.degrees_per_pixel, 0.015625);
    ASSERT_TRUE(back.adaptation_cd_m2.has_value());
    EXPECT_EQ(*back.adaptation_cd_m2, static_cast<double>(0.001f));  // stored as a float attribute
    ASSERT_TRUE(back.wavelength_nm.has_value());
    EXPECT_EQ(*back.wavelength_nm, 555.0);
    EXPECT_EQ(back.strings.at("scene"), "harbour.toml");
    EXPECT_EQ(back.strings.at("camera"), "yaw 45");
    EXPECT_EQ(back.strings.count("units"), 0u);
}

TEST_F(ImageIo, AbsentOptionalAttributesStayAbsent) {
    const fs::path p = dir_ / "plain.exr";
    write_exr(p, test_image(2, 2), ExrMetadata{});
    const ExrMetadata back = read_exr(p).meta;
    EXPECT_EQ(back.units, "cd/m2");
    EXPECT_FALSE(back.adaptation_cd_m2.has_value());
    EXPECT_FALSE(back.wavelength_nm.has_value());
    EXPECT_TRUE(back.strings.empty());
}

TEST_F(ImageIo, ReservedAttributeNameIsABug) {
    ExrMetadata meta;
    meta.strings = {{"units", "lux"}};
    EXPECT_THROW(write_exr(dir_ / "x.exr", test_image(2, 2), meta), std::invalid_argument);
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageIo, OverwriteReplacesTheWholeFile) {
    const fs::path p = dir_ / "frame.exr";
    write_exr(p, test_image(8, 8), ExrMetadata{});
    ImageRGBA32F small = test_image(2, 1);
    small.rgba[0] = 42.0f;
    write_exr(p, small, ExrMetadata{});
    const ExrImage back = read_exr(p);
    EXPECT_EQ(back.image.width, 2);
    EXPECT_EQ(back.image.height, 1);
    EXPECT_EQ(back.image.rgba[0], 42.0f);
    EXPECT_EQ(listing(), std::vector<std::string>{"frame.exr"});
}

TEST_F(ImageIo, MissingFileIsAnInputError) {
    const fs::path p = dir_ / "nowhere.exr";
    const std::string what = what_of([&] { read_exr(p); });
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
    EXPECT_NE(what.find("does not exist"), std::string::npos) << what;
}

TEST_F(ImageIo, NonExrFileIsAnInputError) {
    const fs::path p = dir_ / "text.exr";
    std::ofstream(p) << "this is not an OpenEXR file\n";
    const std::string what = what_of([&] { read_exr(p); });
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
    EXPECT_NE(what.find("cannot read the EXR image"), std::string::npos) << what;
}

TEST_F(ImageIo, TruncatedExrIsAnInputError) {
    const fs::path p = dir_ / "cut.exr";
    write_exr(p, test_image(64, 64), ExrMetadata{});
    fs::resize_file(p, fs::file_size(p) / 2);
    const std::string what = what_of([&] { read_exr(p); });
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
}

TEST_F(ImageIo, MissingDirectoryIsAnInputErrorAndCreatesNothing) {
    const fs::path p = dir_ / "no-such-dir" / "out.exr";
    const std::string what = what_of([&] { write_exr(p, test_image(2, 2), ExrMetadata{}); });
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
    EXPECT_NE(what.find("temporary file"), std::string::npos) << what;
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageIo, ParentIsAFileIsAnInputError) {
    std::ofstream(dir_ / "plain") << "x";
    const fs::path p = dir_ / "plain" / "out.png";
    const std::string what = what_of([&] { write_png_rgb8(p, 1, 1, {0.f, 0.f, 0.f}); });
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
    EXPECT_EQ(listing(), std::vector<std::string>{"plain"});
}

// The rename is the last step: when it fails, the finished temporary must go.
TEST_F(ImageIo, FailedRenameLeavesNoTemporary) {
    fs::create_directory(dir_ / "taken.exr");
    fs::create_directory(dir_ / "taken.exr" / "child");  // a non-empty directory cannot be replaced
    const fs::path p = dir_ / "taken.exr";
    const std::string what = what_of([&] { write_exr(p, test_image(4, 4), ExrMetadata{}); });
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
    EXPECT_EQ(listing(), std::vector<std::string>{"taken.exr"});
    const std::string what_png = what_of([&] { write_png_rgb8(p, 1, 1, {0.f, 0.f, 0.f}); });
    EXPECT_NE(what_png.find(p.string()), std::string::npos) << what_png;
    EXPECT_EQ(listing(), std::vector<std::string>{"taken.exr"});
}

TEST_F(ImageIo, ReadOnlyDirectoryIsAnInputError) {
    if (::geteuid() == 0) ATONLAB_SKIP_NOT_APPLICABLE() << "running as root: directory permissions do not stop writes";
    fs::permissions(dir_, fs::perms::owner_read | fs::perms::owner_exec);
    const fs::path p = dir_ / "out.exr";
    const std::string what = what_of([&] { write_exr(p, test_image(2, 2), ExrMetadata{}); });
    fs::permissions(dir_, fs::perms::owner_all);
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
    EXPECT_TRUE(listing().empty());
}

// ---------------------------------------------------------------------------
// PNG

TEST_F(ImageIo, PngRoundTripsEvery8BitCodeExactly) {
    const int w = 256, h = 2;
    std::vector<float> rgb(static_cast<std::size_t>(w * h * 3));
    for (int y = 0; y < h; ++y)
        for (int k = 0; k < w; ++k) {
            const std::size_t i = static_cast<std::size_t>((y * w + k) * 3);
            rgb[i + 0] = static_cast<float>(k) / 255.0f;
            rgb[i + 1] = static_cast<float>(255 - k) / 255.0f;
            rgb[i + 2] = static_cast<float>((k * 7 + y * 100) % 256) / 255.0f;
        }
    const fs::path p = dir_ / "codes.png";
    write_png_rgb8(p, w, h, rgb);
    int rw = 0, rh = 0;
    const std::vector<float> back = read_png_rgb(p, rw, rh);
    EXPECT_EQ(rw, w);
    EXPECT_EQ(rh, h);
    ASSERT_EQ(back.size(), rgb.size());
    for (std::size_t i = 0; i < rgb.size(); ++i) EXPECT_EQ(back[i], rgb[i]) << i;
    EXPECT_EQ(listing(), std::vector<std::string>{"codes.png"});
}

TEST_F(ImageIo, PngRoundsToNearestAndClamps) {
    // 0.5 * 255 = 127.5 -> 128 and 0.3f * 255 = 76.5 (in float) -> 77: halves round up;
    // 0.0019 * 255 = 0.48 -> 0; out of range and NaN clamp to 0 / 255.
    const std::vector<float> rgb = {0.5f, 0.3f, 0.0019f, -1.0f, 2.0f, std::numeric_limits<float>::quiet_NaN()};
    const fs::path p = dir_ / "round.png";
    write_png_rgb8(p, 2, 1, rgb);
    int w = 0, h = 0;
    const std::vector<float> back = read_png_rgb(p, w, h);
    ASSERT_EQ(back.size(), 6u);
    EXPECT_EQ(back[0], 128.0f / 255.0f);
    EXPECT_EQ(back[1], 77.0f / 255.0f);
    EXPECT_EQ(back[2], 0.0f);
    EXPECT_EQ(back[3], 0.0f);
    EXPECT_EQ(back[4], 1.0f);
    EXPECT_EQ(back[5], 0.0f);
}

TEST_F(ImageIo, PngReaderTakes16BitGrey) {
    // Written with libpng's simplified API as 16-bit linear grey: the reader
    // returns the stored codes over 65535, no gamma applied.
    const png_uint_16 codes[3] = {0, 1000, 65535};
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    image.width = 3;
    image.height = 1;
    image.format = PNG_FORMAT_LINEAR_Y;
    const fs::path p = dir_ / "grey16.png";
    ASSERT_NE(png_image_write_to_file(&image, p.c_str(), 0, codes, 0, nullptr), 0) << image.message;
    int w = 0, h = 0;
    const std::vector<float> back = read_png_rgb(p, w, h);
    ASSERT_EQ(w, 3);
    ASSERT_EQ(h, 1);
    ASSERT_EQ(back.size(), 9u);
    for (int x = 0; x < 3; ++x)
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(back[static_cast<std::size_t>(x * 3 + c)], static_cast<float>(codes[x]) / 65535.0f);
}

TEST_F(ImageIo, PngReaderDropsAlpha) {
    const png_byte rgba[8] = {10, 20, 30, 40, 250, 251, 252, 0};
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    image.width = 2;
    image.height = 1;
    image.format = PNG_FORMAT_RGBA;
    const fs::path p = dir_ / "rgba8.png";
    ASSERT_NE(png_image_write_to_file(&image, p.c_str(), 0, rgba, 0, nullptr), 0) << image.message;
    int w = 0, h = 0;
    const std::vector<float> back = read_png_rgb(p, w, h);
    ASSERT_EQ(back.size(), 6u);
    EXPECT_EQ(back[0], 10.0f / 255.0f);
    EXPECT_EQ(back[1], 20.0f / 255.0f);
    EXPECT_EQ(back[2], 30.0f / 255.0f);
    EXPECT_EQ(back[3], 250.0f / 255.0f);
    EXPECT_EQ(back[4], 251.0f / 255.0f);
    EXPECT_EQ(back[5], 252.0f / 255.0f);
}

TEST_F(ImageIo, NonPngAndMissingPngAreInputErrors) {
    const fs::path text = dir_ / "text.png";
    std::ofstream(text) << "not a png";
    int w = 0, h = 0;
    std::string what = what_of([&] { read_png_rgb(text, w, h); });
    EXPECT_NE(what.find(text.string()), std::string::npos) << what;
    EXPECT_NE(what.find("not a PNG"), std::string::npos) << what;
    const fs::path missing = dir_ / "missing.png";
    what = what_of([&] { read_png_rgb(missing, w, h); });
    EXPECT_NE(what.find(missing.string()), std::string::npos) << what;
}

TEST_F(ImageIo, TruncatedPngIsAnInputError) {
    std::vector<float> rgb(64 * 64 * 3);
    for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<float>((i * 37) % 256) / 255.0f;
    const fs::path p = dir_ / "cut.png";
    write_png_rgb8(p, 64, 64, rgb);
    fs::resize_file(p, fs::file_size(p) / 2);
    int w = 0, h = 0;
    const std::string what = what_of([&] { read_png_rgb(p, w, h); });
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
    EXPECT_NE(what.find("cannot read the PNG image"), std::string::npos) << what;
}

TEST_F(ImageIo, WrongBufferSizeIsABug) {
    EXPECT_THROW(write_png_rgb8(dir_ / "x.png", 2, 2, std::vector<float>(5)), std::invalid_argument);
    ImageRGBA32F bad;
    bad.width = 2;
    bad.height = 2;
    bad.rgba.resize(3);
    EXPECT_THROW(write_exr(dir_ / "x.exr", bad, ExrMetadata{}), std::invalid_argument);
    EXPECT_TRUE(listing().empty());
}

}  // namespace
