// The report's stimulus pictures (snapshot_picture.h; docs/analysis.md,
// "Stimulus pictures").
#include "snapshot_picture.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <span>

#include "atonlab/display/colour.h"
#include "atonlab/display/gamut.h"
#include "atonlab/display/tonemap.h"
#include "atonlab/stimuli/image_io.h"
#include "session/snapshot.h"

namespace atonlab::runner {

namespace an = atonlab::analysis;
namespace fs = std::filesystem;

namespace {

/// The side of each tile: a square of 6° around each judged light (docs/analysis.md, "Outputs").
constexpr double kCropDeg = 6.0;

/// The frames of a snapshot EXR: "rows A-B: frame F (role); ..." (run_session.cpp).
std::vector<std::pair<int, int>> frame_rows(const std::string& note, int height) {
    std::vector<std::pair<int, int>> out;
    std::size_t at = 0;
    while ((at = note.find("rows ", at)) != std::string::npos) {
        int a = 0, b = 0;
        if (std::sscanf(note.c_str() + at, "rows %d-%d", &a, &b) == 2 && a >= 0 && b >= a && b < height)
            out.emplace_back(a, b);
        at += 5;
    }
    if (out.empty()) out.emplace_back(0, height - 1);
    return out;
}

struct Tile {
    int x0, y0, w, h;
    std::string
        label;  ///< what the tile shows: "frame 0 test (red, F, glare none)"; empty: its frame's brightest pixel
};

/// Per frame (rows r0-r1), a tile of up to 2*half pixels square around its brightest pixel.
std::vector<Tile> brightest_tiles(const stimuli::ImageRGBA32F& hdr, const std::vector<std::pair<int, int>>& frames,
                                  int half) {
    std::vector<Tile> tiles;
    for (const auto& [r0, r1] : frames) {
        int bx = hdr.width / 2, by = (r0 + r1) / 2;
        double best = -1.0;
        for (int y = r0; y <= r1; ++y) {
            for (int x = 0; x < hdr.width; ++x) {
                const float* p = hdr.pixel(x, y);
                const double lum = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                if (lum > best) {
                    best = lum;
                    bx = x;
                    by = y;
                }
            }
        }
        const int w = std::min(2 * half, hdr.width), h = std::min(2 * half, r1 - r0 + 1);
        const int x0 = std::clamp(bx - w / 2, 0, hdr.width - w);
        const int y0 = std::clamp(by - h / 2, r0, r1 + 1 - h);
        tiles.push_back({x0, y0, w, h, {}});
    }
    return tiles;
}

/// A judged light as the caption names it.
std::string light_label(const an::LightLook& l, const std::string& glare) {
    std::string out = l.colour.empty() ? std::string() : fmt::format("{}, {}", l.colour, l.rhythm);
    if (!l.spectrum.empty()) out += ", spd " + l.spectrum;
    if (!glare.empty()) out += (out.empty() ? "glare " : ", glare ") + glare;
    return out;
}

/// A tile around every judged light the snapshot's "lights" attribute places
/// (snapshot.cpp: "frame F ROLE at X,Y (LIGHT); ..."), so that a side-by-side
/// frame shows both its lights; two lights of a frame closer than half a tile
/// share one tile. Empty for a snapshot without the attribute (made before it).
std::vector<Tile> light_tiles(const stimuli::ImageRGBA32F& hdr, const std::vector<std::pair<int, int>>& frames,
                              const std::string& note, int half, const an::ConditionInfo& c) {
    struct Placed {
        int frame;
        double x, y;
        std::string label;
    };
    std::vector<Placed> placed;
    for (std::size_t at = 0; at < note.size();) {
        const std::size_t end = std::min(note.find("; ", at), note.size());
        const std::string item = note.substr(at, end - at);
        at = end + 2;
        int f = 0;
        char role[16] = {};
        double x = 0.0, y = 0.0;
        if (std::sscanf(item.c_str(), "frame %d %15s at %lf,%lf", &f, role, &x, &y) != 4 || f < 0 ||
            static_cast<std::size_t>(f) >= frames.size() || !std::isfinite(x) || !std::isfinite(y))
            continue;
        const bool test = std::string_view(role) == "test";
        const std::string look =
            test ? light_label(c.test_look, c.glare_test) : light_label(c.reference_look, c.glare_reference);
        placed.push_back({f, x, y, fmt::format("frame {} {}{}", f, role, look.empty() ? "" : " (" + look + ")")});
    }
    std::vector<Tile> tiles;
    std::vector<bool> used(placed.size(), false);
    for (std::size_t i = 0; i < placed.size(); ++i) {
        if (used[i]) continue;
        double x = placed[i].x, y = placed[i].y;
        std::string label = placed[i].label;
        for (std::size_t j = i + 1; j < placed.size(); ++j)
            if (!used[j] && placed[j].frame == placed[i].frame && std::abs(placed[j].x - placed[i].x) < 0.5 * half &&
                std::abs(placed[j].y - placed[i].y) < 0.5 * half) {
                used[j] = true;
                x = 0.5 * (x + placed[j].x);
                y = 0.5 * (y + placed[j].y);
                label += " and " + placed[j].label;
            }
        const auto [r0, r1] = frames[static_cast<std::size_t>(placed[i].frame)];
        const int w = std::min(2 * half, hdr.width), h = std::min(2 * half, r1 - r0 + 1);
        const int x0 = std::clamp(static_cast<int>(std::lround(x)) - w / 2, 0, hdr.width - w);
        const int y0 = std::clamp(static_cast<int>(std::lround(y)) - h / 2, r0, r1 + 1 - h);
        tiles.push_back({x0, y0, w, h, label});
    }
    return tiles;
}

// Each frame tone-mapped (display-relative linear values, 0..1), then drawn
// twice: as is (top row) and, beneath it, stretched about its background
// (the tile's median) by a power of two that brings its brightest pixel
// near white, so that a dim light and its glare can be seen (docs/analysis.md,
// "Stimulus pictures"). The factors are stated in the caption.
struct Mapped {
    std::vector<glm::dvec3> v;
    glm::dvec3 background{0.0};  ///< per channel: the tile's median (a dim light leaves it the background)
    double stretch = 1.0;
};

/// The tile tone-mapped, with its background and the stretch that shows a dim light.
/// scotopic: the image's A is each pixel's scotopic luminance (scotopic cd/m²), the rod signal the
/// session's tone mapper read (docs/tone-mapping.md "The scotopic channel"); else the RGB weights'.
Mapped map_tile(const stimuli::ImageRGBA32F& hdr, const Tile& t, double adaptation, const display::ToneMapSettings& tm,
                bool scotopic) {
    Mapped m;
    std::array<std::vector<double>, 3> channel;
    for (int y = 0; y < t.h; ++y)
        for (int x = 0; x < t.w; ++x) {
            const float* p = hdr.pixel(t.x0 + x, t.y0 + y);
            const glm::dvec3 rgb(p[0], p[1], p[2]);
            glm::dvec3 d = scotopic ? display::tonemap_pixel(rgb, p[3], adaptation, tm)
                                    : display::tonemap_pixel(rgb, adaptation, tm);
            for (int k = 0; k < 3; ++k) {
                d[k] = std::clamp(d[k], 0.0, 1.0);
                channel[static_cast<std::size_t>(k)].push_back(d[k]);
            }
            m.v.push_back(d);
        }
    for (int k = 0; k < 3; ++k) {
        std::vector<double>& values = channel[static_cast<std::size_t>(k)];
        if (values.empty()) continue;
        std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
        m.background[k] = values[values.size() / 2];
    }
    // A power of two, 1 to 4096: the largest that keeps every channel's
    // rise above the background at or below 90% of white, or, where a glare
    // halo covers more than 1% of the tile, the one that brings the halo's
    // edge there (the rise of the pixel ranked at 1%) to half of that,
    // letting the core clip: what the reader needs to see is the halo.
    std::vector<double> rises;
    double room = 1.0, top = 0.0;
    for (const glm::dvec3& d : m.v) {
        double r = 0.0;
        for (int k = 0; k < 3; ++k)
            if (d[k] - m.background[k] > r) r = d[k] - m.background[k];
        rises.push_back(r);
        if (r > top) {
            top = r;
            room = 0.9 - std::max({m.background.r, m.background.g, m.background.b});
        }
    }
    if (top > 0.0 && room > 0.0) {
        double factor = room / top;
        const std::size_t rank = rises.size() / 100;
        std::nth_element(rises.begin(), rises.begin() + static_cast<std::ptrdiff_t>(rank), rises.end(),
                         std::greater<>());
        if (rises[rank] > 0.0) factor = std::max(factor, 0.5 * room / rises[rank]);
        m.stretch = std::clamp(std::exp2(std::floor(std::log2(factor))), 1.0, 4096.0);
    }
    return m;
}

/// How one frame is tone-mapped here.
struct FrameShown {
    display::ToneMapSettings tonemap;
    double adaptation_cd_m2 = 1.0;
    bool recorded = false;   ///< from the snapshot's "tonemap" attribute (else today's defaults but the operator)
    bool ldr_glare = false;  ///< the session tone-mapped the glare on its own, from a buffer the snapshot lacks
};

/// The frame (index into frames) whose rows hold row y.
std::size_t frame_of(const std::vector<std::pair<int, int>>& frames, int y) {
    for (std::size_t i = 0; i < frames.size(); ++i)
        if (y >= frames[i].first && y <= frames[i].second) return i;
    return 0;
}

/// Per frame, the settings the session's display pass used, as the snapshot
/// records them ("tonemap", snapshot.h); for a snapshot stored before that
/// record, the defaults with the condition's operator at its adaptation
/// luminance (else the EXR's, else 1 cd/m²), as before.
std::vector<FrameShown> frames_shown(const stimuli::ExrImage& img, const std::vector<std::pair<int, int>>& frames,
                                     const an::ConditionInfo& c) {
    const auto at = img.meta.strings.find("tonemap");
    const auto recorded = at == img.meta.strings.end() ? std::nullopt : read_snapshot_tonemap(at->second);
    std::vector<FrameShown> out;
    for (std::size_t i = 0; i < frames.size(); ++i) {
        FrameShown f;
        if (recorded && recorded->size() == frames.size()) {
            const SnapshotToneMap& r = (*recorded)[i];
            f.tonemap = r.tonemap;
            f.recorded = true;
            f.ldr_glare = r.ldr_glare;
            f.adaptation_cd_m2 = r.adaptation_cd_m2;
            if (r.dynamic) {
                // The session's display pass adopts the frame's own log-average after its reset
                // (StimulusRenderer::encode_scene; K2012 eq 4.15): every pixel of the frame's rows.
                const auto [r0, r1] = frames[i];
                const std::size_t offset = static_cast<std::size_t>(r0) * img.image.width * 4;
                const std::size_t pixels = static_cast<std::size_t>(r1 - r0 + 1) * img.image.width;
                f.adaptation_cd_m2 = display::log_average_luminance(
                    std::span<const float>(img.image.rgba).subspan(offset, pixels * 4), pixels, r.epsilon_cd_m2);
            }
        } else {
            if (const auto op = display::tone_operator_from_name(c.tone_operator)) f.tonemap.tone_operator = *op;
            f.adaptation_cd_m2 = c.adaptation_cd_m2.value_or(img.meta.adaptation_cd_m2.value_or(1.0));
        }
        out.push_back(f);
    }
    return out;
}

/// "perceptual at 0.05 cd/m² (blueshift pixel, hue preservation xyY, mesopic k2012, out of gamut
/// keep-luminance, display peak 100 cd/m²)"; without the parenthesis where the snapshot has no record.
std::string shown_phrase(const FrameShown& f) {
    const display::ToneMapSettings& t = f.tonemap;
    std::string s = fmt::format("{} at {:g} cd/m²", display::tone_operator_name(t.tone_operator), f.adaptation_cd_m2);
    if (!f.recorded) return s;
    return s +
           fmt::format(" (blueshift {}, hue preservation {}, mesopic {}, out of gamut {}, display peak {:g} cd/m²{})",
                       t.blueshift ? display::blueshift_luminance_name(t.blueshift_luminance) : "off",
                       display::hue_preservation_name(t.hue_preservation), display::mesopic_model_name(t.mesopic),
                       display::out_of_gamut_name(t.out_of_gamut), t.display_peak_cd_m2,
                       f.ldr_glare ? "; ldr_glare: the session tone-mapped the glare on its own, from a buffer "
                                     "the snapshot does not hold, so no glare is shown"
                                   : "");
}

/// The caption; factors: the stretches ("×64, ×1"), empty for one row.
std::string snapshot_caption(const an::ConditionInfo& c, const stimuli::ExrImage& img, const std::vector<Tile>& tiles,
                             const std::vector<FrameShown>& shown, const std::string& factors) {
    std::string placed;
    for (const Tile& t : tiles) placed += (placed.empty() ? "" : "; ") + t.label;
    std::string how = shown_phrase(shown.front());
    if (std::any_of(shown.begin(), shown.end(), [&](const FrameShown& f) { return shown_phrase(f) != how; })) {
        how.clear();
        for (std::size_t i = 0; i < shown.size(); ++i)
            how += fmt::format("{}frame {}: {}", i ? "; " : "", i, shown_phrase(shown[i]));
    }
    const std::string rods = img.has_alpha
                                 ? "the rod signal of each pixel's own scotopic luminance (the EXR's A)"
                                 : "the rod signal of the RGB weights (a snapshot stored without the scotopic channel)";
    return fmt::format(
        "The stimulus of condition {} as the session rendered it (stored EXR, cd/m²; frames in presentation order: "
        "{}), {} and shown here with the tone mapper {}, {}, and the sRGB curve (the CPU reference, not the "
        "calibrated display encoding).{}",
        c.condition, img.meta.strings.count("frames") ? img.meta.strings.at("frames") : "one frame",
        tiles.front().label.empty()
            ? fmt::format("each frame cropped to {:g}° around its brightest pixel, left to right", kCropDeg)
            : fmt::format("cropped to {:g}° around each judged light, left to right: {}", kCropDeg, placed),
        how, rods,
        !factors.empty()
            ? fmt::format(" Top row: as displayed. Bottom row: the same frames, each channel stretched about its "
                          "background (the tile's median) by {} (left to right), so that a dim light and its glare "
                          "can be seen (a glare core may clip there); the stretch is for the reader, not what the "
                          "observer saw.",
                          factors)
            : std::string(" No frame is dim enough to need a stretched copy."));
}

}  // namespace

std::string snapshot_png(const store::Snapshot& snap, const an::ConditionInfo& c, const fs::path& png,
                         std::string& caption) {
    if (snap.format != "exr") return fmt::format("its format is \"{}\", not exr", snap.format);
    const fs::path exr = fs::temp_directory_path() / fmt::format("atonlab-analyze-{}-snapshot.exr", getpid());
    {
        std::ofstream out(exr, std::ios::binary);
        out.write(reinterpret_cast<const char*>(snap.data.data()), static_cast<std::streamsize>(snap.data.size()));
        if (!out) return "it could not be written to a temporary file";
    }
    stimuli::ExrImage img;
    try {
        img = stimuli::read_exr(exr);
    } catch (const std::exception& e) {
        std::error_code ec;
        fs::remove(exr, ec);
        return e.what();
    }
    std::error_code ec;
    fs::remove(exr, ec);
    const stimuli::ImageRGBA32F& hdr = img.image;
    if (hdr.width <= 0 || hdr.height <= 0) return "the image is empty";
    const int half = img.meta.degrees_per_pixel > 0.0
                         ? std::max(8, static_cast<int>(std::lround(0.5 * kCropDeg / img.meta.degrees_per_pixel)))
                         : 128;
    const auto frames = frame_rows(img.meta.strings.count("frames") ? img.meta.strings.at("frames") : "", hdr.height);
    std::vector<Tile> tiles =
        light_tiles(hdr, frames, img.meta.strings.count("lights") ? img.meta.strings.at("lights") : "", half, c);
    if (tiles.empty()) tiles = brightest_tiles(hdr, frames, half);
    const std::vector<FrameShown> shown = frames_shown(img, frames, c);
    std::vector<Mapped> mapped;
    for (const Tile& t : tiles) {
        const FrameShown& f = shown[frame_of(frames, t.y0)];
        mapped.push_back(map_tile(hdr, t, f.adaptation_cd_m2, f.tonemap, img.has_alpha));
    }
    const int gap = 8;
    int width = 0, row = 0;
    for (const Tile& t : tiles) {
        width += t.w + (width ? gap : 0);
        row = std::max(row, t.h);
    }
    // Nothing dim enough to need it: one row.
    const bool stretched_row =
        std::any_of(mapped.begin(), mapped.end(), [](const Mapped& m) { return m.stretch > 1.0; });
    const int height = stretched_row ? 2 * row + gap : row;
    std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3, 1.0f);  // white gaps
    int left = 0;
    for (std::size_t i = 0; i < tiles.size(); ++i) {
        const Tile& t = tiles[i];
        const Mapped& m = mapped[i];
        for (int y = 0; y < t.h; ++y) {
            for (int x = 0; x < t.w; ++x) {
                const glm::dvec3& d = m.v[static_cast<std::size_t>(y) * t.w + x];
                float* q = &rgb[(static_cast<std::size_t>(y) * width + left + x) * 3];
                for (int k = 0; k < 3; ++k) q[k] = static_cast<float>(display::srgb_encode(d[k]));
                if (!stretched_row) continue;
                float* r = &rgb[(static_cast<std::size_t>(y + row + gap) * width + left + x) * 3];
                for (int k = 0; k < 3; ++k) {
                    const double stretched = m.background[k] + m.stretch * (d[k] - m.background[k]);
                    r[k] = static_cast<float>(display::srgb_encode(std::clamp(stretched, 0.0, 1.0)));
                }
            }
        }
        left += t.w + gap;
    }
    try {
        stimuli::write_png_rgb8(png, width, height, rgb);
    } catch (const std::exception& e) {
        return e.what();
    }
    std::string factors;
    for (const Mapped& m : mapped) factors += fmt::format("{}×{:g}", factors.empty() ? "" : ", ", m.stretch);
    caption = snapshot_caption(c, img, tiles, shown, stretched_row ? factors : std::string());
    return {};
}

}  // namespace atonlab::runner
