// `atonlab psf [--pupil-mm D | --adaptation-cd-m2 L] [--clear] [--spd NAME] [--size N] -o PSF.exr`
// The glare PSF alone (K2012 §4.2): the monochromatic PSF at λ0, the RGB PSF,
// and optionally the billboard kernel's area layers, each an EXR with
// `degreesPerPixel` (and `wavelength` for the monochromatic one).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "atonlab/display/colour.h"
#include "atonlab/runner/psf_command.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/eye_model.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/glare_kernel.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/psf_generator.h"
#include "atonlab/stimuli/scene_file.h"
#include "atonlab/stimuli/spectral_path.h"

namespace atonlab::runner {

void add_psf_command(CLI::App& app, PsfOptions& o) {
    CLI::App* cmd = app.add_subcommand("psf", "Compute the eye's glare PSF (wave optics) and write it as EXR files");
    auto* pupil = cmd->add_option("--pupil-mm", o.pupil_mm, "Pupil diameter in mm");
    auto* adapt = cmd->add_option("--adaptation-cd-m2", o.adaptation_cd_m2,
                                  "Adaptation luminance (cd/m²) giving the pupil by K2012 eq 3.15 (default 0.001)");
    pupil->excludes(adapt);
    cmd->add_option("--scene", o.scene, "Take the eye model from this scene's [glare] table");
    cmd->add_option("--eye-preset", o.eye_preset,
                    "Eye preset: focused (default: two angular scales, in focus) or k2012 (the thesis's single scale "
                    "and Fresnel term); replaces the scene's eye");
    cmd->add_flag("--clear", o.clear, "A clear circular pupil: no obstacles, in focus, physical scale");
    cmd->add_option("--spd", o.spd, "Spectrum to integrate the PSF with (default d65; see docs/scene-file.md)");
    cmd->add_option("--size", o.size, "PSF size N (a power of two, 16 .. 2048; default 512)");
    cmd->add_option("--samples", o.samples, "Spectral samples (1 .. 128; default 30)");
    cmd->add_option("--seed", o.seed, "Seed of the eye's obstacles");
    cmd->add_option("--time", o.time_s, "Time (s) for the pupillary hippus, when the eye model has it on");
    cmd->add_option("--pixels-per-degree", o.pixels_per_degree,
                    "Display pixels per degree for the billboard kernel and area layers (default 50.4: 0.598 m wide "
                    "1920 px at 0.9 m)");
    cmd->add_option("--area-radius-px", o.area_radius_px,
                    "Also write the area layers up to this projected radius (px); 0 = none")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--area-layers", o.area_layers, "Most area layers (default 16)");
    cmd->add_option("-o,--output", o.exr, "Output EXR of the RGB PSF; the mono PSF goes to NAME-mono.exr")->required();
}

namespace {

stimuli::ImageRGBA32F image_of(int n, const auto& value_at) {
    stimuli::ImageRGBA32F img;
    img.width = img.height = n;
    img.rgba.resize(static_cast<std::size_t>(n) * n * 4);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            // The PSF's row 0 is at the bottom; images are written top row first.
            const glm::dvec3 v = value_at(x, n - 1 - y);
            float* p = img.pixel(x, y);
            p[0] = static_cast<float>(v.r);
            p[1] = static_cast<float>(v.g);
            p[2] = static_cast<float>(v.b);
            p[3] = 1.0f;
        }
    return img;
}

std::filesystem::path sibling(const std::filesystem::path& out, const std::string& suffix) {
    return out.parent_path() / (out.stem().string() + suffix + out.extension().string());
}

}  // namespace

PsfImages psf_images(const PsfOptions& o, const std::function<void()>& make_context) {
    // Validate everything before touching the GPU or the output paths.
    stimuli::EyeModel eye;
    if (!o.scene.empty()) eye = stimuli::load_scene(o.scene, {}).glare.eye;
    if (o.eye_preset) {
        const std::optional<stimuli::EyeModel> named = stimuli::eye_preset(*o.eye_preset);
        if (!named) {
            std::string names;
            for (const auto& n : stimuli::eye_preset_names()) names += (names.empty() ? "" : ", ") + n;
            throw InputError(SourceLocation::command_line("--eye-preset"),
                             fmt::format("unknown eye preset \"{}\"; presets are {}.", *o.eye_preset, names));
        }
        eye = *named;
    }
    if (o.seed) eye.seed = *o.seed;
    double pupil = 0;
    if (o.pupil_mm) {
        if (!(*o.pupil_mm > 0) || !std::isfinite(*o.pupil_mm))
            throw InputError(SourceLocation::command_line("--pupil-mm"),
                             fmt::format("the pupil diameter must be a positive number of mm, not {}.", *o.pupil_mm));
        pupil = *o.pupil_mm;
    } else {
        const double L = o.adaptation_cd_m2.value_or(0.001);
        if (!(L >= 0) || !std::isfinite(L))
            throw InputError(SourceLocation::command_line("--adaptation-cd-m2"),
                             fmt::format("the adaptation luminance must be a finite number ≥ 0 cd/m², not {}.", L));
        pupil = stimuli::pupil_diameter_mm_from_adaptation(L);
    }
    if (o.clear) {
        const auto seed = eye.seed;
        const auto plane = eye.plane_width_mm;
        eye = stimuli::EyeModel::clear_pupil(pupil);
        eye.seed = seed;
        eye.plane_width_mm = plane;
    }
    eye.pupil_diameter_mm = pupil;
    if (!stimuli::is_power_of_two(o.size) || o.size < stimuli::kGpuFftMinSize || o.size > stimuli::kGpuFftMaxSize)
        throw InputError(SourceLocation::command_line("--size"),
                         fmt::format("the PSF size must be a power of two from {} to {}, not {}.",
                                     stimuli::kGpuFftMinSize, stimuli::kGpuFftMaxSize, o.size));
    try {
        eye.validate(o.size);
    } catch (const InputError& e) {
        throw InputError(
            o.scene.empty() ? SourceLocation::command_line("--pupil-mm", e.where() ? e.where()->key : std::string())
                            : SourceLocation{o.scene, 0, 0, e.where() ? e.where()->key : std::string()},
            e.message());
    }
    auto spd = display::named_spectrum(o.spd);
    if (!spd) {
        std::string names;
        for (const auto& n : display::spectrum_names()) names += (names.empty() ? "" : ", ") + n;
        throw InputError(SourceLocation::command_line("--spd"),
                         fmt::format("unknown spectrum \"{}\"; named spectra are {}.", o.spd, names));
    }
    if (o.samples < 1 || o.samples > 128)
        throw InputError(SourceLocation::command_line("--samples"),
                         fmt::format("the number of spectral samples must be 1 to 128, not {}.", o.samples));
    if (!(o.pixels_per_degree > 0) || !std::isfinite(o.pixels_per_degree))
        throw InputError(SourceLocation::command_line("--pixels-per-degree"),
                         "the display's pixels per degree must be a positive number.");
    const stimuli::SpectralSamples samples = stimuli::spectral_samples(*spd, o.samples);

    make_context();
    stimuli::GpuPsfGenerator gen(o.size);
    const double dpt = stimuli::psf_degrees_per_texel(eye);
    gen.generate(eye, samples, o.time_s);
    const stimuli::MonoPsf mono = gen.read_mono();
    // The RGB PSF by the default spectral path (docs/glare.md "The spectral path").
    const int anchors = stimuli::GlareSettings{}.spectral_anchors;
    const stimuli::RgbPsf rgb = stimuli::spectral_psf_anchored(eye, o.size, samples, anchors, o.time_s);

    PsfImages out;
    auto& files = out.files;
    auto& metas = out.metas;
    stimuli::ExrMetadata meta;
    meta.units = "relative";
    meta.degrees_per_pixel = dpt;
    meta.strings["software"] = "atonlab " ATONLAB_VERSION;
    meta.strings["pupil_mm"] = fmt::format("{}", pupil);
    meta.strings["seed"] = fmt::format("{}", eye.seed);
    meta.strings["eye"] = o.clear        ? "clear pupil"
                          : o.eye_preset ? *o.eye_preset
                                         : (o.scene.empty() ? "default" : o.scene);
    meta.strings["normalisation"] = "each PSF sums to 1 (RGB: its luminance 0.2126 R + 0.7152 G + 0.0722 B)";
    stimuli::ExrMetadata rgb_meta = meta;
    rgb_meta.strings["spd"] = o.spd;
    rgb_meta.strings["spectral_samples"] = fmt::format("{}", o.samples);
    rgb_meta.strings["spectral_path"] = fmt::format("anchored, {} anchor wavelengths", anchors);
    files.emplace_back(o.exr, image_of(o.size, [&](int x, int y) { return rgb.at(x, y); }));
    metas.push_back(rgb_meta);
    stimuli::ExrMetadata mono_meta = meta;
    mono_meta.wavelength_nm = mono.wavelength_nm;
    files.emplace_back(sibling(o.exr, "-mono"),
                       image_of(o.size, [&](int x, int y) { return glm::dvec3(mono.at(x, y)); }));
    metas.push_back(mono_meta);
    if (o.area_radius_px > 0) {
        const stimuli::GlareKernel kernel = stimuli::glare_kernel_from_psf(
            rgb, o.pixels_per_degree, (o.size / 2 - 1) * dpt, stimuli::GlareWindow::silverman);
        const stimuli::AreaLayers layers = stimuli::build_area_layers(kernel, o.area_radius_px, o.area_layers);
        for (int k = 0; k < layers.layers; ++k) {
            stimuli::ExrMetadata m = meta;
            m.degrees_per_pixel = 1.0 / o.pixels_per_degree;
            m.strings["area_radius_px"] = fmt::format("{}", k * layers.radius_step_px);
            m.strings["window"] = "silverman";
            m.strings["normalisation"] = "each channel sums to 1";
            const auto* base = &layers.rgba[static_cast<std::size_t>(k) * layers.size * layers.size];
            files.emplace_back(sibling(o.exr, fmt::format("-area-{:02}", k)), image_of(layers.size, [&](int x, int y) {
                                   return glm::dvec3(base[static_cast<std::size_t>(y) * layers.size + x]);
                               }));
            metas.push_back(m);
        }
    }
    const auto t = gen.timings();
    out.summary = fmt::format(
        "psf: N={}, pupil {:.3f} mm, {:.5f} deg/texel (field ±{:.2f} deg), {} samples of {}; GPU {:.1f} ms "
        "(FFT {:.1f}, mono {:.1f}, spectral {:.1f}); luminance sum {:.6f}\n",
        o.size, pupil, dpt, o.size / 2 * dpt, o.samples, o.spd,
        t.upload_ms + t.fft_ms + t.mono_ms + t.spectral_ms, t.fft_ms, t.mono_ms, t.spectral_ms, rgb.luminance_sum());
    return out;
}

int run_psf(const PsfOptions& o) {
    std::unique_ptr<gl::Context> context;
    PsfImages images = psf_images(o, [&context] { context = gl::create_headless_context(); });
    const auto& files = images.files;
    // Everything is computed before the first file is written; files are written
    // atomically, and a failure removes the ones already written.
    std::size_t written = 0;
    try {
        for (; written < files.size(); ++written)
            stimuli::write_exr(files[written].first, files[written].second, images.metas[written]);
    } catch (...) {
        std::error_code ec;
        for (std::size_t i = 0; i < written; ++i) std::filesystem::remove(files[i].first, ec);
        throw;
    }
    std::fputs(images.summary.c_str(), stdout);
    for (const auto& f : files) std::printf("  wrote %s\n", f.first.string().c_str());
    return 0;
}

}  // namespace atonlab::runner
