#pragma once
// Text on the participant screen (docs/architecture.md: stb_truetype with a Debian font):
// a TrueType font rasterised on the CPU into a coverage bitmap, laid out in
// word-wrapped lines, and blended into display code values. Text is drawn
// after display encoding, at a code value the session chooses (the luminance
// it emits is the display model's for that code, docs/running.md "Screens"):
// the blend is code = background + (ink − background) × coverage per channel,
// rounded, so glyph edges are blended in code space, not in light.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/stimuli/display_pipeline.h"

namespace atonlab::present {

/// The font the runner uses unless told otherwise (Debian fonts-dejavu-core).
inline constexpr const char* kDefaultFontFile = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

/// Glyph coverage, 0 … 1, row 0 at the top.
struct TextBitmap {
    int width = 0;
    int height = 0;
    std::vector<float> coverage;
    float at(int x, int y) const {
        return coverage[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)];
    }
};

enum class TextAlign : std::uint8_t { left, centre };

class Font {
public:
    /// Reads a TrueType file. Throws InputError naming the file when it cannot
    /// be read or is not a font stb_truetype understands.
    static Font load(const std::filesystem::path& file);
    ~Font();
    Font(Font&&) noexcept;
    Font& operator=(Font&&) noexcept;
    Font(const Font&) = delete;
    Font& operator=(const Font&) = delete;

    /// `utf8` laid out at `pixel_height` px (the font's ascent − descent), lines
    /// broken at '\n' and wrapped at spaces to at most max_width_px (a word
    /// longer than that stands alone on its line), each line aligned.
    /// Characters the font lacks are drawn as its missing-glyph box.
    TextBitmap render(std::string_view utf8, double pixel_height, int max_width_px,
                      TextAlign align = TextAlign::centre) const;
    /// The width of one line of text, px (no wrapping).
    double line_width(std::string_view utf8, double pixel_height) const;

private:
    Font() = default;
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Decodes UTF-8 into code points; a malformed byte becomes U+FFFD.
std::vector<char32_t> decode_utf8(std::string_view text);

/// Blends `ink` (code values) into `image` through `text`'s coverage, with the
/// bitmap's top-left corner at pixel (x, y) of the image (row 0 at the top);
/// what falls outside the image is cut.
void blend_text(stimuli::EncodedImage& image, const TextBitmap& text, int x, int y,
                const std::array<std::uint16_t, 3>& ink);

/// A fixation cross `arm_px` from its centre to each tip and `thickness_px`
/// wide, as a coverage bitmap of (2 arm + 1)² px centred on its middle pixel.
TextBitmap fixation_cross(int arm_px, int thickness_px);

}  // namespace atonlab::present
