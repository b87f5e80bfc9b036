// A minimal ship simulator driving atonlab's pipeline through the stimuli
// library alone (no runner): it owns its GL context, builds its scene in code,
// and every frame renders lights → glare → adaptation → tone mapping →
// encoding with the real frame time, then presents the code values. With
// --ldr it instead draws its own display-referred frame (a flat grey "LDR
// renderer") and lets atonlab add the lights' glare on top (K2012 §6.2.2).
//
//   simulator_loop [--frames N] [--ldr] [--png LAST.png]
//
// Headless (EGL) so it runs in CI; a simulator with a window would create a
// GLFW context instead (gl::create_window_context) and swap buffers after present().
#include <epoxy/gl.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/pipeline.h"
#include "atonlab/stimuli/rhythm.h"

namespace st = atonlab::stimuli;
namespace d = atonlab::display;

int main(int argc, char** argv) {
    int frames = 30;
    bool ldr = false;
    std::string png;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--frames") && i + 1 < argc)
            frames = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--ldr"))
            ldr = true;
        else if (!std::strcmp(argv[i], "--png") && i + 1 < argc)
            png = argv[++i];
        else {
            std::fprintf(stderr, "usage: simulator_loop [--frames N] [--ldr] [--png LAST.png]\n");
            return 2;
        }
    }
    try {
        auto context = atonlab::gl::create_headless_context();

        // The simulator's own world: a bridge 12 m above the sea at dusk, a flashing
        // red buoy ahead and a white harbour light.
        st::Scene scene;
        scene.display = {640, 360, 0.598, 0.9};
        scene.camera.position_m = {0.0, 12.0, 0.0};
        scene.environment.luminance_cd_m2 = 0.03;
        scene.adaptation_cd_m2 = 0.03;
        scene.output.adaptation.mode = st::AdaptationMode::dynamic;
        scene.output.ldr_glare = ldr;
        // A navigator must name the buoy's colour: a core brighter than the display shows in red
        // stays red and gives up luminance (docs/tone-mapping.md "Out of gamut: colour or
        // luminance"). The tone mapper and the encoder take the one choice together.
        scene.output.encode.out_of_gamut = d::OutOfGamut::keep_signal_colour;
        scene.glare.model = st::GlareModel::wave_optics;
        scene.glare.psf_size = 256;
        scene.glare.eye.gratings.enabled = false;  // resolved only from N = 512
        st::Light buoy;
        buoy.name = "buoy";
        buoy.position_m = {-20.0, 2.0, -800.0};
        buoy.intensity_cd = 120.0;
        buoy.rgb_per_cd = *d::iala_colour_rgb("red");
        const st::Rhythm fl = st::parse_rhythm("Fl R 3s");
        buoy.rhythm = fl.channels.at(0).knots;
        buoy.rhythm_period_s = fl.period_s;
        st::Light harbour;
        harbour.name = "harbour";
        harbour.position_m = {150.0, 15.0, -2500.0};
        harbour.intensity_cd = 2000.0;
        scene.lights = {buoy, harbour};

        // The LDR renderer's frame: display-referred, relative to white.
        std::vector<float> grey(static_cast<std::size_t>(640) * 360 * 4, 0.02f);
        atonlab::gl::Texture2D ldr_frame(640, 360, atonlab::gl::PixelFormat::rgba32f);
        ldr_frame.upload(grey.data());

        st::Pipeline pipeline;
        auto last = std::chrono::steady_clock::now();
        double t = 0.0;
        for (int f = 0; f < frames; ++f) {
            const auto now = std::chrono::steady_clock::now();
            const double dt = f == 0 ? 0.0 : std::chrono::duration<double>(now - last).count();
            last = now;
            t += dt;
            scene.camera.yaw_deg = 0.5 * std::sin(t);  // the ship rolls a little
            if (ldr)
                pipeline.render_ldr(ldr_frame, scene, t);
            else
                pipeline.render(scene, t, dt);
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            pipeline.present(0, 0);  // into the simulator's framebuffer (none here: headless)
        }
        const st::EncodedImage codes = pipeline.display().read_codes();
        long lit = 0;
        for (auto c : codes.rgb) lit += c > 0 ? 1 : 0;
        std::printf("simulator_loop: %d frames%s, adapted to %.4g cd/m2, %ld of %zu code values above 0\n", frames,
                    ldr ? " (LDR path)" : "", pipeline.display().adaptation_cd_m2(), lit, codes.rgb.size());
        if (!png.empty()) {
            std::vector<float> v(codes.rgb.size());
            for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<float>(codes.rgb[i]) / 255.0f;
            st::write_png_rgb8(png, codes.width, codes.height, v);
        }
        return lit > 0 ? 0 : 1;
    } catch (const atonlab::gl::ContextUnavailable& e) {
        std::fprintf(stderr, "simulator_loop: %s\n", e.what());
        return 77;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "simulator_loop: %s\n", e.what());
        return 1;
    }
}
