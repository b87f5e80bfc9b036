#pragma once
// What every bench shares: options, the results it adds to, the bench scenes
// and the error metrics.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "atonlab/bench/bench.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/scene.h"
#include "results.h"

namespace atonlab::bench {

struct Bench {
    const BenchOptions& options;
    std::vector<Row> rows;
    std::vector<ScalePoint> points;
    std::vector<std::string> scaling_notes;
    /// Further files a bench writes into the output directory: (name, Markdown).
    std::vector<std::pair<std::string, std::string>> documents;

    bool quick() const { return options.quick; }
    /// Repeats: two in the quick form.
    TimeSpec spec(int full_repeats, bool gpu_timer, int warmup = 1) const {
        return TimeSpec{warmup, quick() ? std::min(full_repeats, 2) : full_repeats, gpu_timer};
    }
    void add(Row r);
    void add(ScalePoint p);
};

// ---- scenes ------------------------------------------------------------------

/// The display atonlab's scenes default to (1920×1080, 0.598 m at 0.9 m: 50.4 px/°).
display::DisplayGeometry default_display();

/// How the lights of the K2012 table 6.2 scene are placed.
enum class Layout {
    overlapping,  ///< a cluster 4° × 2° at 1 km, 100 cd: every billboard overlaps the others (K2012 fig 6.19)
    apart,        ///< spread over the whole view, 0.5–10 km, 0.01 … 10 000 cd (log-uniform): a harbour approach
    behind,       ///< behind the camera: culled by the frustum
    dark,         ///< in view but dark in their rhythm at t = 5 s (Fl 10s): culled by E = 0
    dim,          ///< in view, 1e-4 cd at 5 km: culled as invisible by the display skips
};
std::string layout_name(Layout l);

/// K2012 §6.2: 1280×720 px at 45° vertical field of view (display geometry
/// chosen to match, 15.2 px/°), sky and sea at 0.01 cd/m² (mesopic), fixed
/// adaptation 0.01 cd/m², wave-optics glare with the default eye and PSF,
/// empirical tone mapping, sRGB display. `width_px` scales the image (and the
/// display, keeping 45°) for the quick form.
stimuli::Scene k2012_scene(int lights, Layout layout, unsigned seed = 1, int width_px = 1280);

// ---- metrics -----------------------------------------------------------------

/// Σ L·Ω over an HDR frame (top row first): the illuminance (lux, Y) it holds.
double frame_illuminance_lux(const stimuli::ImageRGBA32F& img, double focal_px);

/// The largest change of any channel's continuous display code (before dither)
/// between two HDR frames (cd/m²), each tone-mapped by the CPU double reference
/// at its own adaptation (cd/m²) and encoded by the scene's display model.
double max_code_change(const stimuli::ImageRGBA32F& a, double adaptation_a, const stimuli::ImageRGBA32F& b,
                       double adaptation_b, const stimuli::OutputSettings& out);

// ---- the benches (bench_*.cpp) -------------------------------------------------

void bench_psf_size(Bench& b);
void bench_spectral_samples(Bench& b);
void bench_cie_veil(Bench& b);
void bench_cie_veil_methods(Bench& b);  // bench_realtime.cpp (issue 27)
void bench_psf_rebuild(Bench& b);
void bench_moving_pupil(Bench& b);
void bench_fft(Bench& b);
void bench_pupil_tolerance(Bench& b);
void bench_area_layers(Bench& b);
void bench_hdr_format(Bench& b);
void bench_adaptation_stride(Bench& b);
void bench_tonemap(Bench& b);
void bench_tonemap_pfstools(Bench& b);
void bench_display_skips(Bench& b);
void bench_lights(Bench& b);
void bench_simulator_frames(Bench& b);  // bench_simulator.cpp (issue 27 item 4)
void bench_eye_validation(Bench& b);

}  // namespace atonlab::bench
