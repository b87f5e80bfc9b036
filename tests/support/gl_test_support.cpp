#include "gl_test_support.h"

#include <cstdlib>

namespace atonlab::test {
namespace {
std::unique_ptr<gl::Context> g_context;
std::string g_reason;
bool g_tried = false;
}  // namespace

gl::Context* gl_context() {
    if (!g_tried) {
        g_tried = true;
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
    if (!ctx) GTEST_SKIP() << "no OpenGL 4.5 core context: " << g_reason;
    ctx->make_current();
}

}  // namespace atonlab::test
