// `atonlab tonemap` and `atonlab glare` on an EXR that `atonlab render` made
// (docs/tone-mapping.md "HDR images in and out"):
//  - tonemap --operator reinhard against pfstools' pfstmo_reinhard02 (Debian
//    pfstools) with the parameters matched as documented: mean |Δcode| <= 0.05,
//    max <= 1; with --out-of-gamut clip-channels the same holds on every pixel,
//    out-of-gamut ones included (pfsout clips each channel);
//  - glare keeps Σ L·Ω within 1e-3 once the reported edge cut is added back.
// GL only for the rendering (exit status 3 without GL 4.5: skipped).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <string>
#include <vector>

#include "atonlab/stimuli/image_io.h"
#include "../support/skip.h"

#ifndef ATONLAB_BINARY
#error "ATONLAB_BINARY (the atonlab executable) must be defined by the build"
#endif

namespace {

namespace fs = std::filesystem;
using namespace atonlab::stimuli;

fs::path scratch(const std::string& name) {
    const fs::path dir =
        fs::temp_directory_path() / ("atonlab-image-commands-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

int shell(const std::string& command) {
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A small rendering of the four coloured lights at night (glare included).
// Returns false (and skips) when there is no GL.
bool render(const fs::path& exr, const std::string& extra = "") {
    const std::string scene = std::string(ATONLAB_SOURCE_DIR) + "/scenes/tonemap-four-lights.toml";
    const int rc = shell(std::string(ATONLAB_BINARY) + " render " + scene + " -o " + exr.string() +
                         " --set display.width_px=480 --set display.height_px=270 " + extra + " > /dev/null");
    if (rc == 3) return false;
    EXPECT_EQ(rc, 0);
    return rc == 0;
}

// IEC 61966-2-1 encoding of a linear value clipped to [0, 1], rounded to 8 bits.
int srgb_code(double v) {
    v = std::clamp(v, 0.0, 1.0);
    const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
    return static_cast<int>(std::lround(255.0 * e));
}

TEST(ImageCommands, TonemapReinhardMatchesPfstmoReinhard02) {
    if (shell("command -v pfstmo_reinhard02 > /dev/null && command -v pfsoutpfm > /dev/null") != 0)
        ATONLAB_SKIP_MISSING_TOOL() << "pfstmo_reinhard02 or pfsoutpfm is not installed (Debian packages pfstmo, pfstools; "
                                        "scripts/setup.sh installs them)";
    const fs::path dir = scratch("reinhard");
    const fs::path exr = dir / "four.exr";
    if (!render(exr)) ATONLAB_SKIP_NO_GPU() << "no OpenGL 4.5 context";
    // pfstmo_reinhard02's global operator: key 0.18, log-average with δ = 1e-5,
    // L_white = the brightest pixel, the curve applied to Y and XYZ scaled by
    // L_d / Y (no hue preservation, no blueshift). The display: sRGB, black 0,
    // no dither (pfsout's sRGB has no black level and no dither).
    ASSERT_EQ(shell(std::string(ATONLAB_BINARY) + " tonemap " + exr.string() + " -o " + (dir / "atonlab.png").string() +
                    " --operator reinhard --key 0.18 --reinhard-white max --epsilon-cd-m2 1e-5 --blueshift off"
                    " --hue-preservation none --display srgb --black-cd-m2 0 --dither off > /dev/null"),
              0);
    ASSERT_EQ(shell("pfsin " + exr.string() + " | pfstmo_reinhard02 --key 0.18 | pfsoutpfm " +
                    (dir / "pfs.pfm").string() + " && pfsin " + exr.string() +
                    " | pfstmo_reinhard02 --key 0.18 | pfsoutppm " + (dir / "pfs.ppm").string() + " --srgb"),
              0);
    int w = 0, h = 0;
    const std::vector<float> ours = read_png_rgb(dir / "atonlab.png", w, h);
    int pw = 0, ph = 0;
    const std::vector<float> pfs = read_pfm_rgb(dir / "pfs.pfm", pw, ph);
    ASSERT_EQ(w, pw);
    ASSERT_EQ(h, ph);
    // pfsout clips each channel at 1; atonlab's encoder keeps an out-of-gamut colour's
    // luminance and gives up chroma (docs/tone-mapping.md "Adding light never darkens"). So
    // pixels pfstmo leaves inside [0, 1]³ must agree code for code, and out-of-gamut ones
    // (the coloured lights' cores) must show at least pfsout's clipped luminance.
    const auto in_gamut = [&](std::size_t px) {
        return pfs[px * 3] <= 1.0f && pfs[px * 3 + 1] <= 1.0f && pfs[px * 3 + 2] <= 1.0f;
    };
    const auto decoded_y = [](const float* rgb_codes_or_linear, bool codes) {
        double y = 0.0;
        const double weight[3] = {0.2126, 0.7152, 0.0722};
        for (int c = 0; c < 3; ++c) {
            const double v = codes ? rgb_codes_or_linear[c] : std::clamp(static_cast<double>(rgb_codes_or_linear[c]), 0.0, 1.0);
            const double linear = codes ? (v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4)) : v;
            y += weight[c] * linear;
        }
        return y;
    };
    double sum = 0;
    int worst = 0;
    std::size_t bright = 0, compared = 0, outside = 0;
    for (std::size_t px = 0; px * 3 < pfs.size(); ++px) {
        if (!in_gamut(px)) {
            ++outside;
            // Luminance kept: ours at least pfsout's clipped luminance, to a code's rounding.
            EXPECT_GE(decoded_y(&ours[px * 3], true), decoded_y(&pfs[px * 3], false) - 0.004) << "pixel " << px;
            continue;
        }
        for (std::size_t i = px * 3; i < px * 3 + 3; ++i) {
            const int a = static_cast<int>(std::lround(ours[i] * 255.0));
            const int b = srgb_code(pfs[i]);
            sum += std::abs(a - b);
            worst = std::max(worst, std::abs(a - b));
            if (b > 20) ++bright;
            ++compared;
        }
    }
    const double mean = sum / static_cast<double>(compared);
    std::printf("tonemap vs pfstmo_reinhard02 (pfsoutpfm, sRGB rounded): mean |dcode| %.5f, max %d over %zu values "
                "in the gamut; %zu pixels outside it (luminance kept)\n",
                mean, worst, compared, outside);
    EXPECT_LE(mean, 0.05);
    EXPECT_LE(worst, 1);
    EXPECT_GT(bright, compared / 2) << "the comparison should see more than a black frame";

    // pfsoutppm --srgb writes the same floats truncated to 8 bits, not rounded:
    // ours is that code or one above, never anything else.
    std::ifstream ppm(dir / "pfs.ppm", std::ios::binary);
    std::string magic;
    int mw = 0, mh = 0, maxval = 0;
    ppm >> magic >> mw >> mh >> maxval;
    ppm.get();
    ASSERT_EQ(magic, "P6");
    ASSERT_EQ(maxval, 255);
    std::vector<unsigned char> codes(static_cast<std::size_t>(mw) * mh * 3);
    ppm.read(reinterpret_cast<char*>(codes.data()), static_cast<std::streamsize>(codes.size()));
    std::size_t one_above = 0, other = 0;
    for (std::size_t i = 0; i < codes.size(); ++i) {
        if (!in_gamut(i / 3)) continue;
        const int d = static_cast<int>(std::lround(ours[i] * 255.0)) - codes[i];
        if (d == 1) ++one_above;
        if (d != 0 && d != 1) ++other;
    }
    std::printf("against pfsoutppm --srgb (8-bit, truncated): %zu of %zu codes one above, %zu otherwise different\n",
                one_above, codes.size(), other);
    EXPECT_EQ(other, 0u);
    fs::remove_all(dir);
}

// display.out_of_gamut = "clip-channels" is what pfsout does to a colour above full drive: each
// channel clipped at 1. With it, `atonlab tonemap` reproduces pfstmo_reinhard02 on every pixel,
// the coloured cores that pfstmo leaves out of gamut included (docs/tone-mapping.md "Out of
// gamut: colour or luminance"); under the default (keep-luminance) those cores differ by up to
// 254 codes.
TEST(ImageCommands, TonemapClipChannelsMatchesPfstmoReinhard02OutOfGamut) {
    if (shell("command -v pfstmo_reinhard02 > /dev/null && command -v pfsoutpfm > /dev/null") != 0)
        ATONLAB_SKIP_MISSING_TOOL() << "pfstmo_reinhard02 or pfsoutpfm is not installed (Debian packages pfstmo, pfstools; "
                                        "scripts/setup.sh installs them)";
    const fs::path dir = scratch("reinhard-clip");
    const fs::path exr = dir / "four.exr";
    if (!render(exr)) ATONLAB_SKIP_NO_GPU() << "no OpenGL 4.5 context";
    const std::string common = " --operator reinhard --key 0.18 --reinhard-white max --epsilon-cd-m2 1e-5 --blueshift off"
                               " --hue-preservation none --display srgb --black-cd-m2 0 --dither off";
    for (const char* choice : {"clip-channels", "keep-luminance"})
        ASSERT_EQ(shell(std::string(ATONLAB_BINARY) + " tonemap " + exr.string() + " -o " + (dir / choice).string() +
                        ".png" + common + " --out-of-gamut " + choice + " > /dev/null"),
                  0);
    ASSERT_EQ(shell("pfsin " + exr.string() + " | pfstmo_reinhard02 --key 0.18 | pfsoutpfm " + (dir / "pfs.pfm").string()),
              0);
    int pw = 0, ph = 0;
    const std::vector<float> pfs = read_pfm_rgb(dir / "pfs.pfm", pw, ph);
    for (const std::string choice : {"clip-channels", "keep-luminance"}) {
        int w = 0, h = 0;
        const std::vector<float> ours = read_png_rgb(dir / (choice + ".png"), w, h);
        ASSERT_EQ(w, pw);
        ASSERT_EQ(h, ph);
        double sum_in = 0, sum_out = 0;
        int worst_in = 0, worst_out = 0;
        std::size_t n_in = 0, n_out = 0;
        for (std::size_t px = 0; px * 3 < pfs.size(); ++px) {
            const bool outside = pfs[px * 3] > 1.0f || pfs[px * 3 + 1] > 1.0f || pfs[px * 3 + 2] > 1.0f;
            for (std::size_t i = px * 3; i < px * 3 + 3; ++i) {
                const int d = std::abs(static_cast<int>(std::lround(ours[i] * 255.0)) - srgb_code(pfs[i]));
                (outside ? sum_out : sum_in) += d;
                (outside ? worst_out : worst_in) = std::max(outside ? worst_out : worst_in, d);
                ++(outside ? n_out : n_in);
            }
        }
        std::printf("tonemap --out-of-gamut %s vs pfstmo_reinhard02: in gamut mean |dcode| %.4f max %d (%zu values); "
                    "out of gamut mean %.2f max %d (%zu values, %.2f %% of the pixels)\n",
                    choice.c_str(), sum_in / static_cast<double>(n_in), worst_in, n_in,
                    n_out ? sum_out / static_cast<double>(n_out) : 0.0, worst_out, n_out,
                    100.0 * static_cast<double>(n_out) / static_cast<double>(n_in + n_out));
        ASSERT_GT(n_out, 0u) << "the frame should hold pixels pfstmo leaves out of gamut";
        EXPECT_LE(sum_in / static_cast<double>(n_in), 0.05) << choice;
        EXPECT_LE(worst_in, 1) << choice;
        if (choice == "clip-channels") {
            EXPECT_LE(sum_out / static_cast<double>(n_out), 0.05);
            EXPECT_LE(worst_out, 1);
        } else {
            EXPECT_GT(worst_out, 50) << "keep-luminance should differ from pfsout's clipping out of gamut";
        }
    }
    fs::remove_all(dir);
}

TEST(ImageCommands, GlareKeepsTheLightsEnergyMinusTheReportedEdgeCut) {
    const fs::path dir = scratch("glare");
    const fs::path exr = dir / "noglare.exr";
    if (!render(exr, "--set 'eye.glare=\"none\"'")) ATONLAB_SKIP_NO_GPU() << "no OpenGL 4.5 context";
    const ExrImage in = read_exr(exr);
    ASSERT_GT(in.meta.degrees_per_pixel, 0);
    const double omega_sr = std::pow(in.meta.degrees_per_pixel * std::numbers::pi / 180.0, 2);
    for (const std::string model : {"spencer", "gaussian-bloom", "wave-optics", "cie"}) {
        const fs::path out_path = dir / (model + ".exr");
        ASSERT_EQ(shell(std::string(ATONLAB_BINARY) + " glare " + exr.string() + " -o " + out_path.string() +
                        " --model " + model + (model == "wave-optics" ? " --psf-size 256" : "") + " > /dev/null"),
                  0)
            << model;
        const ExrImage out = read_exr(out_path);
        ASSERT_EQ(out.image.width, in.image.width);
        ASSERT_DOUBLE_EQ(out.meta.degrees_per_pixel, in.meta.degrees_per_pixel);
        const std::string note = out.meta.strings.at("image_glare");
        std::smatch m;
        ASSERT_TRUE(
            std::regex_search(note, m, std::regex(R"(edge_cut_rgb=\[([0-9.e+-]+), ([0-9.e+-]+), ([0-9.e+-]+)\])")))
            << note;
        for (int c = 0; c < 3; ++c) {
            double sum_in = 0, sum_out = 0;  // Σ L·Ω, cd/m² · sr
            for (int y = 0; y < in.image.height; ++y)
                for (int x = 0; x < in.image.width; ++x) {
                    sum_in += in.image.pixel(x, y)[c] * omega_sr;
                    sum_out += out.image.pixel(x, y)[c] * omega_sr;
                }
            const double cut = std::stod(m[c + 1].str());
            EXPECT_LT(cut, 0.05) << model;
            EXPECT_NEAR((sum_out + cut * sum_in) / sum_in, 1.0, 1e-3) << model << " channel " << c;
        }
        float peak_in = 0, peak_out = 0;
        for (std::size_t i = 0; i < in.image.rgba.size(); i += 4) {
            peak_in = std::max(peak_in, in.image.rgba[i + 1]);
            peak_out = std::max(peak_out, out.image.rgba[i + 1]);
        }
        EXPECT_LT(peak_out, peak_in) << model;  // the glare took light from the core
    }
    fs::remove_all(dir);
}

TEST(ImageCommands, BadInputWritesNothing) {
    const fs::path dir = scratch("bad");
    const std::string bin = ATONLAB_BINARY;
    // No such file, an unknown operator, a glare model an image cannot take.
    EXPECT_EQ(
        shell(bin + " tonemap " + (dir / "missing.exr").string() + " -o " + (dir / "a.png").string() + " 2>/dev/null"),
        2);
    EXPECT_EQ(shell(bin + " tonemap x.exr -o " + (dir / "b.png").string() + " --operator drago 2>/dev/null"), 2);
    EXPECT_EQ(shell(bin + " glare x.exr -o " + (dir / "c.exr").string() + " --model aperture 2>/dev/null"), 2);
    EXPECT_TRUE(fs::is_empty(dir));
    fs::remove_all(dir);
}

}  // namespace
