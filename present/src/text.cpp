// Text rasterised by stb_truetype (text.h). The implementation of stb_truetype
// is compiled here, once; the header is Debian's (libstb-dev), a system header,
// so its own code does not trip the project's warnings.
#include "atonlab/present/text.h"

#define STB_TRUETYPE_IMPLEMENTATION
#include <fmt/format.h>
#include <stb/stb_truetype.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>

#include "atonlab/stimuli/error.h"

namespace atonlab::present {

std::vector<char32_t> decode_utf8(std::string_view s) {
    std::vector<char32_t> out;
    out.reserve(s.size());
    std::size_t i = 0;
    while (i < s.size()) {
        const auto c = static_cast<unsigned char>(s[i]);
        int extra = 0;
        char32_t cp = 0;
        if (c < 0x80) {
            cp = c;
        } else if ((c & 0xE0) == 0xC0) {
            extra = 1;
            cp = c & 0x1Fu;
        } else if ((c & 0xF0) == 0xE0) {
            extra = 2;
            cp = c & 0x0Fu;
        } else if ((c & 0xF8) == 0xF0) {
            extra = 3;
            cp = c & 0x07u;
        } else {
            out.push_back(U'\uFFFD');
            ++i;
            continue;
        }
        bool ok = i + static_cast<std::size_t>(extra) < s.size();  // every continuation byte is there
        for (int k = 1; ok && k <= extra; ++k) {
            const auto cc = static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]);
            if ((cc & 0xC0) != 0x80) ok = false;
            cp = (cp << 6) | (cc & 0x3Fu);
        }
        if (!ok) {
            out.push_back(U'\uFFFD');
            ++i;
            continue;
        }
        out.push_back(cp);
        i += static_cast<std::size_t>(extra) + 1;
    }
    return out;
}

struct Font::Impl {
    std::vector<unsigned char> bytes;
    stbtt_fontinfo info{};
    int ascent = 0, descent = 0, line_gap = 0;  // font units

    float scale(double pixel_height) const {
        return stbtt_ScaleForPixelHeight(&info, static_cast<float>(pixel_height));
    }
    /// Advance of `cp` followed by `next` (kerning included), font units.
    int advance(char32_t cp, char32_t next) const {
        int adv = 0, lsb = 0;
        stbtt_GetCodepointHMetrics(&info, static_cast<int>(cp), &adv, &lsb);
        if (next) adv += stbtt_GetCodepointKernAdvance(&info, static_cast<int>(cp), static_cast<int>(next));
        return adv;
    }
    double width(const std::u32string& line, float s) const {
        long total = 0;
        for (std::size_t i = 0; i < line.size(); ++i) total += advance(line[i], i + 1 < line.size() ? line[i + 1] : 0);
        return static_cast<double>(total) * static_cast<double>(s);
    }
};

Font Font::load(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in)
        throw InputError(SourceLocation{file.string(), 0, 0, ""},
                         "cannot read the font file (install the Debian package fonts-dejavu-core, or give --font).");
    Font f;
    f.impl_ = std::make_unique<Impl>();
    f.impl_->bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    const unsigned char* data = f.impl_->bytes.data();
    const int offset = f.impl_->bytes.size() > 12 ? stbtt_GetFontOffsetForIndex(data, 0) : -1;
    if (offset < 0 || !stbtt_InitFont(&f.impl_->info, data, offset))
        throw InputError(SourceLocation{file.string(), 0, 0, ""}, "is not a TrueType font stb_truetype can read.");
    stbtt_GetFontVMetrics(&f.impl_->info, &f.impl_->ascent, &f.impl_->descent, &f.impl_->line_gap);
    return f;
}

Font::~Font() = default;
Font::Font(Font&&) noexcept = default;
Font& Font::operator=(Font&&) noexcept = default;

double Font::line_width(std::string_view utf8, double pixel_height) const {
    const std::vector<char32_t> cps = decode_utf8(utf8);
    return impl_->width(std::u32string(cps.begin(), cps.end()), impl_->scale(pixel_height));
}

TextBitmap Font::render(std::string_view utf8, double pixel_height, int max_width_px, TextAlign align) const {
    const Impl& m = *impl_;
    const float s = m.scale(pixel_height);
    const std::vector<char32_t> cps = decode_utf8(utf8);

    // Lines: paragraphs at '\n', words wrapped at spaces.
    std::vector<std::u32string> lines;
    std::u32string para;
    auto flush_paragraph = [&] {
        std::u32string line;
        std::size_t i = 0;
        while (i <= para.size()) {
            std::size_t j = para.find(U' ', i);
            if (j == std::u32string::npos) j = para.size();
            const std::u32string word = para.substr(i, j - i);
            std::u32string candidate = line.empty() ? word : line + U' ' + word;
            if (!line.empty() && m.width(candidate, s) > max_width_px) {
                lines.push_back(line);
                line = word;
            } else {
                line = std::move(candidate);
            }
            i = j + 1;
        }
        lines.push_back(line);
        para.clear();
    };
    for (const char32_t c : cps) {
        if (c == U'\n') {
            flush_paragraph();
        } else if (c != U'\r') {
            para.push_back(c == U'\t' ? U' ' : c);
        }
    }
    flush_paragraph();

    const double scale = s;
    const double line_height = (m.ascent - m.descent + m.line_gap) * scale;
    const double baseline0 = m.ascent * scale;
    double widest = 0.0;
    for (const std::u32string& l : lines) widest = std::max(widest, m.width(l, s));
    TextBitmap bmp;
    // (− 1e-3: a height of exactly n px, up to the float scale's rounding, is n px.)
    bmp.width = std::max(1, static_cast<int>(std::ceil(widest - 1e-3)) + 2);
    bmp.height = std::max(1, static_cast<int>(std::ceil(line_height * static_cast<double>(lines.size()) - 1e-3)) + 2);
    bmp.coverage.assign(static_cast<std::size_t>(bmp.width) * static_cast<std::size_t>(bmp.height), 0.0f);

    std::vector<unsigned char> glyph;
    for (std::size_t li = 0; li < lines.size(); ++li) {
        const std::u32string& line = lines[li];
        const double w = m.width(line, s);
        double pen = 1.0 + (align == TextAlign::centre ? 0.5 * (widest - w) : 0.0);
        const double baseline = 1.0 + baseline0 + line_height * static_cast<double>(li);
        for (std::size_t i = 0; i < line.size(); ++i) {
            const int cp = static_cast<int>(line[i]);
            const double x = pen;
            pen += m.advance(line[i], i + 1 < line.size() ? line[i + 1] : 0) * scale;
            if (cp == ' ') continue;
            // Sub-pixel placement in x so the spacing of a line does not drift.
            const float shift_x = static_cast<float>(x - std::floor(x));
            int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
            stbtt_GetCodepointBitmapBoxSubpixel(&m.info, cp, s, s, shift_x, 0.0f, &x0, &y0, &x1, &y1);
            const int gw = x1 - x0, gh = y1 - y0;
            if (gw <= 0 || gh <= 0) continue;
            glyph.assign(static_cast<std::size_t>(gw) * static_cast<std::size_t>(gh), 0);
            stbtt_MakeCodepointBitmapSubpixel(&m.info, glyph.data(), gw, gh, gw, s, s, shift_x, 0.0f, cp);
            const int ox = static_cast<int>(std::floor(x)) + x0;
            const int oy = static_cast<int>(std::lround(baseline)) + y0;
            for (int v = 0; v < gh; ++v) {
                const int yy = oy + v;
                if (yy < 0 || yy >= bmp.height) continue;
                for (int u = 0; u < gw; ++u) {
                    const int xx = ox + u;
                    if (xx < 0 || xx >= bmp.width) continue;
                    float& dst = bmp.coverage[static_cast<std::size_t>(yy) * static_cast<std::size_t>(bmp.width) +
                                              static_cast<std::size_t>(xx)];
                    const float a = glyph[static_cast<std::size_t>(v) * static_cast<std::size_t>(gw) +
                                          static_cast<std::size_t>(u)] /
                                    255.0f;
                    dst = std::min(1.0f, dst + a);  // overlapping glyph edges add up, capped
                }
            }
        }
    }
    return bmp;
}

void blend_text(stimuli::EncodedImage& image, const TextBitmap& text, int x, int y,
                const std::array<std::uint16_t, 3>& ink) {
    for (int v = 0; v < text.height; ++v) {
        const int yy = y + v;
        if (yy < 0 || yy >= image.height) continue;
        for (int u = 0; u < text.width; ++u) {
            const int xx = x + u;
            if (xx < 0 || xx >= image.width) continue;
            const double a = text.at(u, v);
            if (a <= 0.0) continue;
            const std::size_t i =
                (static_cast<std::size_t>(yy) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(xx)) *
                3;
            for (std::size_t c = 0; c < 3; ++c) {
                const double bg = image.rgb[i + c];
                image.rgb[i + c] = static_cast<std::uint16_t>(std::lround(bg + (ink[c] - bg) * a));
            }
        }
    }
}

TextBitmap fixation_cross(int arm_px, int thickness_px) {
    TextBitmap b;
    arm_px = std::max(1, arm_px);
    thickness_px = std::max(1, std::min(thickness_px, 2 * arm_px + 1));
    b.width = b.height = 2 * arm_px + 1;
    b.coverage.assign(static_cast<std::size_t>(b.width) * static_cast<std::size_t>(b.height), 0.0f);
    // A bar of odd or even thickness, centred on pixel arm_px as evenly as it can be.
    const int lo = arm_px - thickness_px / 2;
    const int hi = lo + thickness_px;  // exclusive
    for (int y = 0; y < b.height; ++y)
        for (int x = 0; x < b.width; ++x)
            if ((y >= lo && y < hi) || (x >= lo && x < hi))
                b.coverage[static_cast<std::size_t>(y) * static_cast<std::size_t>(b.width) +
                           static_cast<std::size_t>(x)] = 1.0f;
    return b;
}

}  // namespace atonlab::present
