// `atonlab tonemap --operator reinhard` against pfstools' pfstmo_reinhard02 on
// the same EXR (docs/tone-mapping.md "HDR images in and out"): each from the
// EXR on disk to display values, the parameters matched as the test
// GL.ImageCommands.TonemapReinhardMatchesPfstmoReinhard02 matches them. Skipped
// (no rows) when pfstools is not installed.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/display/display_model.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/tonemap.h"
#include "bench_common.h"

namespace atonlab::bench {

using namespace atonlab::stimuli;
using namespace atonlab::display;

void bench_tonemap_pfstools(Bench& b) {
    if (std::system("command -v pfstmo_reinhard02 > /dev/null 2>&1 && command -v pfsoutpfm > /dev/null 2>&1") != 0) {
        std::printf(
            "  tonemap_pfstools: skipped: pfstmo_reinhard02 or pfsoutpfm is not installed (Debian packages "
            "pfstmo, pfstools; scripts/setup.sh installs them)\n");
        return;
    }
    // A rendered frame (the other frame benches' scene) as an EXR on disk.
    Scene scene = b.quick() ? k2012_scene(20, Layout::apart, 7, 320) : k2012_scene(100, Layout::apart, 7);
    FrameRenderer renderer;
    renderer.render(scene, 0.0);
    const ImageRGBA32F frame = renderer.read_hdr();
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / fmt::format("atonlab-bench-pfstools-{}", ::getpid());
    std::filesystem::create_directories(dir);
    const std::filesystem::path exr = dir / "frame.exr", png = dir / "atonlab.png", pfm = dir / "pfs.pfm";
    write_exr(exr, frame, ExrMetadata{}, ExrPixelType::float32);

    // What `atonlab tonemap --operator reinhard --reinhard-white max --epsilon-cd-m2 1e-5
    // --blueshift off --hue-preservation none --black-cd-m2 0 --dither off` does.
    OutputSettings out;
    out.display = DisplayModel::srgb(100.0, 0.0);
    out.encode.dither = Dither::none;
    out.tonemap.tone_operator = ToneOperator::reinhard;
    out.tonemap.blueshift = false;
    out.tonemap.hue_preservation = HuePreservation::none;
    std::vector<int> ours;
    auto atonlab_tonemap = [&] {
        const ImageRGBA32F hdr = read_exr(exr).image;
        const double la = log_average_luminance(hdr, 1e-5);
        double max_l = 0;
        for (std::size_t i = 0; i < hdr.rgba.size(); i += 4)
            max_l = std::max(max_l, 0.2126 * hdr.rgba[i] + 0.7152 * hdr.rgba[i + 1] + 0.0722 * hdr.rgba[i + 2]);
        ToneMapSettings tm = out.tonemap;
        tm.reinhard_white_relative = tm.reinhard_key * max_l / la;
        std::vector<float> v(static_cast<std::size_t>(hdr.width) * hdr.height * 3);
        ours.assign(v.size(), 0);
        for (int y = 0; y < hdr.height; ++y)
            for (int x = 0; x < hdr.width; ++x) {
                const float* p = hdr.pixel(x, y);
                const glm::ivec3 c =
                    encode_pixel(out.display, tonemap_pixel({p[0], p[1], p[2]}, la, tm), {x, y}, 0, out.encode);
                for (int k = 0; k < 3; ++k) {
                    const std::size_t o = (static_cast<std::size_t>(y) * hdr.width + x) * 3 + k;
                    ours[o] = c[k];
                    v[o] = static_cast<float>(c[k] / 255.0);
                }
            }
        write_png_rgb8(png, hdr.width, hdr.height, v);
    };
    const std::string pfs_command =
        fmt::format("pfsin '{}' | pfstmo_reinhard02 --key 0.18 | pfsoutpfm '{}'", exr.string(), pfm.string());
    int pfs_status = 0;
    auto pfstools = [&] { pfs_status = std::system(pfs_command.c_str()); };
    const std::vector<Timing> times = measure_interleaved({atonlab_tonemap, pfstools}, b.spec(5, false));

    std::vector<float> theirs;  // empty: pfstools failed, or its PFM is not this frame's size
    if (pfs_status == 0) {
        try {
            int w = 0, h = 0;
            theirs = read_pfm_rgb(pfm, w, h);
            if (w != frame.width || h != frame.height) theirs.clear();
        } catch (const InputError&) {
            theirs.clear();
        }
    }
    double sum = 0;
    int worst = 0;
    for (std::size_t i = 0; i < theirs.size(); ++i) {
        // IEC 61966-2-1 encoding of pfstools' linear display value, rounded.
        const double v = std::clamp(static_cast<double>(theirs[i]), 0.0, 1.0);
        const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
        const int d = std::abs(ours[i] - static_cast<int>(std::lround(255.0 * e)));
        sum += d;
        worst = std::max(worst, d);
    }
    const double mean = theirs.empty() ? kNaN : sum / static_cast<double>(theirs.size());
    const std::string metric = "mean |display code difference| (8 bit) vs pfstmo_reinhard02, sRGB-rounded";
    Row a;
    a.bench = "tonemap_pfstools";
    a.setting = "atonlab tonemap (CPU double)";
    a.is_default = true;
    a.time = times[0];
    a.error = mean;
    a.codes = theirs.empty() ? kNaN : worst;
    a.metric = metric;
    a.note = fmt::format(
        "{}x{} px; in-process: EXR read, log-average, Reinhard 2002 global, sRGB encode, PNG write; "
        "one thread; max difference {} code",
        frame.width, frame.height, worst);
    b.add(a);
    Row p;
    p.bench = "tonemap_pfstools";
    p.setting = "pfsin | pfstmo_reinhard02 | pfsoutpfm";
    p.time = times[1];
    p.error = 0;
    p.codes = 0;
    p.metric = metric;
    p.note = pfs_status == 0 ? "three processes (pfstools 2.1.0), float PFM out (no encoding)"
                             : fmt::format("pfstools failed (status {})", pfs_status);
    b.add(p);
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
}

}  // namespace atonlab::bench
