#pragma once
// StimulusRenderer: a frame (a list of scene overrides) → the displayed
// luminance (cd/m²) that the screen would emit around each judged light, with
// an LRU cache keyed by the exact override list, so that a frame shown twice
// is rendered once; and the code values a frame puts on the screen.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "atonlab/protocols/observer.h"
#include "atonlab/protocols/protocol.h"
#include "atonlab/runner/session/lru_cache.h"
#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/pipeline.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/stimuli/scene_file.h"

namespace atonlab::runner {

/// The displayed luminance around one judged light: a square window of the
/// screen centred on the light (pixels beyond the screen's edge are black,
/// 0 cd/m²), and the light's position in it (pixels, row 0 at the top, the
/// DisplayedImage convention).
struct LightWindow {
    protocols::DisplayedImage image;
    glm::dvec2 light_px{0.0};
    /// The light's centre in the whole frame (pixels, row 0 at the top).
    glm::dvec2 frame_px{0.0};
    /// The code values sent to the screen in the same window (displayability.h):
    int peak_code = 0;     ///< the highest code of any channel of any pixel
    bool clipped = false;  ///< a channel of a pixel is at the display's white where the lights-off frame is not
    int white_code = 255;  ///< the display's white, 2^bits − 1
    /// The pixel where the light adds the most displayed luminance (window
    /// coordinates, row 0 at the top); where it adds none, the pixel under its
    /// centre. What the screen shows there with the judged lights off (the
    /// same frame, the same dither) ...
    glm::ivec2 brightest_px{0};
    glm::ivec3 background_code{0};  ///< ... in codes, per channel (R, G, B)
    double background_cd_m2 = 0.0;  ///< ... in displayed luminance, cd/m²
    /// ... and how much one code step there adds: the displayed luminance
    /// (cd/m²) of raising by one code the channels the light raises at that
    /// pixel (all three where it raises none), over the lights-off codes.
    double code_step_cd_m2 = 0.0;
};

/// One rendered frame, as the observer sees it: a window per judged light.
struct FrameViews {
    double time_s = 0.0;               ///< the scene time it was rendered at (rhythms), s
    std::vector<LightWindow> windows;  ///< one per light asked for, in that order
};

class StimulusRenderer {
public:
    /// scene_template: the scene file, read and parsed once (a session renders
    /// the file as it was when it began). window_radius_deg: the radius (degrees of visual
    /// angle) around a light that the observer looks at; the windows kept are
    /// 2 × that (the yes-no annulus) plus a margin. interval_s: how long a frame
    /// is shown (a frame is rendered at the moment in it when its judged light
    /// is brightest). Needs a current GL 4.5 context.
    StimulusRenderer(stimuli::SceneTemplate scene_template, double window_radius_deg, double interval_s,
                     std::size_t cache_frames = 4096);

    /// The scene a frame's overrides give. Throws InputError (the scene's own
    /// errors, or an override's at its origin). Each distinct override list is
    /// applied to the template once (a small LRU of scenes): a trial asks for its scenes from
    /// views(), codes(), animated(), encode() and the backgrounds.
    std::shared_ptr<const stimuli::Scene> scene(const std::vector<SceneOverride>& overrides) const;

    /// The frame seen around `lights` (scene light names; "" = the screen's
    /// centre), from the cache or rendered.
    std::shared_ptr<const FrameViews> views(const protocols::Frame& frame, const std::vector<std::string>& lights);

    /// Renders the frame afresh (also filling the cache) and returns its
    /// scene-referred HDR image (cd/m²) and the degrees per pixel at its centre;
    /// `light_px`, when given, gets each light's centre in the image (pixels,
    /// row 0 at the top), in the order of `lights`.
    stimuli::ImageRGBA32F hdr(const protocols::Frame& frame, const std::vector<std::string>& lights,
                              double& degrees_per_pixel, std::vector<glm::dvec2>* light_px = nullptr);

    // --- On screen (SessionDisplay draws through these) ------------------
    /// The frame's code values for the screen: rendered at the moment of its
    /// interval when `lights` are brightest (as the observer's views), kept in a
    /// small LRU (a block's background is shown every trial).
    std::shared_ptr<const stimuli::EncodedImage> codes(const protocols::Frame& frame,
                                                       const std::vector<std::string>& lights);
    /// A light of the frame's scene has a rhythm: the frame changes within its interval.
    bool animated(const protocols::Frame& frame);
    /// Renders the frame at time_s (s after its onset) through the display
    /// pipeline, leaving its codes on the GPU for present(): an animated frame
    /// is sampled at each flip's predicted time.
    void encode(const protocols::Frame& frame, double time_s);
    /// Draws the codes encode() made into the bound framebuffer, lower-left corner at (x, y).
    void present(int x, int y) const;
    /// The names of the scene's lights (the template with the display).
    std::vector<std::string> light_names(const std::vector<SceneOverride>& overrides) const;
    /// The overrides that take every light and disc of the scene out (lights
    /// dark, discs of zero diameter): what surrounds the stimuli.
    std::vector<SceneOverride> all_off(const std::vector<SceneOverride>& overrides) const;

    /// Encode every frame for this display model instead of the scene's (the
    /// display's measured calibration: calibration_policy.h). Set before the first frame.
    void use_display_model(display::DisplayModel model) {
        display_model_ = std::move(model);
        scenes_ = LruCache<std::string, std::shared_ptr<const stimuli::Scene>>(scenes_.capacity());
    }

    /// The radius (degrees of visual angle) of the observer's window around a light.
    double window_radius_deg() const noexcept { return window_radius_deg_; }
    std::size_t frames_rendered() const noexcept { return rendered_; }
    std::size_t frames_requested() const noexcept { return requested_; }
    /// How many times the scene template was instantiated with a frame's overrides.
    std::size_t scenes_parsed() const noexcept { return parsed_; }
    /// Wall-clock seconds spent rendering and reading frames back.
    double render_seconds() const noexcept { return render_s_; }

private:
    std::shared_ptr<const FrameViews> render(const protocols::Frame& frame, const std::vector<std::string>& lights,
                                             stimuli::ImageRGBA32F* hdr, double* degrees_per_pixel);
    /// Renders a scene through the display pipeline: the code values the screen gets.
    stimuli::EncodedImage render_codes(const stimuli::Scene& scene, double time_s);
    /// render_codes without reading the codes back (they stay on the GPU).
    void encode_scene(const stimuli::Scene& scene, double time_s);
    /// The codes of `frame` with the named `lights` off, at time_s (a small LRU).
    const stimuli::EncodedImage& background_codes(const protocols::Frame& frame, const std::vector<std::string>& lights,
                                                  double time_s);

    stimuli::SceneTemplate template_;
    std::optional<display::DisplayModel> display_model_;  ///< use_display_model()
    double window_radius_deg_;
    double interval_s_;
    stimuli::Pipeline pipeline_;  ///< with the renderer's default options (no display skips)
    LruCache<std::string, std::shared_ptr<const FrameViews>> views_;  ///< views(): cache_frames entries
    LruCache<std::string, stimuli::EncodedImage> background_{8};      ///< background_codes()
    /// codes(): a trial's frames and its background, with room to spare.
    LruCache<std::string, std::shared_ptr<const stimuli::EncodedImage>> codes_{8};
    /// scene(): the scenes of the override lists asked for lately (a trial's
    /// frames, their lights-off backgrounds, the load-time checks' proposals).
    mutable LruCache<std::string, std::shared_ptr<const stimuli::Scene>> scenes_{64};
    mutable std::size_t parsed_ = 0;
    std::size_t rendered_ = 0;
    std::size_t requested_ = 0;
    double render_s_ = 0.0;
};

}  // namespace atonlab::runner
