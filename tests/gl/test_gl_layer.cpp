// The GL layer: context, RAII objects, embedded shaders and their errors.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <numeric>
#include <vector>

#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/gl/objects.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using GLLayer = GLTest;

TEST_F(GLLayer, ContextIsOpenGL45Core) {
    const auto& info = gl_context()->info();
    EXPECT_FALSE(info.renderer.empty());
    EXPECT_NO_THROW(gl::require_gl45());
    std::printf("renderer: %s | %s | %s\n", info.renderer.c_str(), info.version.c_str(), info.platform.c_str());
}

TEST_F(GLLayer, ComputeShaderRoundTripsThroughStorageBuffers) {
    std::vector<float> in(1000);
    std::iota(in.begin(), in.end(), 0.0f);
    auto b_in = gl::Buffer::from(std::span<const float>(in));
    gl::Buffer b_out(in.size() * sizeof(float), nullptr, gl::BufferUsage::dynamic_read);
    auto prog = gl::Program::build({{gl::ShaderStage::compute, "test_fill.comp"}});
    prog.set("a", 2.0f);
    prog.set("b", 0.5f);
    prog.set("count", static_cast<unsigned>(in.size()));
    prog.use();
    b_in.bind_storage(0);
    b_out.bind_storage(1);
    glDispatchCompute(static_cast<unsigned>((in.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<float> out(in.size());
    b_out.download(0, out.size() * sizeof(float), out.data());
    for (std::size_t i = 0; i < in.size(); ++i) ASSERT_EQ(out[i], 2.0f * in[i] + 0.5f) << i;
}

TEST_F(GLLayer, CompileErrorNamesFileStageAndLine) {
    try {
        gl::Program::build({{gl::ShaderStage::fragment, "test_broken.frag"}});
        FAIL() << "a broken shader compiled";
    } catch (const gl::Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("test_broken.frag"), std::string::npos) << msg;
        EXPECT_NE(msg.find("fragment"), std::string::npos) << msg;
        EXPECT_NE(msg.find("undefined_symbol"), std::string::npos) << msg;
        // The error is on line 5 of the file; the driver log names it (source 0).
        EXPECT_NE(msg.find("0:5"), std::string::npos) << msg;
    }
}

TEST_F(GLLayer, UnknownShaderNameIsAnError) {
    EXPECT_THROW(gl::Program::build({{gl::ShaderStage::compute, "no_such_file.comp"}}), gl::Error);
}

TEST_F(GLLayer, ObjectsAreMoveOnlyAndEmptyNeedsNoContext) {
    static_assert(!std::is_copy_constructible_v<gl::Buffer>);
    static_assert(std::is_nothrow_move_constructible_v<gl::Buffer>);
    static_assert(std::is_nothrow_move_assignable_v<gl::Texture2D>);
    gl::Texture2D empty;
    EXPECT_FALSE(empty);
    gl::Texture2D t(4, 4, gl::PixelFormat::rgba32f);
    const auto id = t.id();
    gl::Texture2D moved = std::move(t);
    EXPECT_EQ(moved.id(), id);
    EXPECT_FALSE(t);  // NOLINT(bugprone-use-after-move): the moved-from state is the point
}

TEST_F(GLLayer, TextureUploadDownloadIsExactForFloat32) {
    gl::Texture2D t(3, 2, gl::PixelFormat::rgba32f);
    std::vector<float> data(3 * 2 * 4);
    for (std::size_t i = 0; i < data.size(); ++i) data[i] = 1e-30f * static_cast<float>(i) + 1e9f * static_cast<float>(i % 3);
    t.upload(data.data());
    EXPECT_EQ(t.download_floats(), data);
}

TEST_F(GLLayer, GpuTimerReturnsANonNegativeTime) {
    auto timer = gl::GpuTimer::create();
    timer.begin();
    timer.end();
    auto ms = timer.elapsed_ms(true);
    ASSERT_TRUE(ms.has_value());
    EXPECT_GE(*ms, 0.0);
}

}  // namespace
}  // namespace atonlab::test
