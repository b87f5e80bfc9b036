// Figure and snapshot names are unique per condition (docs/analysis.md,
// "Outputs"): the binary (ATONLAB_BINARY, set by tests/e2e/CMakeLists.txt)
// runs tests/data/run/two-names-one-slug.toml, whose conditions "a<b" (red
// lights) and "a>b" (green lights) have the same file-name form "a_b", with
// the model observer, headless, and analyses the study. Each condition must
// get its own snapshot and psychometric figure, named with the hash of its
// name (the SHA-256 prefixes below come from sha256sum, not from atonlab), and
// each snapshot must show its own stimulus: red where the condition's lights
// are red, green where they are green; the report shows each under its own
// heading. Skips where the binary finds no GL 4.5 context (exit status 3).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "../support/child_process.h"
#include "atonlab/analysis/plots.h"
#include "atonlab/analysis/report.h"
#include "atonlab/stimuli/image_io.h"
#include "../support/skip.h"

#ifndef ATONLAB_BINARY
#error "ATONLAB_BINARY (the atonlab executable) must be defined by the build"
#endif

namespace atonlab {
namespace {

namespace fs = std::filesystem;
using store::test_support::file_bytes;
using store::test_support::TempDir;

const fs::path kProtocol = fs::path(ATONLAB_SOURCE_DIR) / "tests/data/run/two-names-one-slug.toml";

// printf 'a<b' | sha256sum; printf 'a>b' | sha256sum (first 8 hex digits).
constexpr const char* kRedSlug = "a_b-4a826aac";    // "a<b"
constexpr const char* kGreenSlug = "a_b-998a5be8";  // "a>b"

/// Red and green summed over the coloured pixels of a snapshot (max − min
/// channel > 0.1): the lights, not the black background or the white bar
/// between the frames.
struct ChannelSums {
    double r = 0.0, g = 0.0;
    int pixels = 0;
};

ChannelSums sums_of(const fs::path& png) {
    int w = 0, h = 0;
    const std::vector<float> rgb = stimuli::read_png_rgb(png, w, h);
    ChannelSums s;
    for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) {
        const float hi = std::max({rgb[i], rgb[i + 1], rgb[i + 2]});
        const float lo = std::min({rgb[i], rgb[i + 1], rgb[i + 2]});
        if (hi - lo <= 0.1f) continue;
        s.r += rgb[i];
        s.g += rgb[i + 1];
        ++s.pixels;
    }
    return s;
}

TEST(AnalyzeFigureNames, ConditionsWhoseNamesShareAFileNameGetTheirOwnFiguresEachShowingItsOwnStimulus) {
    TempDir dir;
    const fs::path db = dir / "study.db";
    const int run = test::run_to_files(
        {ATONLAB_BINARY, "run", kProtocol.string(), "--db", db.string(), "--headless", "--model-observer"},
        dir / "run.out", dir / "run.err");
    if (run == 3) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << file_bytes(dir / "run.err");
    ASSERT_EQ(run, 0) << file_bytes(dir / "run.err");
    const fs::path out = dir / "report";
    const int analyze = test::run_to_files(
        {ATONLAB_BINARY, "analyze", db.string(), "--out", out.string(), "--bootstrap", "0", "--quiet"}, dir / "an.out",
        dir / "an.err");
    ASSERT_EQ(analyze, 0) << file_bytes(dir / "an.err");

    // The names are as documented: the slug and the hash of the name.
    const auto slugs = analysis::condition_slugs(std::vector<std::string>{"a<b", "a>b"});
    EXPECT_EQ(slugs.at("a<b"), kRedSlug);
    EXPECT_EQ(slugs.at("a>b"), kGreenSlug);

    const fs::path red = out / "figures" / (std::string("snapshot-") + kRedSlug + ".png");
    const fs::path green = out / "figures" / (std::string("snapshot-") + kGreenSlug + ".png");
    ASSERT_TRUE(fs::exists(red)) << red;
    ASSERT_TRUE(fs::exists(green)) << green;
    EXPECT_FALSE(fs::exists(out / "figures" / "snapshot-a_b.png")) << "the shared slug alone names no file";
    EXPECT_NE(file_bytes(red), file_bytes(green));
    // Each shows its own stimulus: the red lights' snapshot has more red than
    // green in its coloured pixels, the green lights' more green than red (by a
    // factor of 2: IALA red and green are far apart in both channels).
    const ChannelSums r = sums_of(red), g = sums_of(green);
    EXPECT_GT(r.pixels, 0);
    EXPECT_GT(g.pixels, 0);
    EXPECT_GT(r.r, 2.0 * r.g) << "a<b: R " << r.r << ", G " << r.g << " over " << r.pixels << " px";
    EXPECT_GT(g.g, 2.0 * g.r) << "a>b: R " << g.r << ", G " << g.g << " over " << g.pixels << " px";

    if (fs::exists(out / "figures" / (std::string("psychometric-") + kRedSlug + ".png"))) {
        // gnuplot drew the figures: one per condition, under its own name.
        EXPECT_TRUE(fs::exists(out / "figures" / (std::string("psychometric-") + kGreenSlug + ".png")));
        EXPECT_FALSE(fs::exists(out / "figures" / "psychometric-a_b.png"));
    }

    // The report shows each snapshot under its own condition's heading.
    const std::string html = file_bytes(out / "report.html");
    const auto red_at = html.find("<h2 id=\"c-" + std::string(kRedSlug) + "\">");
    const auto green_at = html.find("<h2 id=\"c-" + std::string(kGreenSlug) + "\">");
    ASSERT_NE(red_at, std::string::npos);
    ASSERT_NE(green_at, std::string::npos);
    const std::string red_png = analysis::base64(file_bytes(red));
    const std::string green_png = analysis::base64(file_bytes(green));
    const auto red_shown = html.find(red_png), green_shown = html.find(green_png);
    ASSERT_NE(red_shown, std::string::npos);
    ASSERT_NE(green_shown, std::string::npos);
    // The sections follow the protocol's order: a<b, then a>b.
    EXPECT_LT(red_at, red_shown);
    EXPECT_LT(red_shown, green_at);
    EXPECT_LT(green_at, green_shown);
}

}  // namespace
}  // namespace atonlab
