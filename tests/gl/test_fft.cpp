// The fp32 compute-shader FFT (fft.h, GpuFft) against FFTW in double: random
// complex input and a pupil disc, both twiddle sources, N = 256 ... 2048; plus
// analytic answers (delta, one exponential) and the buffer-level interface.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "atonlab/stimuli/fft.h"
#include "atonlab/stimuli/gl/objects.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using GpuFftTest = GLTest;

ComplexImage<double> random_image(int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    ComplexImage<double> img(n);
    for (auto& v : img.data) v = {u(rng), u(rng)};
    return img;
}

/// A pupil: 1 inside a centred disc of radius N/8 pixels, 0 outside.
ComplexImage<double> pupil_disc(int n) {
    ComplexImage<double> img(n);
    const double c = n / 2.0, r = n / 8.0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double dx = x - c, dy = y - c;
            if (dx * dx + dy * dy <= r * r) img.at(x, y) = 1.0;
        }
    return img;
}

ComplexImage<float> to_float(const ComplexImage<double>& in) {
    ComplexImage<float> out(in.n);
    for (std::size_t i = 0; i < in.data.size(); ++i) out.data[i] = std::complex<float>(in.data[i]);
    return out;
}

/// ‖a − b‖₂ / ‖b‖₂, accumulated in double.
double relative_l2(const ComplexImage<float>& a, const ComplexImage<double>& b) {
    double diff = 0, ref = 0;
    for (std::size_t i = 0; i < b.data.size(); ++i) {
        diff += std::norm(std::complex<double>(a.data[i]) - b.data[i]);
        ref += std::norm(b.data[i]);
    }
    return std::sqrt(diff / ref);
}

/// An input rounded to float, and FFTW double's transform of that rounded
/// input, so that only the GPU transform's own error is measured.
struct Reference {
    ComplexImage<float> input;
    ComplexImage<double> spectrum;
};

Reference reference(const ComplexImage<double>& x) {
    Reference r{to_float(x), ComplexImage<double>(x.n)};
    for (std::size_t i = 0; i < x.data.size(); ++i) r.spectrum.data[i] = std::complex<double>(r.input.data[i]);
    fftw_forward(r.spectrum);
    return r;
}

const char* name_of(TwiddleSource t) {
    return t == TwiddleSource::table_from_double ? "table_from_double" : "shader_sincos";
}

// ---- Accuracy against FFTW double ---------------------------------------------------

// Both twiddle sources at one size, on random complex input and on a pupil
// disc; the errors are printed for the record. The acceptance bound: relative
// L2 < 1e-5 with the double-derived twiddle table (asked for at N = 512 and
// 1024, held at every size). An fp32 radix-2 FFT with correctly rounded
// twiddles is expected near eps * sqrt(log2 N²) ~ 2e-7; a wrong index or sign
// gives O(1). shader_sincos is a measured alternative whose accuracy is the
// driver's, so it is only held to 1e-3: a broken shader still fails.
class GpuFftAccuracy : public GLTest, public ::testing::WithParamInterface<int> {};

TEST_P(GpuFftAccuracy, MatchesFftwDouble) {
    const int n = GetParam();
    const Reference random = reference(random_image(n, 100u + static_cast<unsigned>(n)));
    const Reference pupil = reference(pupil_disc(n));
    for (TwiddleSource t : {TwiddleSource::table_from_double, TwiddleSource::shader_sincos}) {
        GpuFft fft(n, t);
        const double random_err = relative_l2(fft.forward(random.input), random.spectrum);
        const double pupil_err = relative_l2(fft.forward(pupil.input), pupil.spectrum);
        std::printf("GPU fp32 FFT vs FFTW double, N = %4d, %-17s: relative L2 %.3g (random), %.3g (pupil)\n", n,
                    name_of(t), random_err, pupil_err);
        const double bound = t == TwiddleSource::table_from_double ? 1e-5 : 1e-3;
        EXPECT_LT(random_err, bound) << name_of(t) << " random, n = " << n;
        EXPECT_LT(pupil_err, bound) << name_of(t) << " pupil, n = " << n;
    }
}

INSTANTIATE_TEST_SUITE_P(Sizes, GpuFftAccuracy, ::testing::Values(256, 512, 1024, 2048),
                         [](const ::testing::TestParamInfo<int>& p) { return "N" + std::to_string(p.param); });

// ---- Analytic answers ----------------------------------------------------------------

TEST_F(GpuFftTest, DeltaAtOriginGivesAllOnes) {
    GpuFft fft(64);
    ComplexImage<float> d(64);
    d.at(0, 0) = 1.0f;
    const ComplexImage<float> out = fft.forward(d);
    for (const auto& v : out.data) {
        ASSERT_NEAR(v.real(), 1.0f, 1e-6f);
        ASSERT_NEAR(v.imag(), 0.0f, 1e-6f);
    }
}

TEST_F(GpuFftTest, ComplexExponentialGivesOneBinOfValueNSquared) {
    const int n = 128, k0 = 3, l0 = 100;
    ComplexImage<float> img(n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double a = 2.0 * std::numbers::pi * static_cast<double>((k0 * x + l0 * y) % n) / n;
            img.at(x, y) = {static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a))};
        }
    GpuFft fft(n);
    const ComplexImage<float> out = fft.forward(img);
    const float n2 = static_cast<float>(n * n);
    for (int l = 0; l < n; ++l)
        for (int k = 0; k < n; ++k) {
            const std::complex<float> expected = (k == k0 && l == l0) ? n2 : 0.0f;
            ASSERT_LT(std::abs(out.at(k, l) - expected), 1e-5f * n2) << k << "," << l;
        }
}

// ---- Interfaces ------------------------------------------------------------------------

TEST_F(GpuFftTest, BufferInterfaceIsReadableRightAfterAndRepeatsBitIdentically) {
    const int n = 256;
    const ComplexImage<float> x = to_float(random_image(n, 31u));
    const std::size_t bytes = x.data.size() * sizeof(x.data[0]);
    gl::Buffer buffer(bytes, x.data.data(), gl::BufferUsage::dynamic_read);
    GpuFft fft(n);
    fft.forward(buffer);
    ComplexImage<float> a(n);
    buffer.download(0, bytes, a.data.data());  // no barrier here: forward() issued it
    const ComplexImage<float> b = fft.forward(x);
    ASSERT_EQ(std::memcmp(a.data.data(), b.data.data(), bytes), 0);

    gl::Buffer too_small(bytes - 8, nullptr, gl::BufferUsage::dynamic_read);
    EXPECT_THROW(fft.forward(too_small), std::invalid_argument);
    EXPECT_THROW(fft.forward(ComplexImage<float>(128)), std::invalid_argument);
}

TEST_F(GpuFftTest, Fft2DGivesTheSameAnswerAsGpuFft) {
    const int n = 128;
    for (TwiddleSource t : {TwiddleSource::table_from_double, TwiddleSource::shader_sincos}) {
        auto fft = make_fft(FftBackend::gpu_fp32, n, t);
        EXPECT_EQ(fft->name(), "gpu-fp32");
        EXPECT_EQ(fft->size(), n);
        ComplexImage<double> via_interface = random_image(n, 77u);
        const ComplexImage<float> direct = GpuFft(n, t).forward(to_float(via_interface));
        fft->forward(via_interface);
        for (std::size_t i = 0; i < direct.data.size(); ++i)
            ASSERT_EQ(via_interface.data[i], std::complex<double>(direct.data[i])) << name_of(t) << " " << i;
    }
}

TEST_F(GpuFftTest, MovesKeepThePlan) {
    GpuFft a(32, TwiddleSource::shader_sincos);
    GpuFft b = std::move(a);
    EXPECT_EQ(b.size(), 32);
    EXPECT_EQ(b.twiddles(), TwiddleSource::shader_sincos);
    EXPECT_EQ(a.size(), 0);  // NOLINT(bugprone-use-after-move): the moved-from state is the point
    ComplexImage<float> d(32);
    d.at(0, 0) = 2.0f;
    EXPECT_EQ(b.forward(d).at(5, 7), std::complex<float>(2.0f, 0.0f));
}

}  // namespace
}  // namespace atonlab::test
