// FFTW transforms (fft.h) against analytic answers: a direct DFT in long
// double, a delta, a single complex exponential, Parseval's theorem; float
// against double; bit-identical repeats; and the size checks of make_fft.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/fft.h"
#include "input_error.h"

namespace {

using namespace atonlab::stimuli;

ComplexImage<double> random_image(int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    ComplexImage<double> img(n);
    for (auto& v : img.data) v = {u(rng), u(rng)};
    return img;
}

template <class A, class B>
double relative_l2(const ComplexImage<A>& a, const ComplexImage<B>& b) {
    long double diff = 0, ref = 0;
    for (std::size_t i = 0; i < b.data.size(); ++i) {
        const std::complex<long double> ai(a.data[i].real(), a.data[i].imag());
        const std::complex<long double> bi(b.data[i].real(), b.data[i].imag());
        diff += std::norm(ai - bi);
        ref += std::norm(bi);
    }
    return static_cast<double>(std::sqrt(diff / ref));
}

/// X[k,l] = Σ x[x,y] e^{-2πi (k x + l y)/N}, straight from the definition in
/// long double, with the exponent reduced mod N so each twiddle is exact-indexed.
ComplexImage<long double> direct_dft(const ComplexImage<double>& in) {
    const int n = in.n;
    std::vector<std::complex<long double>> w(static_cast<std::size_t>(n));
    for (int m = 0; m < n; ++m) {
        const long double a = -2.0L * std::numbers::pi_v<long double> * m / n;
        w[static_cast<std::size_t>(m)] = {std::cos(a), std::sin(a)};
    }
    ComplexImage<long double> out(n);
    for (int l = 0; l < n; ++l)
        for (int k = 0; k < n; ++k) {
            std::complex<long double> sum = 0;
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const std::complex<long double> v(in.at(x, y).real(), in.at(x, y).imag());
                    sum += v * w[static_cast<std::size_t>((k * x + l * y) % n)];
                }
            out.at(k, l) = sum;
        }
    return out;
}

template <class F>
std::string error_of(F&& f) {
    return atonlab::test::input_error_of(f, "(accepted)");
}

// ---- Against the definition ---------------------------------------------------

TEST(FftwDouble, MatchesDirectDftInLongDouble) {
    for (int n : {8, 16}) {
        const ComplexImage<double> x = random_image(n, 11u + static_cast<unsigned>(n));
        ComplexImage<double> fft = x;
        fftw_forward(fft);
        const ComplexImage<long double> ref = direct_dft(x);
        // Double rounding over log2(N²) stages: ~1e-16 * few; 1e-12 leaves room
        // while any wrong sign, index or scale gives O(1).
        EXPECT_LT(relative_l2(fft, ref), 1e-12) << "n = " << n;
        long double peak = 0;
        for (const auto& v : ref.data) peak = std::max(peak, std::abs(v));
        for (std::size_t i = 0; i < ref.data.size(); ++i) {
            const std::complex<long double> f(fft.data[i].real(), fft.data[i].imag());
            ASSERT_LT(static_cast<double>(std::abs(f - ref.data[i]) / peak), 1e-12) << "n = " << n << " i = " << i;
        }
    }
}

TEST(FftwFloat, MatchesDoubleWithinFloatRounding) {
    for (int n : {64, 256}) {
        const ComplexImage<double> x = random_image(n, 5u);
        ComplexImage<double> ref = x;
        fftw_forward(ref);
        ComplexImage<float> f(n);
        for (std::size_t i = 0; i < x.data.size(); ++i) f.data[i] = std::complex<float>(x.data[i]);
        fftw_forward(f);
        const double err = relative_l2(f, ref);
        std::printf("fftw-float vs fftw-double, N = %d: relative L2 = %.3g\n", n, err);
        EXPECT_LT(err, 1e-6) << "n = " << n;
    }
}

// ---- Analytic answers ----------------------------------------------------------

TEST(FftwDouble, DeltaAtOriginGivesAllOnes) {
    ComplexImage<double> d(32);
    d.at(0, 0) = 1.0;
    fftw_forward(d);
    for (const auto& v : d.data) {
        ASSERT_NEAR(v.real(), 1.0, 1e-15);
        ASSERT_NEAR(v.imag(), 0.0, 1e-15);
    }
    ComplexImage<float> f(32);
    f.at(0, 0) = 1.0f;
    fftw_forward(f);
    for (const auto& v : f.data) {
        ASSERT_NEAR(v.real(), 1.0f, 1e-6f);
        ASSERT_NEAR(v.imag(), 0.0f, 1e-6f);
    }
}

TEST(FftwDouble, ComplexExponentialGivesOneBinOfValueNSquared) {
    // x = e^{+2πi (k0 x + l0 y)/N} puts all energy into bin (k0, l0) with value N².
    const int n = 64, k0 = 5, l0 = 49;
    ComplexImage<double> img(n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double a = 2.0 * std::numbers::pi * static_cast<double>((k0 * x + l0 * y) % n) / n;
            img.at(x, y) = {std::cos(a), std::sin(a)};
        }
    fftw_forward(img);
    const double n2 = static_cast<double>(n) * n;
    for (int l = 0; l < n; ++l)
        for (int k = 0; k < n; ++k) {
            const std::complex<double> expected = (k == k0 && l == l0) ? n2 : 0.0;
            ASSERT_LT(std::abs(img.at(k, l) - expected), 1e-12 * n2) << k << "," << l;
        }
}

TEST(FftwDouble, ParsevalSumOfSquaresScalesByNSquared) {
    const int n = 128;
    ComplexImage<double> img = random_image(n, 3u);
    long double before = 0, after = 0;
    for (const auto& v : img.data) before += std::norm(v);
    fftw_forward(img);
    for (const auto& v : img.data) after += std::norm(v);
    const long double n2 = static_cast<long double>(n) * n;
    EXPECT_NEAR(static_cast<double>(after / (n2 * before)), 1.0, 1e-13);
}

// ---- Determinism ----------------------------------------------------------------

TEST(FftwDouble, RepeatIsBitIdentical) {
    const ComplexImage<double> x = random_image(256, 9u);
    ComplexImage<double> a = x;
    fftw_forward(a);
    ComplexImage<double> b = x;
    fftw_forward(b);
    ASSERT_EQ(std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(a.data[0])), 0);

    ComplexImage<float> fa(256);
    for (std::size_t i = 0; i < x.data.size(); ++i) fa.data[i] = std::complex<float>(x.data[i]);
    ComplexImage<float> fb = fa;
    fftw_forward(fa);
    fftw_forward(fb);
    ASSERT_EQ(std::memcmp(fa.data.data(), fb.data.data(), fa.data.size() * sizeof(fa.data[0])), 0);

    auto fft = make_fft(FftBackend::fftw_double, 256);
    ComplexImage<double> c = x, d = x;
    fft->forward(c);
    fft->forward(d);
    ASSERT_EQ(std::memcmp(c.data.data(), d.data.data(), c.data.size() * sizeof(c.data[0])), 0);
}

// ---- The Fft2D interface ---------------------------------------------------------

TEST(Fft2D, FftwBackendsGiveTheDirectFunctionsAnswers) {
    const int n = 64;
    const ComplexImage<double> x = random_image(n, 21u);

    auto dbl = make_fft(FftBackend::fftw_double, n);
    EXPECT_EQ(dbl->name(), "fftw-double");
    EXPECT_EQ(dbl->size(), n);
    ComplexImage<double> via_interface = x, direct = x;
    dbl->forward(via_interface);
    fftw_forward(direct);
    EXPECT_EQ(via_interface.data, direct.data);

    auto flt = make_fft(FftBackend::fftw_float, n);
    EXPECT_EQ(flt->name(), "fftw-float");
    EXPECT_EQ(flt->size(), n);
    ComplexImage<double> via_float = x;
    flt->forward(via_float);
    ComplexImage<float> direct_float(n);
    for (std::size_t i = 0; i < x.data.size(); ++i) direct_float.data[i] = std::complex<float>(x.data[i]);
    fftw_forward(direct_float);
    for (std::size_t i = 0; i < x.data.size(); ++i)
        ASSERT_EQ(via_float.data[i], std::complex<double>(direct_float.data[i])) << i;
}

TEST(Fft2D, WrongImageSizeIsABug) {
    auto fft = make_fft(FftBackend::fftw_double, 16);
    ComplexImage<double> img(32);
    EXPECT_THROW(fft->forward(img), std::invalid_argument);
    ComplexImage<double> inconsistent(16);
    inconsistent.data.pop_back();
    EXPECT_THROW(fftw_forward(inconsistent), std::invalid_argument);
}

// ---- Sizes ------------------------------------------------------------------------

TEST(MakeFft, GpuSizesOutsidePowersOfTwoFrom16To2048AreInputErrors) {
    // Checked before any GL call, so these need no context.
    for (int n : {0, 3, 8, 100, 4096, -16}) {
        const std::string e = error_of([&] { make_fft(FftBackend::gpu_fp32, n); });
        EXPECT_NE(e.find("key 'size'"), std::string::npos) << n << ": " << e;
        EXPECT_NE(e.find("power of two from 16 to 2048"), std::string::npos) << n << ": " << e;
        EXPECT_NE(e.find(std::to_string(n)), std::string::npos) << n << ": " << e;
    }
}

TEST(MakeFft, FftwSizesMustBePowersOfTwo) {
    for (FftBackend b : {FftBackend::fftw_float, FftBackend::fftw_double})
        for (int n : {0, 3, 100, 1000, -4}) {
            const std::string e = error_of([&] { make_fft(b, n); });
            EXPECT_NE(e.find("key 'size'"), std::string::npos) << n << ": " << e;
            EXPECT_NE(e.find("power of two"), std::string::npos) << n << ": " << e;
        }
    EXPECT_EQ(error_of([] { make_fft(FftBackend::fftw_double, 4096); }), "(accepted)");
    EXPECT_EQ(error_of([] { make_fft(FftBackend::fftw_float, 1); }), "(accepted)");
}

TEST(IsPowerOfTwo, ExactlyThePositivePowers) {
    EXPECT_FALSE(is_power_of_two(0));
    EXPECT_FALSE(is_power_of_two(-8));
    EXPECT_TRUE(is_power_of_two(1));
    EXPECT_TRUE(is_power_of_two(2));
    EXPECT_FALSE(is_power_of_two(3));
    EXPECT_TRUE(is_power_of_two(1 << 30));
    EXPECT_FALSE(is_power_of_two((1 << 30) + 1));
}

}  // namespace
