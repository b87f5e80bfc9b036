// Text on the participant screen (present/include/atonlab/present/text.h):
// UTF-8 decoding, DejaVu Sans through stb_truetype at a pixel height, word
// wrapping, the blend into code values (exact for coverage 0, ½ and 1), and
// the fixation cross's pixels.
#include <gtest/gtest.h>

#include <filesystem>
#include <numeric>

#include "atonlab/present/text.h"
#include "atonlab/stimuli/error.h"
#include "../support/skip.h"

namespace atonlab::present {
namespace {

bool have_font() {
    return std::filesystem::exists(kDefaultFontFile);
}

TEST(ScreenText, Utf8DecodesAndMarksBrokenBytes) {
    EXPECT_EQ(decode_utf8("ab"), (std::vector<char32_t>{U'a', U'b'}));
    EXPECT_EQ(decode_utf8("2 · 6"), (std::vector<char32_t>{U'2', U' ', U'\u00B7', U' ', U'6'}));
    EXPECT_EQ(decode_utf8("°"), (std::vector<char32_t>{U'\u00B0'}));
    EXPECT_EQ(decode_utf8("\xE2\x82\xAC"), (std::vector<char32_t>{U'\u20AC'}));          // €
    EXPECT_EQ(decode_utf8("\xF0\x9F\x98\x80"), (std::vector<char32_t>{U'\U0001F600'}));  // 4 bytes
    EXPECT_EQ(decode_utf8("a\xFF"
                          "b"),
              (std::vector<char32_t>{U'a', U'\uFFFD', U'b'}));
    EXPECT_EQ(decode_utf8("\xE2\x82"), (std::vector<char32_t>{U'\uFFFD', U'\uFFFD'})) << "cut short";
}

TEST(ScreenText, AMissingFontIsOneSentenceNamingTheFile) {
    try {
        (void)Font::load("/nonexistent/font.ttf");
        FAIL();
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("/nonexistent/font.ttf"), std::string::npos) << what;
        EXPECT_NE(what.find("fonts-dejavu-core"), std::string::npos) << what;
    }
}

TEST(ScreenText, LinesHaveTheFontsHeightAndWrapAtSpaces) {
    if (!have_font()) ATONLAB_SKIP_MISSING_TOOL() << kDefaultFontFile << " is not installed (fonts-dejavu-core)";
    const Font f = Font::load(kDefaultFontFile);
    // DejaVu Sans: ascent 1901, descent −483, line gap 0 (units per em 2048),
    // so a pixel height h (ascent − descent) puts lines h apart.
    const double h = 40.0;
    const TextBitmap one = f.render("Hello", h, 10000);
    EXPECT_EQ(one.height, static_cast<int>(std::ceil(h)) + 2);
    const double w = f.line_width("Hello", h);
    EXPECT_GT(w, 2.0 * h);
    EXPECT_LT(w, 3.5 * h);
    EXPECT_EQ(one.width, static_cast<int>(std::ceil(w)) + 2);
    const float ink = std::accumulate(one.coverage.begin(), one.coverage.end(), 0.0f);
    EXPECT_GT(ink, 0.05f * static_cast<float>(one.width * one.height));
    for (const float c : one.coverage) {
        EXPECT_GE(c, 0.0f);
        EXPECT_LE(c, 1.0f);
    }
    // Narrower than both words: one per line; a blank line is kept.
    const TextBitmap two = f.render("Hello world", h, static_cast<int>(w) + 4);
    EXPECT_EQ(two.height, static_cast<int>(std::ceil(2 * h)) + 2);
    const TextBitmap three = f.render("a\n\nb", h, 10000);
    EXPECT_EQ(three.height, static_cast<int>(std::ceil(3 * h)) + 2);
    // Scaling: twice the height, twice the width (to the pixel).
    EXPECT_NEAR(f.line_width("Hello", 2 * h), 2 * w, 1.0);
}

TEST(ScreenText, BlendingInCodeSpace) {
    stimuli::EncodedImage img;
    img.width = 4;
    img.height = 2;
    img.rgb.assign(4 * 2 * 3, 10);
    TextBitmap t;
    t.width = 3;
    t.height = 1;
    t.coverage = {0.0f, 0.5f, 1.0f};
    blend_text(img, t, 2, 1, {210, 110, 10});  // the third column falls off the image
    auto px = [&](int x, int y, int c) { return img.rgb[(static_cast<std::size_t>(y) * 4 + x) * 3 + c]; };
    EXPECT_EQ(px(2, 1, 0), 10) << "coverage 0 keeps the background";
    EXPECT_EQ(px(3, 1, 0), 110) << "½: halfway between 10 and 210";
    EXPECT_EQ(px(3, 1, 1), 60);
    EXPECT_EQ(px(3, 1, 2), 10);
    EXPECT_EQ(px(0, 0, 0), 10);
    t.coverage = {1.0f, 1.0f, 1.0f};
    blend_text(img, t, -1, 0, {200, 200, 200});
    EXPECT_EQ(px(0, 0, 0), 200) << "full coverage is the ink";
    EXPECT_EQ(px(1, 0, 2), 200);
    EXPECT_EQ(px(2, 0, 0), 10);
}

TEST(ScreenText, TheFixationCrossHasTwoBarsThroughItsCentre) {
    const TextBitmap thin = fixation_cross(5, 1);
    EXPECT_EQ(thin.width, 11);
    EXPECT_EQ(std::accumulate(thin.coverage.begin(), thin.coverage.end(), 0.0f), 21.0f);  // 11 + 11 − 1
    EXPECT_EQ(thin.at(5, 0), 1.0f);
    EXPECT_EQ(thin.at(0, 5), 1.0f);
    EXPECT_EQ(thin.at(0, 0), 0.0f);
    const TextBitmap thick = fixation_cross(6, 3);
    EXPECT_EQ(std::accumulate(thick.coverage.begin(), thick.coverage.end(), 0.0f), 2.0f * 13 * 3 - 9);
    EXPECT_EQ(thick.at(6, 5), 1.0f);
    EXPECT_EQ(thick.at(6, 7), 1.0f);
    EXPECT_EQ(thick.at(4, 4), 0.0f);
}

}  // namespace
}  // namespace atonlab::present
