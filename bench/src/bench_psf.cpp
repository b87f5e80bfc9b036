// The PSF's knobs (K2012 §4.2, §5.2): its size N, the spectral samples, the
// FFT (GPU fp32 with two twiddle sources, FFTW float, FFTW double), the PSF
// cache's pupil tolerance, and the area layers (§4.2.6).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>

#include "atonlab/stimuli/fft.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/glare_kernel.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/stimuli/psf.h"
#include "atonlab/stimuli/psf_generator.h"
#include "atonlab/stimuli/spectral_path.h"
#include "bench_common.h"

namespace atonlab::bench {

using namespace atonlab::stimuli;
using namespace atonlab::display;

namespace {

constexpr int kDefaultN = 512;       // GlareSettings::psf_size
constexpr int kDefaultSamples = 30;  // GlareSettings::spectral_samples

/// The eye the PSF benches use: the default eye (two scales, in focus,
/// gratings, particles, halo at 4°) with a night pupil.
EyeModel bench_eye() {
    EyeModel e;
    e.pupil_diameter_mm = 6.0;
    return e;
}

/// ‖a − ref‖ / ‖ref‖ over all channels, the kernels centred on each other
/// (the smaller one zero-padded).
double kernel_relative_l2(const GlareKernel& a, const GlareKernel& ref) {
    const int ha = a.half(), hr = ref.half(), h = std::max(ha, hr);
    double num = 0, den = 0;
    for (int y = -h; y <= h; ++y)
        for (int x = -h; x <= h; ++x) {
            glm::dvec3 va(0.0), vr(0.0);
            if (std::abs(x) <= ha && std::abs(y) <= ha) va = glm::dvec3(a.at(x + ha, y + ha));
            if (std::abs(x) <= hr && std::abs(y) <= hr) vr = glm::dvec3(ref.at(x + hr, y + hr));
            const glm::dvec3 d = va - vr;
            num += glm::dot(d, d);
            den += glm::dot(vr, vr);
        }
    return std::sqrt(num / den);
}

double glare_radius_deg(int n, double dpt) {
    GlareSettings g;
    g.model = GlareModel::wave_optics;
    g.psf_size = n;
    return default_glare_radius_deg(g, dpt);
}

}  // namespace

void bench_psf_size(Bench& b) {
    const std::vector<int> sizes = b.quick() ? std::vector<int>{64, 128} : std::vector<int>{128, 256, 512, 1024, 2048};
    const int n_ref = sizes.back();
    const EyeModel eye = bench_eye();
    const double ppd = default_display().pixels_per_degree_at_centre();
    const double dpt = psf_degrees_per_texel(eye);
    const SpectralSamples samples = spectral_samples(d65_spectrum(), kDefaultSamples);
    // Every kernel is cut at the default N's billboard radius (3.1°), or at what
    // a smaller N covers: the error includes the glare a small N cannot reach.
    const double r_default = glare_radius_deg(b.quick() ? sizes.back() : kDefaultN, dpt);
    if (b.options.verbose) std::printf("psf_size: double-precision reference at N = %d ...\n", n_ref);
    const RgbPsf ref_psf = spectral_psf_resampled(mono_psf_reference(eye, n_ref, kReferenceWavelengthNm), samples);
    const GlareKernel ref = glare_kernel_from_psf(ref_psf, ppd, r_default, GlareWindow::silverman);
    for (int n : sizes) {
        const double radius = std::min(r_default, glare_radius_deg(n, dpt));
        GpuPsfGenerator gen(n);
        GlareKernel kernel;
        const TimeSpec spec = n >= 2048 ? TimeSpec{1, 3, false} : b.spec(5, false);
        const Timing t = measure(
            [&] {
                gen.generate(eye, samples);
                kernel = glare_kernel_from_psf(gen.read_rgb(), ppd, radius, GlareWindow::silverman);
                const PsfGpuTimings g = gen.timings();
                return g.upload_ms + g.fft_ms + g.mono_ms + g.spectral_ms;
            },
            spec);
        Row r;
        r.bench = "psf_size";
        r.setting = fmt::format("N={}", n);
        r.is_default = n == kDefaultN;
        r.time = t;
        r.error = kernel_relative_l2(kernel, ref);
        r.metric = fmt::format("relative L2 of the display kernel vs N={} double", n_ref);
        r.note = t.gpu.n > 0 ? fmt::format("rebuild: pupil plane + GPU PSF ({:.0f} ms GPU) + kernel; radius {:.2f}°",
                                           t.gpu.median, radius)
                             : fmt::format("rebuild: pupil plane + PSF + kernel; radius {:.2f}°", radius);
        b.add(r);
    }
}

namespace {

// The spectral paths at the default N and count, for one eye: the anchored
// default (spectral_path.h), eq 4.9's one rescaled λ0 PSF (GPU), and the exact
// per-wavelength path; the reference is the exact path at many wavelengths.
void spectral_path_for(Bench& b, const EyeModel& eye, const std::string& bench, const std::string& eye_note) {
    const int n = b.quick() ? 64 : kDefaultN;
    const int k_ref = b.quick() ? 32 : 120;
    if (b.options.verbose)
        std::printf("%s: exact reference, %d wavelengths at N = %d (FFTW double each) ...\n", bench.c_str(), k_ref, n);
    const RgbPsf ref = spectral_psf_exact(eye, n, spectral_samples(d65_spectrum(), k_ref));
    const SpectralSamples samples = spectral_samples(d65_spectrum(), kDefaultSamples);
    const std::string metric = fmt::format("relative L2 of the RGB PSF vs exact {} wavelengths (N={})", k_ref, n);

    // The two CPU paths interleaved, so a load that changes during the run
    // (the VM is shared) weighs on both alike.
    const int anchors = GlareSettings{}.spectral_anchors;
    RgbPsf exact, anchored;
    const std::vector<Timing> cpu_paths =
        measure_interleaved({[&] { exact = spectral_psf_exact(eye, n, samples); },
                             [&] { anchored = spectral_psf_anchored(eye, n, samples, anchors); }},
                            TimeSpec{b.quick() ? 0 : 1, b.quick() ? 1 : 5, false});
    const Timing& t_exact = cpu_paths[0];
    const Timing& t_anchored = cpu_paths[1];
    Row a;
    a.bench = bench;
    a.setting = fmt::format("anchored, {} anchors, {} samples", anchors, kDefaultSamples);
    a.is_default = true;
    a.time = t_anchored;
    a.error = relative_l2(anchored, ref);
    a.metric = metric;
    a.note = fmt::format(
        "CPU: FFTW fp32 at the anchors, cubic in 1/λ (linear for weak samples), Lanczos-3 rescaling; {:.4f} from the exact path at {} samples, "
        "in {:.2f} of its time{}",
        relative_l2(anchored, exact), kDefaultSamples, t_anchored.primary().median / t_exact.primary().median,
        eye_note);
    b.add(a);

    GpuPsfGenerator gen(n);
    const Timing fast = measure(
        [&] {
            gen.generate(eye, samples);
            return -1.0;
        },
        b.spec(5, false));
    Row f;
    f.bench = bench;
    f.setting = fmt::format("rescaled (eq 4.9), {} samples", kDefaultSamples);
    f.time = fast;
    f.error = relative_l2(gen.read_rgb(), ref);
    f.metric = metric;
    f.note = fmt::format("GPU: one λ0 PSF rescaled per wavelength; {:.4f} from the exact path{}",
                         relative_l2(gen.read_rgb(), exact), eye_note);
    b.add(f);

    Row e;
    e.bench = bench;
    e.setting = fmt::format("exact, {} samples", kDefaultSamples);
    e.time = t_exact;
    e.error = relative_l2(exact, ref);
    e.metric = metric;
    e.note = "CPU: pupil plane and FFTW double per wavelength" + eye_note;
    b.add(e);
}

}  // namespace

void bench_spectral_samples(Bench& b) {
    // The sample count alone: the fast path at each count against the same
    // path in double (spectral_psf_resampled, the CPU twin) at many samples.
    const int n = b.quick() ? 64 : 256;
    const int k_ref = b.quick() ? 32 : 120;
    const std::vector<int> counts =
        b.quick() ? std::vector<int>{4, 30} : std::vector<int>{4, 8, 15, 30, 60, 120};
    const EyeModel eye = bench_eye();
    const MonoPsf mono = mono_psf_reference(eye, n, kReferenceWavelengthNm);
    const RgbPsf ref = spectral_psf_resampled(mono, spectral_samples(d65_spectrum(), k_ref));
    GpuPsfGenerator gen(n);
    for (int k : counts) {
        const SpectralSamples samples = spectral_samples(d65_spectrum(), k);
        const Timing t = measure(
            [&] {
                gen.generate(mono, samples);
                return gen.timings().spectral_ms;
            },
            b.spec(7, false));
        Timing spectral = t;
        spectral.use_gpu = true;  // the spectral stage's own timer query (the whole generate() without one)
        Row r;
        r.bench = "spectral_samples";
        r.setting = fmt::format("{} samples", k);
        r.is_default = k == kDefaultSamples;
        r.time = spectral;
        r.error = relative_l2(gen.read_rgb(), ref);
        r.metric = fmt::format("relative L2 of the RGB PSF vs the same path in double at {} samples (N={})", k_ref, n);
        r.note = gpu_timer_trusted() ? "GPU eq 4.9 lookups; spectral stage timed"
                                     : "GPU eq 4.9 lookups; whole PSF generation timed";
        b.add(r);
    }
    // The fast path itself against the exact per-wavelength path.
    spectral_path_for(b, eye, "spectral_path", "");
    // The k2012 preset's Fresnel term E (eq 4.6) depends on the wavelength,
    // which eq 4.9's rescaling cannot follow; the default eye is in focus.
    EyeModel k2012 = EyeModel::k2012();
    k2012.pupil_diameter_mm = bench_eye().pupil_diameter_mm;
    spectral_path_for(b, k2012, "spectral_path_k2012", "; k2012 preset (E on)");
}

void bench_fft(Bench& b) {
    const std::vector<int> sizes = b.quick() ? std::vector<int>{128} : std::vector<int>{512, 1024, 2048};
    const EyeModel eye = bench_eye();
    const bool software = GpuPsfGenerator(kGpuFftMinSize).fft_placement() == ComputePlacement::cpu;
    for (int n : sizes) {
        // The default eye's pupil plane, rounded to float: what the GPU transforms.
        const auto field = pupil_plane(eye, n, kReferenceWavelengthNm, eye.plane_width_mm);
        ComplexImage<double> input(n);
        for (std::size_t i = 0; i < field.data.size(); ++i)
            input.data[i] = std::complex<double>(std::complex<float>(field.data[i]));
        ComplexImage<double> ref = input;
        fftw_forward(ref);
        auto error_of = [&ref](const ComplexImage<double>& got) {
            double num = 0, den = 0;
            for (std::size_t i = 0; i < ref.data.size(); ++i) {
                num += std::norm(got.data[i] - ref.data[i]);
                den += std::norm(ref.data[i]);
            }
            return std::sqrt(num / den);
        };
        const std::string bench = fmt::format("fft_n{}", n);
        const std::string metric = "relative L2 vs FFTW double";
        for (TwiddleSource tw : {TwiddleSource::table_from_double, TwiddleSource::shader_sincos}) {
            GpuFft fft(n, tw);
            ComplexImage<float> in_f(n);
            for (std::size_t i = 0; i < input.data.size(); ++i) in_f.data[i] = std::complex<float>(input.data[i]);
            const std::size_t bytes = in_f.data.size() * sizeof(std::complex<float>);
            gl::Buffer buffer(bytes, in_f.data.data(), gl::BufferUsage::dynamic_read);
            // Each run transforms the previous output: the cost is the same, and
            // the error is measured on a fresh transform below.
            const Timing t = measure_void([&] { fft.forward(buffer); }, b.spec(n >= 2048 ? 3 : 9, true));
            const ComplexImage<float> out = fft.forward(in_f);
            ComplexImage<double> got(n);
            for (std::size_t i = 0; i < out.data.size(); ++i) got.data[i] = std::complex<double>(out.data[i]);
            Row r;
            r.bench = bench;
            const bool table = tw == TwiddleSource::table_from_double;
            r.setting = table ? "GPU fp32, twiddle table" : "GPU fp32, shader sin/cos";
            // The PSF generator's FFT (ComputePlacement::automatic): the GPU's, unless
            // the renderer is software, where it is FFTW double on the CPU.
            r.is_default = table && !software;
            r.time = t;
            r.error = error_of(got);
            r.metric = metric;
            r.note = table ? "twiddles from double, rounded once" : "fp32 sin()/cos() of the driver";
            b.add(r);
        }
        for (FftBackend backend : {FftBackend::fftw_float, FftBackend::fftw_double}) {
            auto fft = make_fft(backend, n);
            ComplexImage<double> work = input;
            const Timing t = measure_void(
                [&] {
                    work = input;
                    fft->forward(work);
                },
                b.spec(n >= 2048 ? 3 : 9, false));
            Row r;
            r.bench = bench;
            r.setting = backend == FftBackend::fftw_float ? "FFTW float (CPU)" : "FFTW double (CPU)";
            r.is_default = backend == FftBackend::fftw_double && software;
            r.time = t;
            r.error = error_of(work);
            r.metric = metric;
            r.note = "FFTW_ESTIMATE plan, one thread; includes the copy in and out";
            b.add(r);
        }
    }
}

void bench_pupil_tolerance(Bench& b) {
    // Hippus on (K2012 eq 4.7): the pupil moves every frame, so an exact cache
    // rebuilds the PSF every frame. A sequence of frames at 60 Hz.
    const int n = b.quick() ? 64 : 256;
    const int frames = b.quick() ? 4 : 30;
    const std::vector<double> tolerances =
        b.quick() ? std::vector<double>{0.0, 0.1} : std::vector<double>{0.0, 0.01, 0.02, 0.05, 0.1, 0.2};
    Scene scene;
    scene.display = {640, 360, 0.598 / 3.0, 0.9};  // the default display's 50.4 px/°, smaller
    scene.environment.luminance_cd_m2 = 0.001;
    scene.glare.model = GlareModel::wave_optics;
    scene.glare.psf_size = n;
    scene.glare.pupil_mm = 6.0;
    scene.glare.eye.hippus.enabled = true;
    Light L;
    L.position_m = {0, 3, -1000};
    scene.lights = {L};
    // The exact PSF of each frame, for the error.
    std::vector<RgbPsf> exact;
    {
        scene.glare.pupil_tolerance_mm = 0.0;  // the exact pupil (not the default moving-pupil cache)
        FrameRenderer r;
        for (int i = 0; i < frames; ++i) {
            r.render(scene, i / 60.0);
            exact.push_back(*r.glare().psf(0));
        }
    }
    for (double tol : tolerances) {
        scene.glare.pupil_tolerance_mm = tol;
        double worst = 0;
        int builds = 0;
        const Timing t = measure_void(
            [&] {
                FrameRenderer r;  // a fresh cache each run
                worst = 0;
                for (int i = 0; i < frames; ++i) {
                    r.render(scene, i / 60.0);
                    worst = std::max(worst, relative_l2(*r.glare().psf(0), exact[static_cast<std::size_t>(i)]));
                }
                builds = r.glare().build_counts().kernels;
            },
            TimeSpec{0, b.quick() ? 1 : 3, false});
        Timing per_frame = t;
        for (Stats* s : {&per_frame.wall})
            for (double* v : {&s->median, &s->q1, &s->q3, &s->min, &s->max}) *v /= frames;
        Row r;
        r.bench = "pupil_tolerance";
        r.setting = tol > 0 ? fmt::format("{} mm", tol) : "exact (0)";
        r.is_default = tol == 0.0;
        r.time = per_frame;
        r.error = worst;
        r.metric = fmt::format("worst relative L2 of the PSF vs the exact pupil (N={}, hippus)", n);
        r.note = fmt::format("{} PSF builds in {} frames; time per frame, PSF comparison included", builds, frames);
        b.add(r);
    }
}

void bench_area_layers(Bench& b) {
    const int n = b.quick() ? 64 : 512;
    const double r_max = b.quick() ? 8.0 : 32.0;
    const std::vector<int> counts = b.quick() ? std::vector<int>{4, 16} : std::vector<int>{2, 4, 8, 16, 32, 64};
    const EyeModel eye = bench_eye();
    const double ppd = default_display().pixels_per_degree_at_centre();
    const double dpt = psf_degrees_per_texel(eye);
    GpuPsfGenerator gen(n);
    gen.generate(eye, spectral_samples(d65_spectrum(), kDefaultSamples));
    const GlareKernel kernel =
        glare_kernel_from_psf(gen.read_rgb(), ppd, glare_radius_deg(n, dpt), GlareWindow::silverman);
    // Radii between the layers: the exact disc convolution at r is the second
    // layer of a two-layer build up to r.
    std::vector<double> radii;
    for (int i = 1; i <= (b.quick() ? 5 : 17); ++i) radii.push_back(r_max * (i - 0.37) / (b.quick() ? 5 : 17));
    std::vector<AreaLayers> exact;
    for (double r : radii) exact.push_back(build_area_layers(kernel, r, 2));
    auto layer_at = [](const AreaLayers& a, int layer, int x, int y) -> glm::dvec3 {  // x, y from the centre
        const int h = a.half();
        if (std::abs(x) > h || std::abs(y) > h) return glm::dvec3(0.0);
        return glm::dvec3(a.rgba[static_cast<std::size_t>(layer) * a.size * a.size +
                                 static_cast<std::size_t>(y + h) * a.size + static_cast<std::size_t>(x + h)]);
    };
    for (int count : counts) {
        AreaLayers layers;
        const Timing t = measure_void([&] { layers = build_area_layers(kernel, r_max, count); }, b.spec(3, false, 0));
        double worst = 0;
        for (std::size_t k = 0; k < radii.size(); ++k) {
            // K2012 eq 4.13: linear between the two nearest layers, as glare_billboard.geom does.
            const double g = std::min(radii[k] / layers.radius_step_px, static_cast<double>(layers.layers - 1));
            const int z0 = static_cast<int>(std::floor(g));
            const double f = g - z0;
            const int h = std::max(layers.half(), exact[k].half());
            double num = 0, den = 0;
            for (int y = -h; y <= h; ++y)
                for (int x = -h; x <= h; ++x) {
                    glm::dvec3 v = layer_at(layers, z0, x, y);
                    if (f > 0) v = glm::mix(v, layer_at(layers, z0 + 1, x, y), f);
                    const glm::dvec3 e = layer_at(exact[k], 1, x, y), d = v - e;
                    num += glm::dot(d, d);
                    den += glm::dot(e, e);
                }
            worst = std::max(worst, std::sqrt(num / den));
        }
        Row r;
        r.bench = "area_layers";
        r.setting = fmt::format("{} layers", count);
        r.is_default = count == 16;
        r.time = t;
        r.error = worst;
        r.metric = fmt::format("worst relative L2 vs the exact disc convolution, radii 0–{:.0f} px", r_max);
        r.note = fmt::format("CPU build of {} layers of {} px", layers.layers, layers.size);
        b.add(r);
    }
}

}  // namespace atonlab::bench
