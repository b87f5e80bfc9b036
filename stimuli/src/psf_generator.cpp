#include "atonlab/stimuli/psf_generator.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <chrono>
#include <complex>
#include <optional>
#include <string>

#include "atonlab/stimuli/error.h"

namespace atonlab::stimuli {

namespace {
constexpr int kMaxSpectralSamples = 128;  // psf_spectral.comp MAX_SAMPLES

unsigned groups_for(std::size_t count) {
    return static_cast<unsigned>((count + 255) / 256);
}
}  // namespace

struct GpuPsfGenerator::Impl {
    int n;
    PsfFftPlacement placement;
    std::optional<GpuFft> fft;  // empty when the FFT runs on the CPU
    gl::Program magnitude = gl::Program::build({{gl::ShaderStage::compute, "psf_ops.comp"}}, {"OP_MAGNITUDE"});
    gl::Program scale_mono = gl::Program::build({{gl::ShaderStage::compute, "psf_ops.comp"}}, {"OP_SCALE_MONO"});
    gl::Program downsample = gl::Program::build({{gl::ShaderStage::compute, "psf_ops.comp"}}, {"OP_DOWNSAMPLE"});
    gl::Program scale_rgb = gl::Program::build({{gl::ShaderStage::compute, "psf_ops.comp"}}, {"OP_SCALE_RGB"});
    gl::Program reduce_mono = gl::Program::build({{gl::ShaderStage::compute, "psf_reduce.comp"}}, {"REDUCE_MONO"});
    gl::Program reduce_rgb = gl::Program::build({{gl::ShaderStage::compute, "psf_reduce.comp"}}, {"REDUCE_RGB"});
    gl::Program spectral = gl::Program::build({{gl::ShaderStage::compute, "psf_spectral.comp"}});
    gl::Buffer field, mono, level1, rgb, sums;
    gl::GpuTimer timers[4];
    PsfGpuTimings last;
    double degrees_per_texel = 0;

    Impl(int size, TwiddleSource twiddles, PsfFftPlacement where) : n(size), placement(resolve_placement(where)) {
        if (placement == PsfFftPlacement::gpu)
            fft.emplace(size, twiddles);
        else if (!is_power_of_two(n) || n < kGpuFftMinSize || n > kGpuFftMaxSize)  // the GPU path's sizes either way
            throw InputError(SourceLocation{"", 0, 0, "size"},
                             fmt::format("the PSF size must be a power of two from {} to {}, not {}.", kGpuFftMinSize,
                                         kGpuFftMaxSize, n));
        const auto texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
        field = gl::Buffer(texels * 2 * sizeof(float), nullptr, gl::BufferUsage::dynamic_draw);
        mono = gl::Buffer(texels * sizeof(float), nullptr, gl::BufferUsage::dynamic_read);
        level1 = gl::Buffer(texels / 4 * sizeof(float), nullptr, gl::BufferUsage::dynamic_draw);
        rgb = gl::Buffer(texels * 4 * sizeof(float), nullptr, gl::BufferUsage::dynamic_read);
        sums = gl::Buffer(4 * sizeof(double), nullptr, gl::BufferUsage::dynamic_read);
        for (auto& t : timers) t = gl::GpuTimer::create();
    }
    void bind_all() const {
        field.bind_storage(0);
        mono.bind_storage(1);
        level1.bind_storage(2);
        rgb.bind_storage(3);
        sums.bind_storage(4);
    }
    static void barrier() { glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT); }

    void check_samples(const SpectralSamples& samples) const {
        const auto count = samples.wavelength_nm.size();
        if (count < 1 || count > kMaxSpectralSamples)
            throw InputError(SourceLocation{"", 0, 0, "spectral_samples"},
                             fmt::format("the GPU spectral integration takes 1 to {} wavelength samples, not {}.",
                                         kMaxSpectralSamples, count));
    }
    void downsample_mono() {
        downsample.set("n", static_cast<unsigned>(n) / 2);
        downsample.use();
        glDispatchCompute(groups_for(static_cast<std::size_t>(n) * static_cast<std::size_t>(n) / 4), 1, 1);
        barrier();
    }
    void spectral_stage(const SpectralSamples& samples);
};

// Spectral integration (eq 4.9-4.10), then unit luminance.
void GpuPsfGenerator::Impl::spectral_stage(const SpectralSamples& samples) {
    const auto texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    const auto count = static_cast<int>(samples.wavelength_nm.size());
    spectral.set("n", static_cast<unsigned>(n));
    spectral.set("sample_count", count);
    for (int s = 0; s < count; ++s) {
        const double ratio = kReferenceWavelengthNm / samples.wavelength_nm[static_cast<std::size_t>(s)];
        const glm::dvec3 w = samples.xyz_weight[static_cast<std::size_t>(s)] * ratio * ratio;
        spectral.set(fmt::format("ratio[{}]", s), static_cast<float>(ratio));
        spectral.set(fmt::format("weight[{}]", s), static_cast<float>(w.x), static_cast<float>(w.y),
                     static_cast<float>(w.z));
    }
    const glm::mat3 xyz_to_rgb(display::rec709_xyz_to_rgb());
    spectral.set_mat3("xyz_to_rgb", &xyz_to_rgb[0][0]);
    spectral.use();
    glDispatchCompute(groups_for(texels), 1, 1);
    barrier();
    reduce_rgb.set("count", static_cast<unsigned>(texels));
    reduce_rgb.use();
    glDispatchCompute(1, 1, 1);
    barrier();
    scale_rgb.set("n", static_cast<unsigned>(n));
    scale_rgb.use();
    glDispatchCompute(groups_for(texels), 1, 1);
    barrier();
}

GpuPsfGenerator::GpuPsfGenerator(int n, TwiddleSource twiddles, PsfFftPlacement fft)
    : impl_(std::make_unique<Impl>(n, twiddles, fft)) {}
GpuPsfGenerator::~GpuPsfGenerator() = default;
GpuPsfGenerator::GpuPsfGenerator(GpuPsfGenerator&&) noexcept = default;
GpuPsfGenerator& GpuPsfGenerator::operator=(GpuPsfGenerator&&) noexcept = default;

int GpuPsfGenerator::size() const {
    return impl_->n;
}
PsfGpuTimings GpuPsfGenerator::timings() const {
    return impl_->last;
}
PsfFftPlacement GpuPsfGenerator::fft_placement() const {
    return impl_->placement;
}

void GpuPsfGenerator::generate(const ComplexImage<double>& pupil, double degrees_per_texel,
                               const SpectralSamples& samples) {
    Impl& m = *impl_;
    if (pupil.n != m.n)
        throw InputError(
            SourceLocation{"", 0, 0, "size"},
            fmt::format("the pupil plane is {0}×{0} but the PSF generator was made for {1}×{1}.", pupil.n, m.n));
    m.check_samples(samples);
    m.degrees_per_texel = degrees_per_texel;
    const auto texels = static_cast<std::size_t>(m.n) * static_cast<std::size_t>(m.n);
    const auto n = static_cast<unsigned>(m.n);

    const bool cpu_fft = m.placement == PsfFftPlacement::cpu;
    double cpu_fft_ms = 0;
    m.timers[0].begin();
    ComplexImage<float> packed(m.n);
    if (cpu_fft) {
        // FFTW double, rounded once to float for the upload: as fast as FFTW
        // float on the machines measured (bench fft_nN) and exact.
        const auto t0 = std::chrono::steady_clock::now();
        ComplexImage<double> spectrum = pupil;
        fftw_forward(spectrum);
        for (std::size_t i = 0; i < texels; ++i) packed.data[i] = std::complex<float>(spectrum.data[i]);
        cpu_fft_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    } else {
        for (std::size_t i = 0; i < texels; ++i) packed.data[i] = std::complex<float>(pupil.data[i]);
    }
    // std::complex<float> is two floats (re, im): the std430 layout of vec2.
    m.field.upload(0, texels * sizeof(std::complex<float>), packed.data.data());
    m.timers[0].end();

    m.timers[1].begin();
    if (!cpu_fft) m.fft->forward(m.field);
    m.timers[1].end();

    // |F|², shift, sum, unit sum, level 1.
    m.timers[2].begin();
    m.bind_all();
    m.magnitude.set("n", n);
    m.magnitude.use();
    glDispatchCompute(groups_for(texels), 1, 1);
    Impl::barrier();
    m.reduce_mono.set("count", static_cast<unsigned>(texels));
    m.reduce_mono.use();
    glDispatchCompute(1, 1, 1);
    Impl::barrier();
    m.scale_mono.set("n", n);
    m.scale_mono.use();
    glDispatchCompute(groups_for(texels), 1, 1);
    Impl::barrier();
    m.downsample_mono();
    m.timers[2].end();

    m.timers[3].begin();
    m.spectral_stage(samples);
    m.timers[3].end();

    m.last.upload_ms = m.timers[0].elapsed_ms().value_or(0);
    m.last.fft_ms = cpu_fft ? cpu_fft_ms : m.timers[1].elapsed_ms().value_or(0);
    m.last.mono_ms = m.timers[2].elapsed_ms().value_or(0);
    m.last.spectral_ms = m.timers[3].elapsed_ms().value_or(0);
}

void GpuPsfGenerator::generate(const MonoPsf& psf, const SpectralSamples& samples) {
    Impl& m = *impl_;
    if (psf.n != m.n || psf.value.size() != static_cast<std::size_t>(m.n) * static_cast<std::size_t>(m.n))
        throw InputError(SourceLocation{"", 0, 0, "size"},
                         fmt::format("the PSF is {0}×{0} but the PSF generator was made for {1}×{1}.", psf.n, m.n));
    m.check_samples(samples);
    m.degrees_per_texel = psf.degrees_per_texel;
    m.timers[0].begin();
    const std::vector<float> packed(psf.value.begin(), psf.value.end());
    m.mono.upload(0, packed.size() * sizeof(float), packed.data());
    m.bind_all();
    m.downsample_mono();
    m.timers[0].end();
    m.timers[3].begin();
    m.spectral_stage(samples);
    m.timers[3].end();
    m.last = {};
    m.last.upload_ms = m.timers[0].elapsed_ms().value_or(0);
    m.last.spectral_ms = m.timers[3].elapsed_ms().value_or(0);
}

void GpuPsfGenerator::generate(const EyeModel& eye, const SpectralSamples& samples, double time_s) {
    if (!has_two_scales(eye)) {
        generate(pupil_plane(eye, impl_->n, kReferenceWavelengthNm, eye.plane_width_mm, time_s),
                 psf_degrees_per_texel(eye), samples);
        return;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const MonoPsf mono = mono_psf_reference(eye, impl_->n, kReferenceWavelengthNm, time_s);
    const double cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    generate(mono, samples);
    impl_->last.fft_ms = cpu_ms;  // the CPU's pupil planes, FFTs and binning
}

MonoPsf GpuPsfGenerator::read_mono() const {
    const Impl& m = *impl_;
    MonoPsf p;
    p.n = m.n;
    p.degrees_per_texel = m.degrees_per_texel;
    p.wavelength_nm = kReferenceWavelengthNm;
    std::vector<float> raw(static_cast<std::size_t>(m.n) * static_cast<std::size_t>(m.n));
    m.mono.download(0, raw.size() * sizeof(float), raw.data());
    p.value.assign(raw.begin(), raw.end());
    return p;
}

RgbPsf GpuPsfGenerator::read_rgb() const {
    const Impl& m = *impl_;
    RgbPsf p;
    p.n = m.n;
    p.degrees_per_texel = m.degrees_per_texel;
    const auto texels = static_cast<std::size_t>(m.n) * static_cast<std::size_t>(m.n);
    std::vector<float> raw(texels * 4);
    m.rgb.download(0, raw.size() * sizeof(float), raw.data());
    p.rgb.resize(texels);
    for (std::size_t i = 0; i < texels; ++i) p.rgb[i] = {raw[4 * i], raw[4 * i + 1], raw[4 * i + 2]};
    return p;
}

}  // namespace atonlab::stimuli
