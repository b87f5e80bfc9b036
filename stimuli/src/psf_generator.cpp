#include "atonlab/stimuli/psf_generator.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <bit>
#include <chrono>
#include <cstdint>
#include <complex>
#include <optional>
#include <stdexcept>
#include <string>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/spectral_path.h"
#include "parallel.h"
#include "psf_binning.h"
#include "spectral_terms.h"

namespace atonlab::stimuli {

namespace {
constexpr int kMaxSpectralSamples = 128;  // psf_spectral.comp MAX_SAMPLES

unsigned groups_for(std::size_t count) {
    return static_cast<unsigned>((count + 255) / 256);
}

/// A pupil-plane field as the generator uploads it for its FFT placement: the
/// field itself rounded to float (the GPU transforms it), or its spectrum by
/// FFTW in double rounded once to float (as fast as FFTW float on the machines
/// measured, bench fft_nN, and exact).
ComplexImage<float> field_as_uploaded(ComplexImage<double> f, ComputePlacement fft) {
    if (fft == ComputePlacement::cpu) fftw_forward(f);
    ComplexImage<float> packed(f.n);
    for (std::size_t i = 0; i < f.data.size(); ++i) packed.data[i] = std::complex<float>(f.data[i]);
    return packed;
}
}  // namespace

struct GpuPsfGenerator::Impl {
    int n;
    ComputePlacement placement;
    std::optional<GpuFft> fft;  // empty when the FFT runs on the CPU
    gl::Program magnitude = gl::Program::build({{gl::ShaderStage::compute, "psf_ops.comp"}}, {"OP_MAGNITUDE"});
    gl::Program scale_mono = gl::Program::build({{gl::ShaderStage::compute, "psf_ops.comp"}}, {"OP_SCALE_MONO"});
    gl::Program downsample = gl::Program::build({{gl::ShaderStage::compute, "psf_ops.comp"}}, {"OP_DOWNSAMPLE"});
    gl::Program scale_rgb = gl::Program::build({{gl::ShaderStage::compute, "psf_ops.comp"}}, {"OP_SCALE_RGB"});
    gl::Program reduce_mono = gl::Program::build({{gl::ShaderStage::compute, "psf_reduce.comp"}}, {"REDUCE_MONO"});
    gl::Program reduce_rgb = gl::Program::build({{gl::ShaderStage::compute, "psf_reduce.comp"}}, {"REDUCE_RGB"});
    gl::Program spectral = gl::Program::build({{gl::ShaderStage::compute, "psf_spectral.comp"}});
    gl::Program anchor = gl::Program::build({{gl::ShaderStage::compute, "psf_anchored.comp"}}, {"OP_ANCHOR"});
    gl::Program combine = gl::Program::build({{gl::ShaderStage::compute, "psf_anchored.comp"}}, {"OP_COMBINE"});
    gl::Buffer field, mono, level1, rgb, sums;
    // The anchored path's (generate_anchored), made on its first call.
    std::vector<gl::Buffer> fields;  // each anchor's transformed field(s)
    gl::Buffer anchors, core_power, core_sums, bins, recipe_samples, recipe_terms, recipe_taps;
    gl::GpuTimer timers[4];
    PsfGpuTimings last;
    double degrees_per_texel = 0;

    Impl(int size, TwiddleSource twiddles, ComputePlacement where) : n(size), placement(resolve_placement(where)) {
        if (placement == ComputePlacement::gpu)
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
    void normalise_rgb();
    /// The field into `out` transformed: FFTW double on the CPU (rounded once
    /// to float), or uploaded as float for the GPU's FFT (transform_on_gpu()).
    void upload_field(const ComplexImage<double>& field, gl::Buffer& out) const;
    void transform_on_gpu(gl::Buffer& data) {
        if (placement == ComputePlacement::gpu) fft->forward(data);
    }
    /// |F|² of `spectrum`, centred, into `power` and its sum into `sum`.
    void power_and_sum(const gl::Buffer& spectrum, const gl::Buffer& power, const gl::Buffer& sum);
    void upload_recipe(const std::vector<detail::SpectralSample>& recipe);
    void upload_bins(double fine_over_coarse);
};

void GpuPsfGenerator::Impl::upload_field(const ComplexImage<double>& f, gl::Buffer& out) const {
    const ComplexImage<float> packed = field_as_uploaded(f, placement);
    // std::complex<float> is two floats (re, im): the std430 layout of vec2.
    out.upload(0, packed.data.size() * sizeof(std::complex<float>), packed.data.data());
}

void GpuPsfGenerator::Impl::power_and_sum(const gl::Buffer& spectrum, const gl::Buffer& power, const gl::Buffer& sum) {
    const auto texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    spectrum.bind_storage(0);
    power.bind_storage(1);
    sum.bind_storage(4);
    magnitude.set("n", static_cast<unsigned>(n));
    magnitude.use();
    glDispatchCompute(groups_for(texels), 1, 1);
    barrier();
    reduce_mono.set("count", static_cast<unsigned>(texels));
    reduce_mono.use();
    glDispatchCompute(1, 1, 1);
    barrier();
}

// Per coarse texel (both axes alike) the fine texels that overlap it and their
// shares, inverted from detail::axis_shares (what bin_into scatters).
void GpuPsfGenerator::Impl::upload_bins(double fine_over_coarse) {
    const std::vector<detail::AxisShare> shares = detail::axis_shares(n, n, fine_over_coarse);
    // bins[m] … bins[m + 1]: coarse texel m's entries, each two words (the
    // fine index and the share's float bits) after the n + 1 offsets.
    std::vector<std::vector<std::uint32_t>> gather(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) {
        const detail::AxisShare& a = shares[static_cast<std::size_t>(k)];
        for (std::size_t b = 0; b < a.share.size(); ++b) {
            const int m = a.first + static_cast<int>(b);
            if (m < 0 || m >= n || a.share[b] == 0) continue;
            gather[static_cast<std::size_t>(m)].push_back(static_cast<std::uint32_t>(k));
            gather[static_cast<std::size_t>(m)].push_back(std::bit_cast<std::uint32_t>(static_cast<float>(a.share[b])));
        }
    }
    std::vector<std::uint32_t> words(static_cast<std::size_t>(n) + 1);
    std::uint32_t entries = 0;
    for (std::size_t m = 0; m < gather.size(); ++m) {
        words[m] = entries;
        entries += static_cast<std::uint32_t>(gather[m].size() / 2);
    }
    words[static_cast<std::size_t>(n)] = entries;
    for (const auto& g : gather) words.insert(words.end(), g.begin(), g.end());
    bins = gl::Buffer(words.size() * sizeof(std::uint32_t), words.data(), gl::BufferUsage::static_draw);
}

void GpuPsfGenerator::Impl::upload_recipe(const std::vector<detail::SpectralSample>& recipe) {
    struct SampleRecord {
        float xyz[4];
        std::uint32_t first_term, term_count, unused[2];
    };
    struct TermRecord {
        std::uint32_t anchor;
        std::int32_t taps;
        float scale;
        std::uint32_t unused;
    };
    struct TapRecord {
        std::int32_t first;
        float w[detail::kLanczosTaps];
    };
    static_assert(sizeof(SampleRecord) == 32 && sizeof(TermRecord) == 16 && sizeof(TapRecord) == 28,
                  "the std430 layouts of psf_anchored.comp");
    std::vector<SampleRecord> sample_records;
    std::vector<TermRecord> term_records;
    std::vector<TapRecord> tap_records;
    for (const detail::SpectralSample& s : recipe) {
        sample_records.push_back({{s.xyz.x, s.xyz.y, s.xyz.z, 0.0f},
                                  static_cast<std::uint32_t>(term_records.size()),
                                  static_cast<std::uint32_t>(s.terms.size()),
                                  {0, 0}});
        for (const detail::SpectralTerm& t : s.terms) {
            std::int32_t taps = -1;
            if (t.ratio != 1.0) {
                taps = static_cast<std::int32_t>(tap_records.size());
                for (std::size_t i = 0; i < t.taps.first.size(); ++i) {
                    TapRecord r{t.taps.first[i], {}};
                    for (std::size_t k = 0; k < detail::kLanczosTaps; ++k)
                        r.w[k] = static_cast<float>(t.taps.weight[i * detail::kLanczosTaps + k]);
                    tap_records.push_back(r);
                }
            }
            term_records.push_back({static_cast<std::uint32_t>(t.anchor), taps, t.scale, 0});
        }
    }
    if (tap_records.empty()) tap_records.push_back({});  // a buffer may not be empty
    recipe_samples = gl::Buffer(sample_records.size() * sizeof(SampleRecord), sample_records.data(),
                                gl::BufferUsage::static_draw);
    recipe_terms =
        gl::Buffer(term_records.size() * sizeof(TermRecord), term_records.data(), gl::BufferUsage::static_draw);
    recipe_taps = gl::Buffer(tap_records.size() * sizeof(TapRecord), tap_records.data(), gl::BufferUsage::static_draw);
}

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
    normalise_rgb();
}

// The RGB PSF (binding 3) to unit luminance sum, by a double reduction.
void GpuPsfGenerator::Impl::normalise_rgb() {
    const auto texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    rgb.bind_storage(3);
    sums.bind_storage(4);
    reduce_rgb.set("count", static_cast<unsigned>(texels));
    reduce_rgb.use();
    glDispatchCompute(1, 1, 1);
    barrier();
    const display::Mat3& to_xyz = display::rec709_rgb_to_xyz();  // Y: row 1 (column-major)
    scale_rgb.set("n", static_cast<unsigned>(n));
    scale_rgb.set("luminance_weights", static_cast<float>(to_xyz[0][1]), static_cast<float>(to_xyz[1][1]),
                  static_cast<float>(to_xyz[2][1]));
    scale_rgb.use();
    glDispatchCompute(groups_for(texels), 1, 1);
    barrier();
}

GpuPsfGenerator::GpuPsfGenerator(int n, TwiddleSource twiddles, ComputePlacement fft)
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
ComputePlacement GpuPsfGenerator::fft_placement() const {
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

    const bool cpu_fft = m.placement == ComputePlacement::cpu;
    double cpu_fft_ms = 0;
    m.timers[0].begin();
    const auto t0 = std::chrono::steady_clock::now();
    m.upload_field(pupil, m.field);
    if (cpu_fft) cpu_fft_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    m.timers[0].end();

    m.timers[1].begin();
    m.transform_on_gpu(m.field);
    m.timers[1].end();

    // |F|², shift, sum, unit sum, level 1.
    m.timers[2].begin();
    m.power_and_sum(m.field, m.mono, m.sums);
    m.bind_all();
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

AnchoredPupilPlanes anchored_pupil_planes(const EyeModel& eye, int n, const SpectralSamples& samples, int anchor_count,
                                          double time_s, ComputePlacement fft) {
    if (fft == ComputePlacement::automatic)
        throw std::invalid_argument("anchored_pupil_planes: the FFT placement must be resolved (gpu or cpu)");
    eye.validate(n);
    AnchoredPupilPlanes out;
    out.n = n;
    out.anchor_nm = spectral_anchor_wavelengths(samples, anchor_count);
    out.two_scales = has_two_scales(eye);
    out.fft = fft;
    const std::size_t parts = out.two_scales ? 2 : 1;
    out.fields.resize(out.anchor_nm.size() * parts);
    detail::parallel_items(static_cast<int>(out.anchor_nm.size()), [&](int i) {
        const auto a = static_cast<std::size_t>(i);
        const double w = eye.plane_width_mm * out.anchor_nm[a] / kReferenceWavelengthNm;
        if (out.two_scales) {
            PupilParts p = pupil_parts(eye, n, out.anchor_nm[a], w, time_s);
            out.fields[a * parts] = field_as_uploaded(std::move(p.scatter), fft);
            out.fields[a * parts + 1] = field_as_uploaded(std::move(p.core), fft);
        } else {
            out.fields[a] = field_as_uploaded(pupil_plane(eye, n, out.anchor_nm[a], w, time_s), fft);
        }
    });
    return out;
}

void GpuPsfGenerator::generate_anchored(const EyeModel& eye, const SpectralSamples& samples, int anchor_count,
                                        double time_s, const AnchoredPupilPlanes* drawn) {
    Impl& m = *impl_;
    const int n = m.n;
    eye.validate(n);
    const std::vector<double> anchor_nm = spectral_anchor_wavelengths(samples, anchor_count);
    const std::size_t k = anchor_nm.size();
    const bool two_scales = has_two_scales(eye);
    const std::size_t parts = two_scales ? 2 : 1;
    const auto texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    m.degrees_per_texel = stimuli::psf_degrees_per_texel(eye);
    if (drawn && (drawn->n != n || drawn->anchor_nm != anchor_nm || drawn->two_scales != two_scales ||
                  drawn->fft != m.placement || drawn->fields.size() != k * parts))
        throw std::invalid_argument(
            "generate_anchored: the planes drawn ahead are for another size, anchors, eye or FFT placement");

    // The pupil planes on the CPU in double, as spectral_psf_anchored draws
    // them, unless a worker thread drew them ahead.
    const auto t0 = std::chrono::steady_clock::now();
    AnchoredPupilPlanes here;
    if (!drawn) here = anchored_pupil_planes(eye, n, samples, anchor_count, time_s, m.placement);
    const std::vector<ComplexImage<float>>& planes = drawn ? drawn->fields : here.fields;
    if (m.fields.size() != planes.size()) {
        m.fields.clear();
        for (std::size_t i = 0; i < planes.size(); ++i)
            m.fields.emplace_back(texels * 2 * sizeof(float), nullptr, gl::BufferUsage::dynamic_draw);
    }
    // std::complex<float> is two floats (re, im): the std430 layout of vec2.
    for (std::size_t i = 0; i < planes.size(); ++i)
        m.fields[i].upload(0, texels * sizeof(std::complex<float>), planes[i].data.data());
    if (m.anchors.size() != k * texels * sizeof(float))
        m.anchors = gl::Buffer(k * texels * sizeof(float), nullptr, gl::BufferUsage::dynamic_draw);
    if (m.core_power.size() == 0) {  // bound for the one-scale eye too (its shader skips them)
        m.core_power = gl::Buffer(texels * sizeof(float), nullptr, gl::BufferUsage::dynamic_draw);
        m.core_sums = gl::Buffer(4 * sizeof(double), nullptr, gl::BufferUsage::dynamic_read);
    }
    // The core's texel in the scatter's: the shares of bin_into.
    m.upload_bins(two_scales ? core_degrees_per_texel(eye) / m.degrees_per_texel : 1.0);
    m.upload_recipe(detail::spectral_recipe(anchor_nm, samples, n));
    const double cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

    m.timers[1].begin();
    for (gl::Buffer& f : m.fields) m.transform_on_gpu(f);
    m.timers[1].end();

    m.timers[2].begin();
    for (std::size_t a = 0; a < k; ++a) {
        if (two_scales) m.power_and_sum(m.fields[a * parts + 1], m.core_power, m.core_sums);
        m.power_and_sum(m.fields[a * parts], m.mono, m.sums);
        m.mono.bind_storage(1);
        m.anchors.bind_storage(2);
        m.sums.bind_storage(4);
        m.core_power.bind_storage(5);
        m.core_sums.bind_storage(6);
        m.bins.bind_storage(7);
        m.anchor.set("n", static_cast<unsigned>(n));
        m.anchor.set("anchor_index", static_cast<unsigned>(a));
        m.anchor.set("two_scales", two_scales ? 1 : 0);
        m.anchor.use();
        glDispatchCompute(groups_for(texels), 1, 1);
        Impl::barrier();
    }
    m.timers[2].end();

    m.timers[3].begin();
    m.anchors.bind_storage(2);
    m.rgb.bind_storage(3);
    m.recipe_samples.bind_storage(5);
    m.recipe_terms.bind_storage(6);
    m.recipe_taps.bind_storage(7);
    const glm::mat3 xyz_to_rgb(display::rec709_xyz_to_rgb());
    m.combine.set("n", static_cast<unsigned>(n));
    m.combine.set("sample_count", static_cast<unsigned>(samples.wavelength_nm.size()));
    m.combine.set_mat3("xyz_to_rgb", &xyz_to_rgb[0][0]);
    m.combine.use();
    glDispatchCompute(groups_for(texels), 1, 1);
    Impl::barrier();
    m.normalise_rgb();
    m.timers[3].end();

    m.last = {};
    m.last.upload_ms = cpu_ms;
    m.last.fft_ms = m.timers[1].elapsed_ms().value_or(0);
    m.last.mono_ms = m.timers[2].elapsed_ms().value_or(0);
    m.last.spectral_ms = m.timers[3].elapsed_ms().value_or(0);
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
