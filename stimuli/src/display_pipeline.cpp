#include "atonlab/stimuli/display_pipeline.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <cmath>
#include <cstring>

#include "atonlab/stimuli/error.h"

namespace atonlab::stimuli {

void validate_output_settings(const OutputSettings& s) {
    display::validate_tonemap_settings(s.tonemap);
    s.display.validate(SourceLocation{"", 0, 0, "display"});
    if (s.encode.bits < 1 || s.encode.bits > 16)
        throw InputError(SourceLocation{"", 0, 0, "tonemap.bits"},
                         fmt::format("the frame buffer's bits per channel must be 1 to 16, not {}.", s.encode.bits));
    if (s.adaptation.stride < 1)
        throw InputError(SourceLocation{"", 0, 0, "eye.adaptation_stride"},
                         fmt::format("the log-average stride must be at least 1 pixel, not {}.", s.adaptation.stride));
    if (!(s.adaptation.epsilon_cd_m2 > 0) || !std::isfinite(s.adaptation.epsilon_cd_m2))
        throw InputError(SourceLocation{"", 0, 0, "eye.adaptation_epsilon_cd_m2"},
                         "the log-average's ε must be a positive number of cd/m².");
}

namespace {
void validate_adaptation(double adaptation_cd_m2) {
    if (!(adaptation_cd_m2 > 0) || !std::isfinite(adaptation_cd_m2))
        throw InputError(
            SourceLocation{"", 0, 0, "eye.adaptation_cd_m2"},
            fmt::format("the adaptation luminance must be a positive number of cd/m², not {}.", adaptation_cd_m2));
}
}  // namespace

void validate_output_settings(const OutputSettings& s, double adaptation_cd_m2) {
    validate_output_settings(s);
    validate_adaptation(adaptation_cd_m2);
}

namespace {
constexpr unsigned kPartialGroups = 64;  // workgroups of the first reduction pass
}

struct DisplayPipeline::Impl {
    gl::Program partial = gl::Program::build({{gl::ShaderStage::compute, "adaptation.comp"}}, {"PASS_PARTIAL"});
    gl::Program final_pass = gl::Program::build({{gl::ShaderStage::compute, "adaptation.comp"}}, {"PASS_FINAL"});
    gl::Program encode = gl::Program::build({{gl::ShaderStage::compute, "display_pass.comp"}});
    gl::Program encode_ldr = gl::Program::build({{gl::ShaderStage::compute, "display_pass.comp"}}, {"LDR_PATH"});
    gl::Program present =
        gl::Program::build({{gl::ShaderStage::vertex, "fullscreen.vert"}, {gl::ShaderStage::fragment, "present.frag"}});
    gl::VertexArray vao = gl::VertexArray::create();
    gl::Buffer partials{kPartialGroups * sizeof(double), nullptr, gl::BufferUsage::dynamic_draw};
    gl::Buffer state{4 * sizeof(double), nullptr, gl::BufferUsage::dynamic_read};
    gl::Buffer tone_block{sizeof(display::ToneMapGpuParams), nullptr, gl::BufferUsage::dynamic_draw};
    gl::Buffer display_block{sizeof(display::GpuDisplayParams), nullptr, gl::BufferUsage::dynamic_draw};
    gl::Buffer lut, codes;
    int width = 0, height = 0, bits = 8;

    Impl() { reset(); }
    void reset() {
        const double zero[4] = {0, 0, 0, 0};
        state.upload(0, sizeof(zero), zero);
    }
    void upload_settings(const OutputSettings& s) {
        // display.out_of_gamut's home is the encoder's setting; the tone mapper follows it
        // (ToneMapSettings::out_of_gamut), so that a caller sets it once.
        display::ToneMapSettings tm = s.tonemap;
        tm.out_of_gamut = s.encode.out_of_gamut;
        const display::ToneMapGpuParams tp = display::tonemap_gpu_params(tm);
        tone_block.upload(0, sizeof(tp), &tp);
        const display::GpuDisplayParams dp = display::gpu_display_params(s.display, s.encode);
        display_block.upload(0, sizeof(dp), &dp);
        std::vector<double> knots = display::gpu_display_lut(s.display);
        if (knots.empty()) knots.push_back(0.0);
        if (!lut || lut.size() < knots.size() * sizeof(double))
            lut = gl::Buffer(knots.size() * sizeof(double), knots.data(), gl::BufferUsage::dynamic_draw);
        else
            lut.upload(0, knots.size() * sizeof(double), knots.data());
        bits = s.encode.bits;
    }
    void size_for(const gl::Texture2D& t) {
        width = t.width();
        height = t.height();
        const std::size_t bytes = static_cast<std::size_t>(width) * height * 2 * sizeof(std::uint32_t);
        if (!codes || codes.size() < bytes) codes = gl::Buffer(bytes, nullptr, gl::BufferUsage::dynamic_read);
    }
    void run_encode(const gl::Program& prog, std::uint32_t frame) {
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_UNIFORM_BARRIER_BIT);
        tone_block.bind_uniform(0);
        display_block.bind_uniform(1);
        state.bind_storage(7);
        codes.bind_storage(8);
        lut.bind_storage(9);
        prog.set("size", width, height);
        prog.set("frame_index", static_cast<unsigned>(frame));
        prog.use();
        glDispatchCompute(static_cast<unsigned>((width + 15) / 16), static_cast<unsigned>((height + 15) / 16), 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    }
};

DisplayPipeline::DisplayPipeline() : impl_(std::make_unique<Impl>()) {}
DisplayPipeline::~DisplayPipeline() = default;

void DisplayPipeline::reset_adaptation() {
    impl_->reset();
}

void DisplayPipeline::process(const gl::Texture2D& hdr, const OutputSettings& s, double adaptation_cd_m2, double dt_s,
                              std::uint32_t frame, double pre_exposure, bool scotopic_alpha) {
    Impl& m = *impl_;
    if (!(dt_s >= 0) || !std::isfinite(dt_s))
        throw InputError(SourceLocation{"", 0, 0, "dt_s"},
                         fmt::format("the frame time must be a finite number of seconds ≥ 0, not {}.", dt_s));
    if (!(pre_exposure > 0) || !std::isfinite(pre_exposure))
        throw InputError(SourceLocation{"", 0, 0, "pre_exposure"},
                         fmt::format("the HDR frame's pre-exposure must be a positive number, not {}.", pre_exposure));
    const bool dynamic = s.adaptation.mode == AdaptationMode::dynamic;
    if (!dynamic) validate_adaptation(adaptation_cd_m2);
    const auto inv_pre_exposure = static_cast<float>(1.0 / pre_exposure);
    m.upload_settings(s);
    m.size_for(hdr);
    const int stride = std::max(1, s.adaptation.stride);
    const unsigned samples =
        static_cast<unsigned>(((m.width + stride - 1) / stride) * ((m.height + stride - 1) / stride));
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    m.partials.bind_storage(6);
    m.state.bind_storage(7);
    if (dynamic) {
        // eq 4.15, first pass: per-workgroup sums of log(Y + ε) in double.
        hdr.bind(0);
        m.partial.set("size", m.width, m.height);
        m.partial.set("stride", stride);
        m.partial.set("epsilon_cd_m2", static_cast<float>(s.adaptation.epsilon_cd_m2));
        m.partial.set("inv_pre_exposure", inv_pre_exposure);
        m.partial.use();
        glDispatchCompute(kPartialGroups, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    m.final_pass.set("partial_count", dynamic ? kPartialGroups : 0u);
    m.final_pass.set("sample_count", dynamic ? samples : 1u);
    m.final_pass.set("epsilon_cd_m2", static_cast<float>(s.adaptation.epsilon_cd_m2));
    m.final_pass.set("fixed_mode", dynamic ? 0 : 1);
    m.final_pass.set("fixed_cd_m2", adaptation_cd_m2);  // read in fixed mode only
    m.final_pass.set("dt_s", dt_s);
    m.final_pass.set("tau_rod_s", static_cast<float>(display::kTauRodS));
    m.final_pass.set("tau_cone_s", static_cast<float>(display::kTauConeS));
    m.final_pass.set("rod_sigma_cd_m2", static_cast<float>(display::kRodSigmaCdM2));
    m.final_pass.use();
    glDispatchCompute(1, 1, 1);
    hdr.bind(0);
    m.encode.set("inv_pre_exposure", inv_pre_exposure);
    m.encode.set("scotopic_alpha", scotopic_alpha ? 1 : 0);
    m.run_encode(m.encode, frame);
}

void DisplayPipeline::process_ldr(const gl::Texture2D& ldr, const gl::Texture2D& glare, const OutputSettings& s,
                                  double adaptation_cd_m2, std::uint32_t frame, double hdr_scale, bool scotopic_alpha) {
    Impl& m = *impl_;
    validate_adaptation(adaptation_cd_m2);
    if (ldr.width() != glare.width() || ldr.height() != glare.height())
        throw InputError(SourceLocation{"", 0, 0, "ldr"},
                         fmt::format("the LDR frame is {}×{} but the glare buffer is {}×{}.", ldr.width(), ldr.height(),
                                     glare.width(), glare.height()));
    m.upload_settings(s);
    m.size_for(ldr);
    // The LDR path has no HDR scene to measure: adaptation is the eye's level.
    const double st[4] = {adaptation_cd_m2, adaptation_cd_m2, 1.0, 0.0};
    m.state.upload(0, sizeof(st), st);
    ldr.bind(0);
    glare.bind(1);
    m.encode_ldr.set("ldr_scale", static_cast<float>(hdr_scale));
    m.encode_ldr.set("scotopic_alpha", scotopic_alpha ? 1 : 0);
    m.run_encode(m.encode_ldr, frame);
}

EncodedImage DisplayPipeline::read_codes() const {
    const Impl& m = *impl_;
    EncodedImage out;
    out.width = m.width;
    out.height = m.height;
    out.bits = m.bits;
    std::vector<std::uint32_t> raw(static_cast<std::size_t>(m.width) * m.height * 2);
    m.codes.download(0, raw.size() * sizeof(std::uint32_t), raw.data());
    out.rgb.resize(static_cast<std::size_t>(m.width) * m.height * 3);
    for (int y = 0; y < m.height; ++y)
        for (int x = 0; x < m.width; ++x) {
            const std::size_t src = (static_cast<std::size_t>(y) * m.width + x) * 2;
            const std::size_t dst = (static_cast<std::size_t>(m.height - 1 - y) * m.width + x) * 3;  // top row first
            out.rgb[dst] = static_cast<std::uint16_t>(raw[src] & 0xFFFFu);
            out.rgb[dst + 1] = static_cast<std::uint16_t>(raw[src] >> 16);
            out.rgb[dst + 2] = static_cast<std::uint16_t>(raw[src + 1]);
        }
    return out;
}

double DisplayPipeline::adaptation_cd_m2() const {
    double st[4];
    impl_->state.download(0, sizeof(st), st);
    return st[0];
}

double DisplayPipeline::log_average_cd_m2() const {
    double st[4];
    impl_->state.download(0, sizeof(st), st);
    return st[1];
}

void DisplayPipeline::present(int x, int y) const {
    const Impl& m = *impl_;
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    m.codes.bind_storage(8);
    m.present.set("size", m.width, m.height);
    m.present.set("origin", x, y);
    m.present.set("max_code", static_cast<float>((1 << m.bits) - 1));
    m.present.use();
    m.vao.bind();
    glDisable(GL_BLEND);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace atonlab::stimuli
