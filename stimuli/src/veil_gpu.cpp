// The `cie` veil as compute shaders (veiling_glare.h, GpuVeilingGlare;
// shaders/veil_gpu.comp, fft_rows.comp).
#include <epoxy/gl.h>
#include <fftw3.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <map>
#include <numbers>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "atonlab/display/tonemap.h"
#include "atonlab/stimuli/veiling_glare.h"
#include "fftw_planner.h"
#include "gl_enums.h"
#include "gpu_fft_lines.h"

namespace atonlab::stimuli {

namespace {

constexpr int kMinLength = 16;     // fft_rows.comp's smallest line
constexpr int kMaxLength = 4096;   // a line of 4096 vec2 is 32 KiB of shared memory, GL's guaranteed minimum
constexpr int kR = GpuVeilingGlare::kNearRadiusPx;

int power_of_two_at_least(int m) {
    int n = kMinLength;
    while (n < m) n *= 2;
    return n;
}

/// The longest line fft_rows.comp can hold on this context: n vec2 in a workgroup's shared memory.
int longest_line() {
    GLint bytes = 0;
    glGetIntegerv(GL_MAX_COMPUTE_SHARED_MEMORY_SIZE, &bytes);
    int n = kMinLength;
    while (n * 2 <= kMaxLength && static_cast<long>(n) * 2 * 8 <= bytes) n *= 2;
    return n;
}

unsigned groups(int count, int size) {
    return static_cast<unsigned>((count + size - 1) / size);
}

void storage_barrier() {
    ATONLAB_GL_CHECK(glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT));
}

/// The kernel's far part (the window |dx|, |dy| ≤ R zeroed) with its centre at
/// (0, 0), negative offsets wrapped, transformed once in double: K is even in x
/// and y, so its spectrum is real and even; the full mx × my spectrum, scaled
/// by 1/(mx·my) (the inverse's normalisation), rounded once to float.
std::vector<float> far_spectrum(const VeilKernelQuadrant& k, int mx, int my) {
    const int w = k.width, h = k.height;
    std::vector<double> wrapped(static_cast<std::size_t>(mx) * static_cast<std::size_t>(my), 0.0);
    for (int dy = -(h - 1); dy <= h - 1; ++dy)
        for (int dx = -(w - 1); dx <= w - 1; ++dx) {
            if (std::abs(dx) <= kR && std::abs(dy) <= kR) continue;
            wrapped[static_cast<std::size_t>((dy + my) % my) * static_cast<std::size_t>(mx) +
                    static_cast<std::size_t>((dx + mx) % mx)] = k.at(std::abs(dx), std::abs(dy));
        }
    const int cols = mx / 2 + 1;
    std::vector<std::complex<double>> hat(static_cast<std::size_t>(my) * static_cast<std::size_t>(cols));
    fftw_plan p;
    {
        std::lock_guard lock(detail::fftw_planner_mutex());
        p = fftw_plan_dft_r2c_2d(my, mx, wrapped.data(), reinterpret_cast<fftw_complex*>(hat.data()), FFTW_ESTIMATE);
    }
    if (p == nullptr) throw std::runtime_error("FFTW could not plan the veil kernel's transform");
    fftw_execute(p);
    detail::count_cpu_ffts();
    {
        std::lock_guard lock(detail::fftw_planner_mutex());
        fftw_destroy_plan(p);
    }
    const double norm = 1.0 / (static_cast<double>(mx) * my);
    std::vector<float> out(wrapped.size());
    for (int y = 0; y < my; ++y)
        for (int x = 0; x < mx; ++x) {
            const int c = x <= mx / 2 ? x : mx - x;  // even in x: X(mx − x, y) = X(x, y)
            out[static_cast<std::size_t>(y) * static_cast<std::size_t>(mx) + static_cast<std::size_t>(x)] =
                static_cast<float>(hat[static_cast<std::size_t>(y) * static_cast<std::size_t>(cols) +
                                       static_cast<std::size_t>(c)]
                                       .real() *
                                   norm);
        }
    return out;
}

/// S(i, j) = Σ over the frame's pixels q of K(q − p): the share of a light at
/// p = (i, j) that stays in the frame, from prefix sums of the quadrant in
/// double. With T(a, b) = Σ_{dx ≤ a, dy ≤ b} K, the row and column sums
/// Rw(a) = Σ_{dx ≤ a} K(dx, 0) and Cl(b) = Σ_{dy ≤ b} K(0, dy), the window
/// [−a1, a2] × [−b1, b2] of the even kernel holds
/// Σ T(a_s, b_t) − Rw(a1) − Rw(a2) − Cl(b1) − Cl(b2) + K(0, 0) (the axes
/// counted once).
std::vector<float> kept_share(const VeilKernelQuadrant& k) {
    const int w = k.width, h = k.height;
    const auto uw = static_cast<std::size_t>(w);
    std::vector<double> t(uw * static_cast<std::size_t>(h));
    for (int b = 0; b < h; ++b) {
        double row = 0;
        for (int a = 0; a < w; ++a) {
            row += k.at(a, b);
            t[static_cast<std::size_t>(b) * uw + static_cast<std::size_t>(a)] =
                row + (b > 0 ? t[static_cast<std::size_t>(b - 1) * uw + static_cast<std::size_t>(a)] : 0.0);
        }
    }
    std::vector<double> rw(uw), cl(static_cast<std::size_t>(h));
    for (int a = 0; a < w; ++a) rw[static_cast<std::size_t>(a)] = k.at(a, 0) + (a > 0 ? rw[static_cast<std::size_t>(a - 1)] : 0.0);
    for (int b = 0; b < h; ++b) cl[static_cast<std::size_t>(b)] = k.at(0, b) + (b > 0 ? cl[static_cast<std::size_t>(b - 1)] : 0.0);
    auto at = [&](int a, int b) { return t[static_cast<std::size_t>(b) * uw + static_cast<std::size_t>(a)]; };
    std::vector<float> s(uw * static_cast<std::size_t>(h));
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            const int a1 = i, a2 = w - 1 - i, b1 = j, b2 = h - 1 - j;
            const double v = at(a1, b1) + at(a1, b2) + at(a2, b1) + at(a2, b2) - rw[static_cast<std::size_t>(a1)] -
                             rw[static_cast<std::size_t>(a2)] - cl[static_cast<std::size_t>(b1)] -
                             cl[static_cast<std::size_t>(b2)] + k.at(0, 0);
            s[static_cast<std::size_t>(j) * uw + static_cast<std::size_t>(i)] = static_cast<float>(v);
        }
    return s;
}

}  // namespace

struct GpuVeilingGlare::Impl {
    int width = 0, height = 0, mx = 0, my = 0;
    double focal_px = 0;
    CieObserver observer;
    bool ready = false;
    int builds = 0;
    gl::Program pack, multiply, rows, columns;
    std::map<std::pair<bool, gl::PixelFormat>, gl::Program> unpack;  // (add, target format)
    gl::Buffer rg, blue, lux, omega, kept, partials, k_hat, k_near, row_twiddles, column_twiddles;

    void build(int w, int h, double f, const CieObserver& obs);
    const gl::Program& unpack_program(bool add, gl::PixelFormat format);
    void transform(gl::Buffer& data, bool rows_first);
};

std::string GpuVeilingGlare::unsupported_reason(int w, int h) {
    const int mx = power_of_two_at_least(2 * w - 1), my = power_of_two_at_least(2 * h - 1);
    const int longest = longest_line();
    if (mx <= longest && my <= longest) return {};
    return fmt::format(
        "a {}x{} frame needs {}x{}-point transforms, and this GPU's workgroups hold lines of at most {} points",
        w, h, mx, my, longest);
}

void GpuVeilingGlare::Impl::build(int w, int h, double f, const CieObserver& obs) {
    const CieGlareSpread gsf = cie_glare_spread(obs);  // validates the observer first
    if (const std::string why = unsupported_reason(w, h); !why.empty())
        throw std::runtime_error("the whole-frame veil cannot run on the GPU here: " + why);
    ready = false;
    width = w;
    height = h;
    focal_px = f;
    observer = obs;
    mx = power_of_two_at_least(2 * w - 1);
    my = power_of_two_at_least(2 * h - 1);
    const VeilKernelQuadrant quadrant = veil_kernel_quadrant(gsf, w, h, f);

    const auto pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    const auto padded = static_cast<std::size_t>(mx) * static_cast<std::size_t>(my);
    std::vector<float> om(pixels);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            om[static_cast<std::size_t>(j) * static_cast<std::size_t>(w) + static_cast<std::size_t>(i)] =
                static_cast<float>(frame_pixel_solid_angle_sr(i, j, w, h, f));
    std::vector<float> near(static_cast<std::size_t>((kR + 1) * (kR + 1)), 0.0f);
    for (int dy = 0; dy <= kR; ++dy)
        for (int dx = 0; dx <= kR; ++dx)
            if (dx < w && dy < h)
                near[static_cast<std::size_t>(dy * (kR + 1) + dx)] = static_cast<float>(quadrant.at(dx, dy));

    rg = gl::Buffer(padded * 2 * sizeof(float), nullptr, gl::BufferUsage::dynamic_draw);
    blue = gl::Buffer(padded * 2 * sizeof(float), nullptr, gl::BufferUsage::dynamic_draw);
    lux = gl::Buffer(pixels * 4 * sizeof(float), nullptr, gl::BufferUsage::dynamic_draw);
    omega = gl::Buffer::from(std::span<const float>(om));
    kept = gl::Buffer::from(std::span<const float>(kept_share(quadrant)));
    const std::size_t pack_groups = static_cast<std::size_t>(groups(mx, 16)) * groups(h, 16);
    partials = gl::Buffer(pack_groups * 2 * 4 * sizeof(float), nullptr, gl::BufferUsage::dynamic_read);
    k_hat = gl::Buffer::from(std::span<const float>(far_spectrum(quadrant, mx, my)));
    k_near = gl::Buffer::from(std::span<const float>(near));
    row_twiddles = gl::Buffer::from(std::span<const float>(detail::fft_twiddle_table(mx)));
    column_twiddles = gl::Buffer::from(std::span<const float>(detail::fft_twiddle_table(my)));
    rows = detail::fft_line_program(mx, mx, false, TwiddleSource::table_from_double);
    columns = detail::fft_line_program(my, mx, true, TwiddleSource::table_from_double);
    if (!pack) pack = gl::Program::build({{gl::ShaderStage::compute, "veil_gpu.comp"}}, {"VEIL_PACK 1"});
    if (!multiply) multiply = gl::Program::build({{gl::ShaderStage::compute, "veil_gpu.comp"}}, {"VEIL_MULTIPLY 1"});
    ready = true;
    ++builds;
}

const gl::Program& GpuVeilingGlare::Impl::unpack_program(bool add, gl::PixelFormat format) {
    auto [it, made] = unpack.try_emplace({add, format});
    if (made) {
        const std::string radius = fmt::format("VEIL_NEAR_RADIUS {}", kR);
        const std::string image = fmt::format("VEIL_IMAGE_FORMAT {}", format == gl::PixelFormat::rgba16f ? "rgba16f" : "rgba32f");
        it->second = gl::Program::build({{gl::ShaderStage::compute, "veil_gpu.comp"}},
                                        {"VEIL_UNPACK 1", radius, image, add ? "VEIL_ADD 1" : "VEIL_REPLACE 1"});
    }
    return it->second;
}

// The 2-D transform of one padded image: along x over the frame's rows only
// (the rows beyond are zero before the forward transform, and not needed after
// the inverse one), along y over every column.
void GpuVeilingGlare::Impl::transform(gl::Buffer& data, bool rows_first) {
    data.bind_storage(0);
    auto along_rows = [&] {
        row_twiddles.bind_storage(1);
        rows.use();
        ATONLAB_GL_CHECK(glDispatchCompute(static_cast<GLuint>(height), 1, 1));
        storage_barrier();
    };
    auto along_columns = [&] {
        column_twiddles.bind_storage(1);
        columns.use();
        ATONLAB_GL_CHECK(glDispatchCompute(static_cast<GLuint>(mx), 1, 1));
        storage_barrier();
    };
    if (rows_first) {
        along_rows();
        along_columns();
    } else {
        along_columns();
        along_rows();
    }
}

GpuVeilingGlare::GpuVeilingGlare() : impl_(std::make_unique<Impl>()) {}
GpuVeilingGlare::~GpuVeilingGlare() = default;

int GpuVeilingGlare::kernel_builds() const {
    return impl_->builds;
}

glm::dvec3 GpuVeilingGlare::apply(gl::Texture2D& light, gl::Texture2D* add_to, double scale, double f,
                                  const CieObserver& obs) {
    Impl& m = *impl_;
    const int w = light.width(), h = light.height();
    if (light.format() != gl::PixelFormat::rgba32f)
        throw std::invalid_argument("GpuVeilingGlare::apply: the light texture must be RGBA32F");
    if (add_to != nullptr && (add_to->width() != w || add_to->height() != h ||
                              (add_to->format() != gl::PixelFormat::rgba32f && add_to->format() != gl::PixelFormat::rgba16f)))
        throw std::invalid_argument("GpuVeilingGlare::apply: the target must be an RGBA32F or RGBA16F texture of the light's size");
    if (!m.ready || m.width != w || m.height != h || m.focal_px != f || m.observer.age_years != obs.age_years ||
        m.observer.pigmentation != obs.pigmentation)
        m.build(w, h, f, obs);

    // The padding rows must be zero for the forward transform; the last frame's inverse left values there.
    const auto row_bytes = static_cast<GLintptr>(m.mx) * 2 * static_cast<GLintptr>(sizeof(float));
    for (gl::Buffer* b : {&m.rg, &m.blue})
        ATONLAB_GL_CHECK(glClearNamedBufferSubData(b->id(), GL_RG32F, row_bytes * h,
                                                   row_bytes * (m.my - h), GL_RG, GL_FLOAT, nullptr));
    m.rg.bind_storage(0);
    m.blue.bind_storage(1);
    m.lux.bind_storage(2);
    m.omega.bind_storage(3);
    m.kept.bind_storage(4);
    m.partials.bind_storage(5);
    light.bind(0);
    m.pack.use();
    m.pack.set("frame_size", w, h);
    m.pack.set("pitch", static_cast<unsigned>(m.mx));
    const GLuint pack_x = groups(m.mx, 16), pack_y = groups(h, 16);
    ATONLAB_GL_CHECK(glDispatchCompute(pack_x, pack_y, 1));
    storage_barrier();

    m.transform(m.rg, true);
    m.transform(m.blue, true);
    m.rg.bind_storage(0);
    m.blue.bind_storage(1);
    m.k_hat.bind_storage(6);
    m.multiply.use();
    m.multiply.set("pitch", static_cast<unsigned>(m.mx));
    ATONLAB_GL_CHECK(glDispatchCompute(groups(m.mx, 256), static_cast<GLuint>(m.my), 1));
    storage_barrier();
    m.transform(m.rg, false);
    m.transform(m.blue, false);

    gl::Texture2D& target = add_to != nullptr ? *add_to : light;
    const gl::Program& unpack = m.unpack_program(add_to != nullptr, target.format());
    m.rg.bind_storage(0);
    m.blue.bind_storage(1);
    m.lux.bind_storage(2);
    m.omega.bind_storage(3);
    m.k_near.bind_storage(7);
    ATONLAB_GL_CHECK(glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT));
    target.bind_image(0, true, true);
    unpack.use();
    unpack.set("frame_size", w, h);
    unpack.set("pitch", static_cast<unsigned>(m.mx));
    unpack.set("scale", static_cast<float>(scale));
    const glm::dvec3 sw = display::scotopic_weights_rgb();
    unpack.set("scotopic_weights", static_cast<float>(sw.r), static_cast<float>(sw.g), static_cast<float>(sw.b));
    ATONLAB_GL_CHECK(glDispatchCompute(groups(w, 16), groups(h, 16), 1));
    ATONLAB_GL_CHECK(glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                                     GL_TEXTURE_UPDATE_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT));

    // Σ e and Σ e·S per channel from the pack pass's partial sums, in double.
    std::vector<float> sums(static_cast<std::size_t>(pack_x) * pack_y * 8);
    m.partials.download(0, sums.size() * sizeof(float), sums.data());
    glm::dvec3 in{0.0}, kept{0.0};
    for (std::size_t g = 0; g < sums.size(); g += 8)
        for (int c = 0; c < 3; ++c) {
            in[c] += sums[g + static_cast<std::size_t>(c)];
            kept[c] += sums[g + 4 + static_cast<std::size_t>(c)];
        }
    glm::dvec3 outside{0.0};
    for (int c = 0; c < 3; ++c)
        if (in[c] > 0) outside[c] = std::clamp(1.0 - kept[c] / in[c], 0.0, 1.0);
    return outside;
}

}  // namespace atonlab::stimuli
