#include "gl_test_support.h"

#include <cstdlib>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/footprint.h"
#include "atonlab/stimuli/gl/objects.h"
#include "skip.h"

namespace atonlab::gl::detail {
// The tests' own shaders (tests/shaders/, embedded by tests/CMakeLists.txt).
extern const std::pair<std::string_view, std::string_view> test_shaders[];
extern const std::size_t test_shaders_count;
}  // namespace atonlab::gl::detail

namespace atonlab::test {
namespace {
std::unique_ptr<gl::Context> g_context;
std::string g_reason;
bool g_tried = false;
}  // namespace

gl::Context* gl_context() {
    if (!g_tried) {
        g_tried = true;
        gl::add_shader_table({gl::detail::test_shaders, gl::detail::test_shaders_count});
        try {
            gl::HeadlessOptions opt;
            opt.debug = std::getenv("ATONLAB_GL_DEBUG") != nullptr;
            g_context = gl::create_headless_context(opt);
        } catch (const gl::ContextUnavailable& e) {
            g_reason = e.what();
        }
    }
    return g_context.get();
}

const std::string& gl_unavailable_reason() {
    gl_context();
    return g_reason;
}

void GLTest::SetUp() {
    gl::Context* ctx = gl_context();
    if (!ctx) ATONLAB_SKIP_NO_GPU() << "no OpenGL 4.5 core context: " << g_reason;
    ctx->make_current();
}

glm::dvec3 image_illuminance_rgb_lux(const stimuli::ImageRGBA32F& img, double focal_px) {
    glm::dvec3 sum{0.0};
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const float* p = img.pixel(x, y);
            if (p[0] == 0.0f && p[1] == 0.0f && p[2] == 0.0f) continue;
            // Row y of the top-down image covers window rows [H-1-y, H-y].
            const double x0 = x - 0.5 * img.width, y0 = (img.height - 1 - y) - 0.5 * img.height;
            sum += glm::dvec3(p[0], p[1], p[2]) * stimuli::pixel_solid_angle_sr(x0, y0, focal_px);
        }
    return sum;
}

double image_illuminance_lux(const stimuli::ImageRGBA32F& img, double focal_px) {
    return display::luminance_of_linear_rgb(image_illuminance_rgb_lux(img, focal_px));
}

}  // namespace atonlab::test
