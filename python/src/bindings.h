#pragma once
// What the binding's files share (docs/python.md): the one GL context of the
// process, numpy views of the libraries' images, EXR metadata as a dict.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <mutex>
#include <string>
#include <vector>

#include "atonlab/common/scene_override.h"
#include "atonlab/display/display_model.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/stimuli/scene_file.h"

namespace atonlab::python {

namespace py = pybind11;

/// The module's one headless GL 4.5 context, made on first use and kept for
/// the life of the process, current on the calling thread while a GlUse
/// lives: the use is serialised (the GIL is released while rendering, so two
/// Python threads could otherwise share it) and the context is released from
/// the thread afterwards, so any thread may render next. Nested uses on one
/// thread (a run's progress callback that renders) share the outer one. Throws
/// gl::ContextUnavailable (atonlab.NoContextError) where none can be made.
class GlUse {
public:
    GlUse();
    ~GlUse();
    GlUse(const GlUse&) = delete;
    GlUse& operator=(const GlUse&) = delete;

private:
    std::unique_lock<std::recursive_mutex> lock_;
};

/// image's R, G, B as an H×W×3 float32 array that borrows the image's memory
/// (strides skip A): the array owns the image through a capsule, no copy.
py::array rgb_view(stimuli::ImageRGBA32F&& image);
/// An H×W×3 or H×W×4 array (any real dtype; C order) as RGBA (A = 1 when absent).
/// `name` is the argument named in an InputError.
stimuli::ImageRGBA32F image_from_array(const py::array& array, const char* name);
/// The EXR header's attributes as a dict: "units", "degreesPerPixel",
/// "adaptationLuminance", "wavelength" (when present) and every string attribute.
py::dict metadata_dict(const stimuli::ExrMetadata& meta);

/// A Python value (bool, int, float, str, list, tuple, dict) as TOML value
/// text, for a scene override. `key` names it in an InputError.
std::string toml_value(const py::handle& value, const std::string& key);

/// A frame's display as numbers (Frame.display; displayed.cpp).
py::dict display_dict(const stimuli::Scene& scene, int bits);
/// H×W×3 codes (uint8 for bits <= 8, else uint16) decoded through the display
/// model: what each channel of each pixel emits, cd/m² (Frame.displayed_cd_m2).
py::array displayed_cd_m2(const py::array& codes, const display::DisplayModel& model, int bits);
/// The light (lx) `light` adds within radius_deg of it, as `atonlab check`
/// computes it (Frame.added_lux). Takes a GlUse. Throws InputError.
double added_lux(const stimuli::SceneTemplate& scene_template, const std::vector<SceneOverride>& overrides,
                 const stimuli::Scene& scene, const std::string& light, double radius_deg);

void bind_exceptions(py::module_& m);
void bind_render(py::module_& m);
void bind_images(py::module_& m);
void bind_study(py::module_& m);

}  // namespace atonlab::python
