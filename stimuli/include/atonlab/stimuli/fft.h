#pragma once
// Two-dimensional forward FFTs of square complex images (K2012 §4.2.2, §5.2):
// FFTW in float and double on the CPU, and an fp32 compute-shader FFT on the
// GPU, behind one interface so tests and the benchmark can swap them.
//
// Convention everywhere: forward transform, X[k] = Σ_x x[n] e^{-2πi k·x/N},
// unnormalised, origin at index 0 (no shift), row-major, N a power of two.
#include <complex>
#include <memory>
#include <string>
#include <vector>

#include "atonlab/stimuli/gl/objects.h"

namespace atonlab::stimuli {

/// A square complex image, row-major: data[y * n + x].
template <class T>
struct ComplexImage {
    int n = 0;
    std::vector<std::complex<T>> data;

    ComplexImage() = default;
    explicit ComplexImage(int size) : n(size), data(static_cast<std::size_t>(size) * static_cast<std::size_t>(size)) {}
    std::complex<T>& at(int x, int y) { return data[static_cast<std::size_t>(y) * n + x]; }
    const std::complex<T>& at(int x, int y) const { return data[static_cast<std::size_t>(y) * n + x]; }
};

bool is_power_of_two(int n);

/// Which implementation computes the transform.
enum class FftBackend {
    gpu_fp32,     ///< compute shaders, fp32 arithmetic; needs a current GL 4.5 context
    fftw_float,   ///< FFTW single precision (fftwf), FFTW_ESTIMATE plans (deterministic)
    fftw_double,  ///< FFTW double precision: the reference
};

/// Where the GPU FFT's twiddle factors e^{-2πik/N} come from.
enum class TwiddleSource {
    table_from_double,  ///< cos/sin evaluated in double on the CPU, rounded once to fp32 (default: ≤ 0.5 ulp each)
    shader_sincos,      ///< fp32 sin()/cos() in the shader (driver accuracy; kept to measure it)
};

/// Sizes the GPU FFT supports: one row lives in a workgroup's shared memory.
constexpr int kGpuFftMinSize = 16;
constexpr int kGpuFftMaxSize = 2048;

/// One interface over the three backends. Each object is planned for one size.
class Fft2D {
public:
    virtual ~Fft2D() = default;
    virtual int size() const = 0;
    virtual std::string name() const = 0;  ///< "gpu-fp32", "fftw-float", "fftw-double"
    /// In-place forward transform. fp32 backends round the input to float and
    /// the output back to double.
    virtual void forward(ComplexImage<double>& image) = 0;
};

/// Throws InputError (key "size") unless n is a power of two in the backend's range.
std::unique_ptr<Fft2D> make_fft(FftBackend backend, int n, TwiddleSource twiddles = TwiddleSource::table_from_double);

/// CPU transforms without the virtual interface (FFTW; planned per call with
/// FFTW_ESTIMATE, so the same input gives bit-identical output on a machine).
void fftw_forward(ComplexImage<double>& image);
void fftw_forward(ComplexImage<float>& image);

/// The GPU FFT working on data that stays on the GPU: an SSBO of n*n vec2
/// (re, im), row-major. Needs a current GL 4.5 context for its whole life.
class GpuFft {
public:
    explicit GpuFft(int n, TwiddleSource twiddles = TwiddleSource::table_from_double);
    ~GpuFft();
    GpuFft(GpuFft&&) noexcept;
    GpuFft& operator=(GpuFft&&) noexcept;

    int size() const;
    TwiddleSource twiddles() const;
    /// In-place forward transform of `data` (at least n*n*8 bytes). Issues the
    /// needed memory barriers before and after, so the caller may read the
    /// buffer from a shader or download it right away.
    void forward(gl::Buffer& data);
    /// Upload, transform, download (tests and benchmark).
    ComplexImage<float> forward(const ComplexImage<float>& image);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace atonlab::stimuli
