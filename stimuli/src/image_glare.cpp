// Glare on an HDR image by FFT convolution with a glare kernel (image_glare.h).
#include "atonlab/stimuli/image_glare.h"

#include <fftw3.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <mutex>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/cie_glare.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/eye_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/psf.h"
#include "atonlab/stimuli/spectral_path.h"
#include "fftw_planner.h"

namespace atonlab::stimuli {
namespace {

constexpr int kMaxTransformPx = 8192;

// The smallest n' >= n whose only prime factors are 2, 3, 5 and 7 (fast FFTW sizes).
int fft_friendly_size(int n) {
    for (int m = std::max(n, 1);; ++m) {
        int r = m;
        for (const int p : {2, 3, 5, 7})
            while (r % p == 0) r /= p;
        if (r == 1) return m;
    }
}

struct FftwFree {
    void operator()(void* p) const { fftw_free(p); }
};

}  // namespace

GlareKernel image_glare_kernel(const GlareSettings& glare, double adaptation_cd_m2, double degrees_per_pixel) {
    if (!(degrees_per_pixel > 0 && std::isfinite(degrees_per_pixel)))
        throw InputError(SourceLocation{"", 0, 0, "degrees_per_pixel"},
                         fmt::format("the degrees per pixel must be a positive number, not {}.", degrees_per_pixel));
    const double ppd = 1.0 / degrees_per_pixel;
    const SpectralSamples samples = spectral_samples(display::d65_spectrum(), glare.spectral_samples);
    Scene scene;  // the pupil (eq 3.15) and Spencer's vision class follow the adaptation
    scene.adaptation_cd_m2 = adaptation_cd_m2;
    scene.glare = glare;
    // A model that cannot (none, aperture) says which can (key "model").
    return glare_model_type(glare.model).image_kernel({glare, scene, samples, ppd, glare_pupil_mm(scene), 0.0, {}});
}

ImageGlareResult convolve_image_glare(const ImageRGBA32F& hdr, const GlareKernel& kernel) {
    const int w = hdr.width, h = hdr.height, m = kernel.size, half = kernel.half();
    // Linear convolution: the full result is (w + m - 1) x (h + m - 1); padding
    // to at least that leaves no wrap-around.
    const int pw = fft_friendly_size(w + m - 1), ph = fft_friendly_size(h + m - 1);
    if (pw > kMaxTransformPx || ph > kMaxTransformPx)
        throw InputError(SourceLocation{"", 0, 0, ""},
                         fmt::format("the image ({}x{} px) and the glare kernel ({} px) need a {}x{} transform; at "
                                     "most {} a side: use a smaller image or glare radius.",
                                     w, h, m, pw, ph, kMaxTransformPx));
    const int cw = pw / 2 + 1;  // r2c output columns
    const std::size_t real_n = static_cast<std::size_t>(pw) * ph, complex_n = static_cast<std::size_t>(cw) * ph;
    std::unique_ptr<double, FftwFree> real(fftw_alloc_real(real_n));
    std::unique_ptr<fftw_complex, FftwFree> image_f(fftw_alloc_complex(complex_n));
    std::unique_ptr<fftw_complex, FftwFree> kernel_f(fftw_alloc_complex(complex_n));
    // FFTW's planner is not thread-safe: the library's one lock (a render may
    // run beside this one, e.g. from Python with the GIL released).
    std::unique_lock planner(detail::fftw_planner_mutex());
    fftw_plan forward = fftw_plan_dft_r2c_2d(ph, pw, real.get(), image_f.get(), FFTW_ESTIMATE);
    fftw_plan forward_k = fftw_plan_dft_r2c_2d(ph, pw, real.get(), kernel_f.get(), FFTW_ESTIMATE);
    fftw_plan inverse = fftw_plan_dft_c2r_2d(ph, pw, image_f.get(), real.get(), FFTW_ESTIMATE);
    planner.unlock();

    ImageGlareResult out;
    out.image.width = w;
    out.image.height = h;
    out.image.rgba.assign(hdr.rgba.size(), 0.0f);
    for (std::size_t i = 3; i < hdr.rgba.size(); i += 4) out.image.rgba[i] = hdr.rgba[i];
    const double norm = 1.0 / static_cast<double>(real_n);
    for (int c = 0; c < 3; ++c) {
        // The kernel in image orientation (its row 0 is at the bottom, the image's at the top).
        std::fill(real.get(), real.get() + real_n, 0.0);
        for (int j = 0; j < m; ++j)
            for (int i = 0; i < m; ++i) real.get()[static_cast<std::size_t>(m - 1 - j) * pw + i] = kernel.at(i, j)[c];
        fftw_execute(forward_k);
        detail::count_cpu_ffts();
        std::fill(real.get(), real.get() + real_n, 0.0);
        double in_sum = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const double v = hdr.pixel(x, y)[c];
                const double l = v > 0 && std::isfinite(v) ? v : 0.0;
                real.get()[static_cast<std::size_t>(y) * pw + x] = l;
                in_sum += l;
            }
        fftw_execute(forward);
        auto* a = reinterpret_cast<std::complex<double>*>(image_f.get());
        const auto* b = reinterpret_cast<const std::complex<double>*>(kernel_f.get());
        for (std::size_t k = 0; k < complex_n; ++k) a[k] *= b[k] * norm;
        fftw_execute(inverse);
        detail::count_cpu_ffts(2);  // the image's forward transform and this inverse
        // Full result index (X, Y) is the image pixel (X - half, Y - half).
        double full_sum = 0, inside_sum = 0;
        for (int y = 0; y < ph; ++y)
            for (int x = 0; x < pw; ++x) {
                const double v = real.get()[static_cast<std::size_t>(y) * pw + x];
                full_sum += v;
                const int ix = x - half, iy = y - half;
                if (ix < 0 || iy < 0 || ix >= w || iy >= h) continue;
                // FFT round-off leaves ~1e-16 of the peak where the result is 0.
                const double l = std::max(v, 0.0);
                inside_sum += l;
                out.image.pixel(ix, iy)[c] = static_cast<float>(l);
            }
        out.input_sum[c] = in_sum;
        out.output_sum[c] = inside_sum;
        out.edge_cut[c] = in_sum > 0 ? (full_sum - inside_sum) / in_sum : 0.0;
    }
    planner.lock();
    fftw_destroy_plan(forward);
    fftw_destroy_plan(forward_k);
    fftw_destroy_plan(inverse);
    return out;
}

}  // namespace atonlab::stimuli
