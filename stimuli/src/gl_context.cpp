// Headless EGL context (surfaceless or device platform) and the GL 4.5 check.
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "atonlab/stimuli/gl/context.h"

namespace atonlab::gl {
namespace {

std::string gl_string(GLenum e) {
    const auto* s = reinterpret_cast<const char*>(glGetString(e));
    return s ? s : "";
}

void GLAPIENTRY debug_callback(GLenum, GLenum type, GLuint, GLenum severity, GLsizei, const GLchar* message,
                               const void*) {
    if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) return;
    std::fprintf(stderr, "atonlab: GL %s: %s\n", type == GL_DEBUG_TYPE_ERROR ? "error" : "message", message);
}

bool has_extension(const char* list, const char* name) {
    if (!list) return false;
    const std::size_t n = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}

std::string egl_error_name(EGLint e) {
    switch (e) {
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    default: return fmt::format("EGL error 0x{:04x}", e);
    }
}

class EglContext final : public Context {
public:
    EglContext(EGLDisplay display, EGLContext context, std::string platform)
        : display_(display), context_(context) {
        info_.platform = std::move(platform);
    }
    ~EglContext() override {
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display_, context_);
        eglTerminate(display_);
    }
    void make_current() override {
        if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
            throw Error("eglMakeCurrent failed: " + egl_error_name(eglGetError()));
    }
    void fill_info() {
        info_.vendor = gl_string(GL_VENDOR);
        info_.renderer = gl_string(GL_RENDERER);
        info_.version = gl_string(GL_VERSION);
        info_.glsl_version = gl_string(GL_SHADING_LANGUAGE_VERSION);
        info_.software = info_.renderer.find("llvmpipe") != std::string::npos ||
                         info_.renderer.find("softpipe") != std::string::npos ||
                         info_.renderer.find("swrast") != std::string::npos;
    }

private:
    EGLDisplay display_;
    EGLContext context_;
};

struct Candidate {
    EGLDisplay display;
    std::string platform;
    bool software;
};

// Lists EGL displays to try, hardware devices first unless told otherwise.
std::vector<Candidate> candidate_displays(const HeadlessOptions& opt, std::string& why) {
    std::vector<Candidate> out;
    const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client_ext) {
        why = "no EGL client extensions are available (is libEGL installed?)";
    }
    const char* env = std::getenv("ATONLAB_EGL_DEVICE");
    const std::string choice = env ? env : "";
    if (has_extension(client_ext, "EGL_EXT_device_enumeration") && has_extension(client_ext, "EGL_EXT_platform_device")) {
        EGLint n = 0;
        eglQueryDevicesEXT(0, nullptr, &n);
        std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(n));
        if (n > 0) eglQueryDevicesEXT(n, devices.data(), &n);
        std::vector<Candidate> hw, sw;
        for (EGLint i = 0; i < n; ++i) {
            const char* dev_ext = eglQueryDeviceStringEXT(devices[static_cast<std::size_t>(i)], EGL_EXTENSIONS);
            const bool software = has_extension(dev_ext, "EGL_MESA_device_software");
            if (!choice.empty() && std::isdigit(static_cast<unsigned char>(choice[0])) && std::atoi(choice.c_str()) != i)
                continue;
            EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[static_cast<std::size_t>(i)], nullptr);
            if (d == EGL_NO_DISPLAY) continue;
            (software ? sw : hw).push_back({d, fmt::format("egl-device {}", i), software});
        }
        const bool want_sw = choice == "software" || !opt.prefer_hardware;
        auto& first = want_sw ? sw : hw;
        auto& second = want_sw ? hw : sw;
        if (choice != "hardware" || !hw.empty()) {
            out.insert(out.end(), first.begin(), first.end());
            out.insert(out.end(), second.begin(), second.end());
        } else {
            out.insert(out.end(), hw.begin(), hw.end());
        }
    }
    if (has_extension(client_ext, "EGL_MESA_platform_surfaceless")) {
        EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (d != EGL_NO_DISPLAY) out.push_back({d, "egl-surfaceless", true});
    }
    EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (d != EGL_NO_DISPLAY) out.push_back({d, "egl-default", false});
    return out;
}

}  // namespace

void require_gl45() {
    GLint major = 0, minor = 0, profile = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    if (major * 10 + minor < 45)
        throw ContextUnavailable(fmt::format("OpenGL 4.5 core is needed but the driver ('{}') offers only {}.{}",
                                             gl_string(GL_RENDERER), major, minor));
    if (!(profile & GL_CONTEXT_CORE_PROFILE_BIT))
        throw ContextUnavailable("OpenGL 4.5 is available only as a compatibility profile, and atonlab needs core");
}

std::unique_ptr<Context> create_headless_context(const HeadlessOptions& options) {
    std::string why;
    const auto candidates = candidate_displays(options, why);
    if (candidates.empty())
        throw ContextUnavailable(why.empty() ? "no EGL display is available on this machine" : why);
    std::string last_error;
    for (const Candidate& c : candidates) {
        EGLint major = 0, minor = 0;
        if (!eglInitialize(c.display, &major, &minor)) {
            last_error = fmt::format("{}: eglInitialize failed ({})", c.platform, egl_error_name(eglGetError()));
            continue;
        }
        const char* dpy_ext = eglQueryString(c.display, EGL_EXTENSIONS);
        if (!has_extension(dpy_ext, "EGL_KHR_surfaceless_context") || !eglBindAPI(EGL_OPENGL_API)) {
            last_error = fmt::format("{}: no surfaceless desktop-OpenGL support", c.platform);
            eglTerminate(c.display);
            continue;
        }
        const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLConfig config = nullptr;
        EGLint n_configs = 0;
        const bool have_config = eglChooseConfig(c.display, config_attribs, &config, 1, &n_configs) && n_configs > 0;
        const EGLint ctx_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4,
                                      EGL_CONTEXT_MINOR_VERSION, 5,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_CONTEXT_OPENGL_DEBUG, options.debug ? EGL_TRUE : EGL_FALSE,
                                      EGL_NONE};
        // EGL_KHR_no_config_context lets us create without a config when none is offered.
        EGLContext ctx = eglCreateContext(c.display, have_config ? config : EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, ctx_attribs);
        if (ctx == EGL_NO_CONTEXT) {
            last_error = fmt::format("{}: no OpenGL 4.5 core context ({})", c.platform, egl_error_name(eglGetError()));
            eglTerminate(c.display);
            continue;
        }
        auto context = std::make_unique<EglContext>(c.display, ctx, c.platform);
        context->make_current();
        context->fill_info();
        require_gl45();
        if (options.debug) {
            glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
            glDebugMessageCallback(debug_callback, nullptr);
        }
        return context;
    }
    throw ContextUnavailable(fmt::format("no headless OpenGL 4.5 core context could be made: {}", last_error));
}

}  // namespace atonlab::gl
