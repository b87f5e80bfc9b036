// Two-dimensional forward FFTs (K2012 §4.2.2, §5.2): FFTW in float and double,
// and an fp32 compute-shader FFT (shaders/fft_rows.comp) behind one interface.
#include "atonlab/stimuli/fft.h"

#include <epoxy/gl.h>
#include <fftw3.h>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <new>
#include <numbers>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "atonlab/stimuli/cpu_threads.h"
#include "atonlab/stimuli/error.h"
#include "fftw_planner.h"
#include "gpu_fft_lines.h"
#include "gl_enums.h"

namespace atonlab::stimuli {

std::mutex& detail::fftw_planner_mutex() {
    static std::mutex m;
    return m;
}

namespace {
std::atomic<std::uint64_t> g_cpu_ffts{0};
}  // namespace

void detail::count_cpu_ffts(unsigned n) {
    g_cpu_ffts.fetch_add(n, std::memory_order_relaxed);
}

std::uint64_t cpu_fft_count() {
    return g_cpu_ffts.load(std::memory_order_relaxed);
}

bool is_power_of_two(int n) {
    return n > 0 && (n & (n - 1)) == 0;
}

namespace {

// The largest FFTW size make_fft accepts: 16384² complex doubles are 4 GiB,
// and n*n stays far below INT_MAX, which FFTW's int-sized plans need.
constexpr int kFftwMaxSize = 16384;

std::size_t pixel_count(int n) {
    return static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
}

InputError size_error(const std::string& sentence) {
    return InputError(SourceLocation{"", 0, 0, "size"}, sentence);
}

void check_gpu_size(int n) {
    if (!is_power_of_two(n) || n < kGpuFftMinSize || n > kGpuFftMaxSize)
        throw size_error(fmt::format("the GPU FFT needs an image size that is a power of two from {} to {}, not {}.",
                                     kGpuFftMinSize, kGpuFftMaxSize, n));
}

void check_fftw_size(int n) {
    if (!is_power_of_two(n) || n > kFftwMaxSize)
        throw size_error(fmt::format(
            "the FFTW transform needs an image size that is a power of two from 1 to {}, not {}.", kFftwMaxSize, n));
}

/// A ComplexImage whose n and data disagree is a caller's bug, not bad input.
template <class T>
void check_image(const ComplexImage<T>& image) {
    if (image.n < 0 || image.data.size() != pixel_count(image.n))
        throw std::invalid_argument(fmt::format("ComplexImage of size {} holds {} values instead of {}", image.n,
                                                image.data.size(), pixel_count(std::max(image.n, 0))));
}

std::mutex& planner_mutex() {
    return detail::fftw_planner_mutex();
}

/// FFTW in one precision: the fftw_ / fftwf_ prefixes behind one name.
template <class T>
struct Fftw;

template <>
struct Fftw<double> {
    using Complex = fftw_complex;
    using Plan = fftw_plan;
    static Complex* alloc(std::size_t count) { return fftw_alloc_complex(count); }
    static void free(Complex* p) { fftw_free(p); }
    static Plan plan(int n, Complex* data) { return fftw_plan_dft_2d(n, n, data, data, FFTW_FORWARD, FFTW_ESTIMATE); }
    static void execute(Plan p) { fftw_execute(p); }
    static void destroy(Plan p) { fftw_destroy_plan(p); }
};

template <>
struct Fftw<float> {
    using Complex = fftwf_complex;
    using Plan = fftwf_plan;
    static Complex* alloc(std::size_t count) { return fftwf_alloc_complex(count); }
    static void free(Complex* p) { fftwf_free(p); }
    static Plan plan(int n, Complex* data) { return fftwf_plan_dft_2d(n, n, data, data, FFTW_FORWARD, FFTW_ESTIMATE); }
    static void execute(Plan p) { fftwf_execute(p); }
    static void destroy(Plan p) { fftwf_destroy_plan(p); }
};

/// An in-place n×n FFTW plan over its own SIMD-aligned buffer. The buffer is
/// FFTW's rather than the caller's so the plan (and hence every bit of the
/// result) does not depend on where the caller's vector happens to be aligned.
template <class T>
class FftwPlan {
public:
    explicit FftwPlan(int n) : n_(n), count_(pixel_count(n)) {
        std::lock_guard lock(planner_mutex());
        data_ = Fftw<T>::alloc(count_);
        if (data_ == nullptr) throw std::bad_alloc();
        // FFTW_ESTIMATE never touches the array while planning, and picks the
        // same algorithm every time for the same size and alignment.
        plan_ = Fftw<T>::plan(n_, data_);
        if (plan_ == nullptr) {
            Fftw<T>::free(data_);
            throw std::runtime_error(fmt::format("FFTW could not plan a {}x{} transform", n, n));
        }
    }
    ~FftwPlan() {
        std::lock_guard lock(planner_mutex());
        Fftw<T>::destroy(plan_);
        Fftw<T>::free(data_);
    }
    FftwPlan(const FftwPlan&) = delete;
    FftwPlan& operator=(const FftwPlan&) = delete;

    int size() const { return n_; }

    /// Transforms `values` (n*n, row-major) in place through the plan's buffer.
    void forward(std::complex<T>* values) {
        // fftw_complex is T[2]; std::complex<T> is guaranteed to have the same
        // layout (C++ [complex.numbers]/4, FFTW manual §4.1.1), so the buffer
        // can be viewed as std::complex<T> for the copies.
        auto* buffer = reinterpret_cast<std::complex<T>*>(data_);
        std::copy_n(values, count_, buffer);
        Fftw<T>::execute(plan_);
        detail::count_cpu_ffts();
        std::copy_n(buffer, count_, values);
    }

private:
    int n_;
    std::size_t count_;
    typename Fftw<T>::Complex* data_ = nullptr;
    typename Fftw<T>::Plan plan_ = nullptr;
};

/// Plans made once and reused (issue 27 item 3): a plan and its buffer are
/// taken from the pool for one transform and given back, so no call plans,
/// allocates or page-faults a fresh buffer. Any thread may take one; a plan is
/// used by one thread at a time. Every plan of a size was made alike (its own
/// aligned buffer, FFTW_ESTIMATE), so the result does not depend on which one.
template <class T>
class FftwPlanPool {
public:
    std::unique_ptr<FftwPlan<T>> take(int n) {
        {
            std::lock_guard lock(mutex_);
            for (auto it = free_.begin(); it != free_.end(); ++it)
                if ((*it)->size() == n) {
                    std::unique_ptr<FftwPlan<T>> p = std::move(*it);
                    free_.erase(it);
                    return p;
                }
        }
        return std::make_unique<FftwPlan<T>>(n);
    }
    void give_back(std::unique_ptr<FftwPlan<T>> p) {
        std::lock_guard lock(mutex_);
        // The pool holds at most as many plans of a size as were in use at once
        // (one per thread that transforms concurrently).
        free_.push_back(std::move(p));
    }

private:
    std::mutex mutex_;
    std::vector<std::unique_ptr<FftwPlan<T>>> free_;
};

template <class T>
FftwPlanPool<T>& plan_pool() {
    // Never destroyed: plans may be given back by threads that outlive main's
    // static destructors, and the process's end frees everything anyway.
    static auto* pool = new FftwPlanPool<T>();
    return *pool;
}

template <class T>
void fftw_forward_any(ComplexImage<T>& image) {
    check_image(image);
    if (image.n == 0) return;
    FftwPlanPool<T>& pool = plan_pool<T>();
    std::unique_ptr<FftwPlan<T>> plan = pool.take(image.n);
    plan->forward(image.data.data());
    pool.give_back(std::move(plan));
}

}  // namespace

void fftw_forward(ComplexImage<double>& image) {
    fftw_forward_any(image);
}
void fftw_forward(ComplexImage<float>& image) {
    fftw_forward_any(image);
}

// --- GpuFft ------------------------------------------------------------------

namespace {

// Workgroup size of the FFT passes: each invocation does n/2/threads radix-2
// butterflies per stage. 256 is the usual sweet spot on desktop GPUs and within
// GL's guaranteed 1024 invocations; on llvmpipe 64, 256 and 1024 measured
// within about 30% of each other.
constexpr int kGpuFftMaxThreads = 256;

int log2_of(int n) {
    int k = 0;
    while ((1 << k) < n) ++k;
    return k;
}

}  // namespace

namespace detail {

std::vector<float> fft_twiddle_table(int n) {
    std::vector<float> table(static_cast<std::size_t>(n));  // n/2 vec2
    for (int k = 0; k < n / 2; ++k) {
        const double angle = 2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
        table[static_cast<std::size_t>(2 * k)] = static_cast<float>(std::cos(angle));
        table[static_cast<std::size_t>(2 * k + 1)] = static_cast<float>(-std::sin(angle));
    }
    return table;
}

gl::Program fft_line_program(int n, int pitch, bool columns, TwiddleSource twiddles) {
    const std::string n_def = fmt::format("FFT_N {}u", n);
    const std::string log2_def = fmt::format("FFT_LOG2N {}u", log2_of(n));
    const std::string threads_def = fmt::format("FFT_THREADS {}", std::min(n / 2, kGpuFftMaxThreads));
    const std::string pitch_def = fmt::format("FFT_PITCH {}u", pitch);
    const std::string_view twiddle_def =
        twiddles == TwiddleSource::table_from_double ? "FFT_TWIDDLE_TABLE 1" : "FFT_TWIDDLE_SINCOS 1";
    return gl::Program::build({{gl::ShaderStage::compute, "fft_rows.comp"}},
                              {n_def, log2_def, threads_def, twiddle_def, pitch_def,
                               columns ? "FFT_COLUMNS 1" : "FFT_ROWS 1"});
}

}  // namespace detail

struct GpuFft::Impl {
    int n = 0;
    TwiddleSource twiddles = TwiddleSource::table_from_double;
    gl::Program rows, columns;
    gl::Buffer twiddle_table;  // empty for shader_sincos
    gl::Buffer scratch;        // for the upload/transform/download overload, made on first use
};

GpuFft::GpuFft(int n, TwiddleSource twiddles) {
    check_gpu_size(n);
    auto impl = std::make_unique<Impl>();
    impl->n = n;
    impl->twiddles = twiddles;
    impl->rows = detail::fft_line_program(n, n, false, twiddles);
    impl->columns = detail::fft_line_program(n, n, true, twiddles);
    if (twiddles == TwiddleSource::table_from_double)
        impl->twiddle_table = gl::Buffer::from(std::span<const float>(detail::fft_twiddle_table(n)));
    impl_ = std::move(impl);
}

GpuFft::~GpuFft() = default;
GpuFft::GpuFft(GpuFft&&) noexcept = default;
GpuFft& GpuFft::operator=(GpuFft&&) noexcept = default;

int GpuFft::size() const {
    return impl_ ? impl_->n : 0;
}
TwiddleSource GpuFft::twiddles() const {
    return impl_ ? impl_->twiddles : TwiddleSource::table_from_double;
}

void GpuFft::forward(gl::Buffer& data) {
    if (!impl_) throw std::logic_error("GpuFft::forward on a moved-from GpuFft");
    const std::size_t bytes = pixel_count(impl_->n) * 2 * sizeof(float);
    if (data.size() < bytes)
        throw std::invalid_argument(fmt::format("GpuFft::forward: a {}x{} transform needs a buffer of {} bytes, not {}",
                                                impl_->n, impl_->n, bytes, data.size()));
    // Binding points 0 (data) and 1 (twiddles) are the shader's: the caller's
    // storage bindings there, and the current program, are replaced.
    data.bind_storage(0);
    if (impl_->twiddle_table) impl_->twiddle_table.bind_storage(1);
    const auto groups = static_cast<GLuint>(impl_->n);  // one workgroup per row, then per column
    // Shader writes to `data` made before this call become visible to the FFT.
    ATONLAB_GL_CHECK(glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT));
    impl_->rows.use();
    ATONLAB_GL_CHECK(glDispatchCompute(groups, 1, 1));
    ATONLAB_GL_CHECK(glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT));
    impl_->columns.use();
    ATONLAB_GL_CHECK(glDispatchCompute(groups, 1, 1));
    // The result is visible to later shaders reading it as storage, uniform or
    // vertex data, to buffer downloads/copies and to pixel transfers from it.
    ATONLAB_GL_CHECK(glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT |
                                     GL_UNIFORM_BARRIER_BIT | GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT |
                                     GL_PIXEL_BUFFER_BARRIER_BIT));
}

ComplexImage<float> GpuFft::forward(const ComplexImage<float>& image) {
    if (!impl_) throw std::logic_error("GpuFft::forward on a moved-from GpuFft");
    check_image(image);
    if (image.n != impl_->n)
        throw std::invalid_argument(
            fmt::format("GpuFft planned for {}x{} was given a {}x{} image", impl_->n, impl_->n, image.n, image.n));
    // std::complex<float> is two floats (re, im): the std430 layout of vec2.
    const std::size_t bytes = image.data.size() * sizeof(std::complex<float>);
    if (!impl_->scratch) impl_->scratch = gl::Buffer(bytes, nullptr, gl::BufferUsage::dynamic_read);
    impl_->scratch.upload(0, bytes, image.data.data());
    forward(impl_->scratch);
    ComplexImage<float> out(image.n);
    impl_->scratch.download(0, bytes, out.data.data());
    return out;
}

// --- Fft2D backends ----------------------------------------------------------

namespace {

template <class T>
class FftwFft2D final : public Fft2D {
public:
    explicit FftwFft2D(int n) : plan_(n) {}
    int size() const override { return plan_.size(); }
    std::string name() const override { return std::is_same_v<T, double> ? "fftw-double" : "fftw-float"; }
    void forward(ComplexImage<double>& image) override {
        check_size(image);
        if constexpr (std::is_same_v<T, double>) {
            plan_.forward(image.data.data());
        } else {
            std::vector<std::complex<float>> values(image.data.begin(), image.data.end());
            plan_.forward(values.data());
            std::copy(values.begin(), values.end(), image.data.begin());
        }
    }

private:
    void check_size(const ComplexImage<double>& image) const {
        check_image(image);
        if (image.n != plan_.size())
            throw std::invalid_argument(fmt::format("{} planned for {}x{} was given a {}x{} image", name(),
                                                    plan_.size(), plan_.size(), image.n, image.n));
    }
    FftwPlan<T> plan_;
};

class GpuFft2D final : public Fft2D {
public:
    GpuFft2D(int n, TwiddleSource twiddles) : fft_(n, twiddles) {}
    int size() const override { return fft_.size(); }
    std::string name() const override { return "gpu-fp32"; }
    void forward(ComplexImage<double>& image) override {
        check_image(image);
        ComplexImage<float> in(image.n);
        std::copy(image.data.begin(), image.data.end(), in.data.begin());
        const ComplexImage<float> out = fft_.forward(in);
        std::copy(out.data.begin(), out.data.end(), image.data.begin());
    }

private:
    GpuFft fft_;
};

}  // namespace

std::unique_ptr<Fft2D> make_fft(FftBackend backend, int n, TwiddleSource twiddles) {
    switch (backend) {
        case FftBackend::gpu_fp32:
            check_gpu_size(n);
            return std::make_unique<GpuFft2D>(n, twiddles);
        case FftBackend::fftw_float:
            check_fftw_size(n);
            return std::make_unique<FftwFft2D<float>>(n);
        case FftBackend::fftw_double:
            check_fftw_size(n);
            return std::make_unique<FftwFft2D<double>>(n);
    }
    throw std::invalid_argument("make_fft: unknown FftBackend");
}

}  // namespace atonlab::stimuli
