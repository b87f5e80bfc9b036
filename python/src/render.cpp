// atonlab.Scene and atonlab.Frame (docs/python.md "Rendering"): a scene file
// loaded with typed overrides, rendered headless by the same core as `atonlab
// render` (atonlab/runner/render_frame.h), its HDR image returned as a numpy view
// of the frame's memory and its display codes as the display gets them.
#include <epoxy/egl.h>
#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/display/display_encodings.h"
#include "atonlab/runner/render_frame.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/pipeline.h"
#include "atonlab/stimuli/scene_file.h"
#include "bindings.h"

namespace atonlab::python {

namespace {

/// The module's context (bindings.h): made once, never destroyed (scenes
/// still alive when the interpreter exits hold GL objects of it).
gl::Context* g_context = nullptr;

/// What a scene was loaded from: a frame renders its lights' windows again from it (Frame.added_lux).
struct SceneSource {
    stimuli::SceneTemplate scene_template;
    std::vector<SceneOverride> overrides;
    stimuli::Scene scene;
};

struct PyFrame {
    py::array hdr;     ///< H×W×3 float32, cd/m², a view of `rgba`'s memory
    py::array rgba;    ///< H×W×4 float32, the frame's own buffer (A: scotopic cd/m²)
    py::object codes;  ///< H×W×3 uint8 (8-bit display) or uint16, or None
    int bits = 0;      ///< the display's code depth
    double deg_per_px = 0.0;
    double time_s = 0.0;
    double render_s = 0.0;  ///< wall-clock s inside the library (render, read back), for the overhead bench
    py::dict metadata;
    py::dict display;  ///< display_dict()
    std::shared_ptr<const SceneSource> source;
    py::object displayed;  ///< displayed_cd_m2, made on first use (None until then)
};

/// A loaded scene and, once rendered, its pipeline (GL objects of the module's context).
class PyScene {
public:
    PyScene(std::string path, std::shared_ptr<const SceneSource> source)
        : path_(std::move(path)), source_(std::move(source)), scene_(source_->scene) {}
    ~PyScene() {
        if (!pipeline_) return;
        // The pipeline's GL objects are deleted with the module's context
        // current. The GIL stays held: a rendering thread gives the GL back
        // before it takes the GIL again, so this wait ends.
        try {
            GlUse gl;
            pipeline_.reset();
        } catch (const std::exception&) {
            (void)pipeline_.release();  // no context: the objects die with the process
        }
    }
    PyScene(const PyScene&) = delete;
    PyScene& operator=(const PyScene&) = delete;

    const std::string& path() const { return path_; }
    const stimuli::Scene& scene() const { return scene_; }

    PyFrame render(double time_s) {
        if (!std::isfinite(time_s))
            throw InputError(SourceLocation::command_line("time_s"), "the time must be a finite number of seconds");
        const auto started = std::chrono::steady_clock::now();
        auto frame = std::make_unique<runner::RenderedFrame>();
        stimuli::EncodedImage codes;
        std::vector<std::uint8_t> codes8;
        double render_s = 0.0;
        {
            py::gil_scoped_release release;
            {
                GlUse gl;
                if (!pipeline_) pipeline_ = std::make_unique<stimuli::Pipeline>();
                *frame = runner::render_frame(*pipeline_, scene_, path_, time_s);
                codes = pipeline_->display().read_codes();
            }
            // An 8-bit display's codes as bytes (the library reads them back as
            // 16-bit values; `atonlab render --png` converts them likewise).
            if (codes.bits <= 8) codes8.assign(codes.rgb.begin(), codes.rgb.end());
            render_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
        }
        PyFrame out;
        out.render_s = render_s;
        out.deg_per_px = frame->meta.degrees_per_pixel;
        out.time_s = time_s;
        out.metadata = metadata_dict(frame->meta);
        out.bits = codes.bits;
        out.display = display_dict(scene_, codes.bits);
        out.source = source_;
        out.displayed = py::none();
        out.codes = codes.bits <= 8 ? owned_array(std::move(codes8), codes.height, codes.width)
                                    : owned_array(std::move(codes.rgb), codes.height, codes.width);
        out.hdr = rgb_view(std::move(frame->hdr));
        // The RGBA array over the same buffer (hdr's base owns it).
        const py::ssize_t h = out.hdr.shape(0), w = out.hdr.shape(1);
        out.rgba =
            py::array(py::dtype::of<float>(), {h, w, py::ssize_t{4}},
                      {w * 4 * py::ssize_t(sizeof(float)), 4 * py::ssize_t(sizeof(float)), py::ssize_t(sizeof(float))},
                      out.hdr.data(), out.hdr.base());
        return out;
    }

private:
    /// H×W×3 codes as a numpy array owning `values` (no copy).
    template <typename T>
    static py::object owned_array(std::vector<T>&& values, int height, int width) {
        auto* owned = new std::vector<T>(std::move(values));
        py::capsule base(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
        return py::array_t<T>({py::ssize_t{height}, py::ssize_t{width}, py::ssize_t{3}}, owned->data(), base);
    }

    std::string path_;
    std::shared_ptr<const SceneSource> source_;
    const stimuli::Scene& scene_;  ///< source_'s
    std::unique_ptr<stimuli::Pipeline> pipeline_;
};

std::unique_ptr<PyScene> load(const std::filesystem::path& file, const std::optional<py::dict>& overrides) {
    const std::string path = file.string();
    std::vector<SceneOverride> list;
    if (overrides)
        for (const auto& [k, v] : *overrides) {
            const std::string key = py::str(k);
            list.emplace_back(key, toml_value(v, key), SourceLocation::command_line("overrides", key));
        }
    std::shared_ptr<SceneSource> source;
    try {
        py::gil_scoped_release release;
        stimuli::SceneTemplate scene_template = stimuli::SceneTemplate::load(path);
        stimuli::Scene scene = scene_template.instantiate(list);
        stimuli::validate_output_settings(scene.output, scene.adaptation_cd_m2);
        source =
            std::make_shared<SceneSource>(SceneSource{std::move(scene_template), std::move(list), std::move(scene)});
    } catch (const InputError& e) {
        // An override's error names the `overrides` argument (its origin) and echoes the value given.
        const std::optional<SourceLocation> where = e.where();
        if (overrides && where && where->option == "overrides")
            for (const auto& [k, v] : *overrides) {
                const std::string key = py::str(k);
                if (where->key == key || where->key.starts_with(key + ".") || where->key.starts_with(key + "[")) {
                    std::string message = e.message();
                    if (message.ends_with('.')) message.pop_back();
                    throw InputError(*where,
                                     message + " (the value given: " + std::string(py::str(py::repr(v))) + ").");
                }
            }
        throw;
    }
    return std::make_unique<PyScene>(path, std::move(source));
}

}  // namespace

namespace {
thread_local int t_gl_depth = 0;  ///< GlUse objects alive on this thread
}  // namespace

GlUse::GlUse() {
    static std::recursive_mutex m;
    lock_ = std::unique_lock<std::recursive_mutex>(m);
    if (t_gl_depth == 0) {
        if (!g_context)
            g_context = gl::create_headless_context().release();  // made current by the factory
        else
            g_context->make_current();
    }
    ++t_gl_depth;
}

GlUse::~GlUse() {
    // The outermost use releases the context from this thread, so that the next may be on another.
    if (--t_gl_depth == 0 && g_context)
        eglMakeCurrent(eglGetCurrentDisplay(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

void bind_render(py::module_& m) {
    // The laws' names from the registry (display_encodings.h).
    static const std::string display_doc = fmt::format(
        "The display as numbers: name, peak_cd_m2, black_cd_m2, encoding (the channels' law: {}; a list of three "
        "where they differ; \"transfer\" is its deprecated old name), channel_white_cd_m2 and channel_black_cd_m2 (R, "
        "G, B), bits, primaries_xy (red, "
        "green, blue and white CIE 1931 xy: Rec.709 with D65), width_px, height_px, width_m, viewing_distance_m "
        "and focal_px (the viewing distance in pixel pitches).",
        display::display_encoding_choices("\"", true));
    py::class_<PyFrame>(m, "Frame", "One rendered frame: the scene-referred image and what the display is sent.")
        .def_readonly("hdr", &PyFrame::hdr,
                      "H×W×3 float32: linear Rec.709 (sRGB primaries, D65), absolute cd/m² (Y = 0.2126 R + 0.7152 G "
                      "+ 0.0722 B is the luminance); row 0 is the top. A view of the frame's own memory (no copy).")
        .def_readonly(
            "rgba", &PyFrame::rgba,
            "H×W×4 float32: the same memory as hdr with its alpha, the frame's scotopic luminance (scotopic cd/m²).")
        .def_readonly("codes", &PyFrame::codes,
                      "H×W×3 display codes as the display gets them (tone-mapped, encoded, dithered): uint8 for an "
                      "8-bit display, uint16 for a deeper one (bits says).")
        .def_readonly("bits", &PyFrame::bits, "The display's code depth (8, 10, ...).")
        .def_readonly("deg_per_px", &PyFrame::deg_per_px, "Degrees of visual angle per pixel at the image centre.")
        .def_readonly("time_s", &PyFrame::time_s, "The scene time (s) the frame was rendered at.")
        .def_readonly("render_s", &PyFrame::render_s,
                      "Wall-clock seconds spent in the library: the render, the read-back of the image and the codes "
                      "(an 8-bit display's as bytes), without the Python call around it.")
        .def_readonly(
            "metadata", &PyFrame::metadata,
            "What `atonlab render`'s EXR header carries: units, degreesPerPixel, adaptationLuminance (cd/m²), "
            "camera, scene, time_s, software, glare, tonemap, ...")
        .def_readonly("display", &PyFrame::display, display_doc.c_str())
        .def_property_readonly(
            "displayed_cd_m2",
            [](PyFrame& f) {
                if (f.displayed.is_none() && !f.codes.is_none())
                    f.displayed = displayed_cd_m2(f.codes.cast<py::array>(), f.source->scene.output.display, f.bits);
                return f.displayed;
            },
            "H×W×3 float32: what each pixel's red, green and blue emit (cd/m²), the codes decoded through the "
            "display model; their sum is the luminance the pixel shows (dither and clipping included). Row 0 is "
            "the top.")
        .def(
            "added_lux",
            [](const PyFrame& f, const std::string& light, double radius_deg) {
                return added_lux(f.source->scene_template, f.source->overrides, f.source->scene, light, radius_deg);
            },
            py::arg("light"), py::arg("radius_deg") = 0.5,
            "The light (lx) the scene light or disc `light` adds at the observer's eye within radius_deg of it: "
            "Σ (L − L_off) · Ω over the window's pixels, L the displayed luminance with the light and L_off "
            "without it (the same frame and dither), Ω each pixel's own solid angle; `atonlab check`'s number "
            "(its 'adds' column), rendered the same way at scene time 0. Negative where it takes light away.")
        .def("__repr__", [](const PyFrame& f) {
            return "<atonlab.Frame " + std::to_string(f.hdr.shape(1)) + "x" + std::to_string(f.hdr.shape(0)) + ", " +
                   std::to_string(f.deg_per_px) + " deg/px>";
        });

    py::class_<PyScene>(m, "Scene", "A scene file (docs/scene-file.md) with its overrides applied.")
        .def_static("load", &load, py::arg("path"), py::arg("overrides") = py::none(),
                    "Loads and checks a scene file. overrides: {\"eye.adaptation_cd_m2\": 0.03, "
                    "\"tonemap.operator\": \"perceptual\", \"camera.position_m\": [0, 3, 0], ...} with Python values "
                    "(bool, int, float, str, lists), as `--set` takes them. Raises InputError naming the file, line "
                    "and key (or the override's key).")
        .def_property_readonly("path", &PyScene::path, "The scene file.")
        .def_property_readonly(
            "width_px", [](const PyScene& s) { return s.scene().display.width_px; },
            "The display's width in pixels (the frame's width).")
        .def_property_readonly(
            "height_px", [](const PyScene& s) { return s.scene().display.height_px; },
            "The display's height in pixels.")
        .def_property_readonly(
            "adaptation_cd_m2", [](const PyScene& s) { return s.scene().adaptation_cd_m2; },
            "The scene's adaptation luminance (cd/m²).")
        .def("render", &PyScene::render, py::arg("time_s") = 0.0,
             "Renders one frame headless at scene time time_s (s; rhythms are sampled there), as `atonlab render` "
             "does (dynamic adaptation adopts the frame's log-average at once). The GIL is released while the GPU "
             "works. Raises NoContextError where no OpenGL 4.5 context can be made.")
        .def("__repr__", [](const PyScene& s) { return "<atonlab.Scene " + s.path() + ">"; });
}

}  // namespace atonlab::python
