// 10-bit output (docs/display-calibration.md, "10-bit output"): under an Xvfb
// screen of depth 30 (tests/gl/run_under_xvfb.sh --screen 1024x64x30
// --framebuffer-file), a full-screen window gets a 10-bit framebuffer; the
// GPU display encoder's 10-bit codes for an sRGB and a PQ (1000 cd/m²) grey
// ramp are drawn into it, and the codes read back from
// the back buffer (glReadPixels) and from the X server's screen after the swap
// (Xvfb's -fbdir file) equal the encoder's, every pixel. Skips, saying why,
// when there is no display, the screen is not 10-bit or GL offers no 10-bit
// framebuffer.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/gl/window.h"
#include "../support/skip.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

struct Screen10 {
    int width = 0, height = 0;
    std::vector<std::uint16_t> rgb;  ///< row 0 at the top
    std::string why_not;             ///< empty when read
};

/// The X server's screen from Xvfb's -fbdir file (XWD, ZPixmap, 32 bits a pixel,
/// 10 bits a channel at depth 30).
Screen10 read_screen(const char* path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    const std::string d = ss.str();
    Screen10 s;
    auto be32 = [&](std::size_t i) {
        const auto* b = reinterpret_cast<const unsigned char*>(d.data()) + 4 * i;
        return (std::uint32_t{b[0]} << 24) | (std::uint32_t{b[1]} << 16) | (std::uint32_t{b[2]} << 8) | b[3];
    };
    if (d.size() < 100) {
        s.why_not = "the screen file is too short";
        return s;
    }
    const std::uint32_t header = be32(0), depth = be32(3), bpp = be32(11), bpl = be32(12), ncolors = be32(19);
    const std::uint32_t order = be32(7), masks[3] = {be32(14), be32(15), be32(16)};
    s.width = static_cast<int>(be32(4));
    s.height = static_cast<int>(be32(5));
    if (depth != 30 || bpp != 32) {
        s.why_not = "the screen file is not depth 30, 32 bits a pixel";
        return s;
    }
    const std::size_t off = header + 12 * ncolors;
    if (d.size() < off + static_cast<std::size_t>(bpl) * static_cast<std::size_t>(s.height)) {
        s.why_not = "the screen file is cut short";
        return s;
    }
    for (int y = 0; y < s.height; ++y)
        for (int x = 0; x < s.width; ++x) {
            const auto* b = reinterpret_cast<const unsigned char*>(d.data()) + off + static_cast<std::size_t>(y) * bpl +
                            4 * static_cast<std::size_t>(x);
            const std::uint32_t v =
                order == 0
                    ? (std::uint32_t{b[3]} << 24) | (std::uint32_t{b[2]} << 16) | (std::uint32_t{b[1]} << 8) | b[0]
                    : (std::uint32_t{b[0]} << 24) | (std::uint32_t{b[1]} << 16) | (std::uint32_t{b[2]} << 8) | b[3];
            for (std::uint32_t mask : masks) {
                int shift = 0;
                while (mask && !(mask & 1u)) {
                    mask >>= 1;
                    ++shift;
                }
                s.rgb.push_back(static_cast<std::uint16_t>((v >> shift) & mask));
            }
        }
    return s;
}

class Window10 : public ::testing::Test {
protected:
    void SetUp() override {
        if (!std::getenv("DISPLAY")) ATONLAB_SKIP_NO_GPU() << "no display server (DISPLAY unset); CTest runs this under Xvfb";
        gl::WindowOptions opt;
        opt.fullscreen = true;
        opt.monitor = 0;
        window_ = gl::create_window_context(opt);
        GLint bits[3] = {};
        const GLenum names[3] = {GL_FRAMEBUFFER_ATTACHMENT_RED_SIZE, GL_FRAMEBUFFER_ATTACHMENT_GREEN_SIZE,
                                 GL_FRAMEBUFFER_ATTACHMENT_BLUE_SIZE};
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        for (int i = 0; i < 3; ++i)
            glGetFramebufferAttachmentParameteriv(GL_FRAMEBUFFER, GL_BACK_LEFT, names[i], &bits[i]);
        if (bits[0] != 10 || bits[1] != 10 || bits[2] != 10)
            ATONLAB_SKIP_NO_GPU() << "the window's framebuffer has " << bits[0] << "/" << bits[1] << "/" << bits[2]
                         << " bits, not 10: the X server (depth of its screen) or the GL driver ("
                         << window_->info().renderer << ") offers no 10-bit visual";
        width_ = window_->framebuffer_width();
        height_ = window_->framebuffer_height();
    }

    /// A grey ramp, relative 0 at the left to 1 at the right, encoded for `display`
    /// at 10 bits without dither, shown; the encoder's codes against the framebuffer's
    /// and the screen's.
    void check_ramp(const DisplayModel& display, std::size_t min_distinct) {
        std::vector<float> ldr(static_cast<std::size_t>(width_) * height_ * 4, 1.0f);
        for (int y = 0; y < height_; ++y)
            for (int x = 0; x < width_; ++x)
                for (int c = 0; c < 3; ++c)
                    ldr[(static_cast<std::size_t>(y) * width_ + x) * 4 + c] =
                        static_cast<float>(x) / static_cast<float>(width_ - 1);
        gl::Texture2D scene(width_, height_, gl::PixelFormat::rgba32f);
        scene.upload(ldr.data());
        std::vector<float> none(ldr.size(), 0.0f);
        gl::Texture2D glare(width_, height_, gl::PixelFormat::rgba32f);
        glare.upload(none.data());
        OutputSettings s;
        s.display = display;
        s.encode.bits = 10;
        s.encode.dither = Dither::none;
        DisplayPipeline pipeline;
        pipeline.process_ldr(scene, glare, s, 0.001, 0);  // the eye's level tone-maps the glare: none here
        const EncodedImage codes = pipeline.read_codes();
        ASSERT_EQ(codes.bits, 10);
        ASSERT_EQ(codes.width, width_);
        ASSERT_EQ(codes.height, height_);
        // 10-bit, not 8 bits scaled: most codes are not multiples of 4, and hundreds are distinct
        // (more than 256 could not come from 8 bits).
        std::set<int> distinct;
        int off_grid = 0;
        for (std::size_t i = 0; i < codes.rgb.size(); i += 3) {
            distinct.insert(codes.rgb[i]);
            off_grid += codes.rgb[i] % 4 != 0;
        }
        EXPECT_GT(distinct.size(), min_distinct);
        EXPECT_GT(off_grid, static_cast<int>(codes.rgb.size() / 3 / 2));

        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, width_, height_);
        pipeline.present(0, 0);
        gl::finish();
        std::vector<std::uint32_t> back(static_cast<std::size_t>(width_) * height_);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadBuffer(GL_BACK);
        glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_INT_2_10_10_10_REV, back.data());
        std::size_t differing = 0;
        for (int y = 0; y < height_; ++y)  // glReadPixels' row 0 is the bottom; the codes' the top
            for (int x = 0; x < width_; ++x) {
                const std::uint32_t v = back[static_cast<std::size_t>(y) * width_ + x];
                const std::size_t at = (static_cast<std::size_t>(height_ - 1 - y) * width_ + x) * 3;
                for (int c = 0; c < 3; ++c) differing += ((v >> (10 * c)) & 1023u) != codes.rgb[at + c];
            }
        EXPECT_EQ(differing, 0u) << "framebuffer codes differing from the encoder's";

        window_->swap_buffers();
        gl::finish();
        const char* file = std::getenv("ATONLAB_XVFB_SCREEN_FILE");
        if (!file) {
            ADD_FAILURE() << "ATONLAB_XVFB_SCREEN_FILE unset: run under tests/gl/run_under_xvfb.sh --framebuffer-file";
            return;
        }
        // The X server copies the swapped frame into its screen asynchronously.
        Screen10 screen;
        std::size_t on_screen = 1;
        // Up to 30 s (1500 × 20 ms; it is there within tens of ms on an idle
        // machine): a loaded machine's X server may take long to get to it.
        for (int attempt = 0; attempt < 1500 && on_screen != 0; ++attempt) {
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            window_->poll_events();
            screen = read_screen(file);
            ASSERT_TRUE(screen.why_not.empty()) << screen.why_not;
            ASSERT_EQ(screen.width, width_);
            ASSERT_EQ(screen.height, height_);
            on_screen = 0;
            for (std::size_t i = 0; i < codes.rgb.size(); ++i) on_screen += screen.rgb[i] != codes.rgb[i];
        }
        EXPECT_EQ(on_screen, 0u) << "codes on the X server's screen differing from the encoder's";
    }

    std::unique_ptr<gl::WindowContext> window_;
    int width_ = 0, height_ = 0;
};

TEST_F(Window10, SrgbRampCodesReachTheScreenExactly) {
    check_ramp(DisplayModel::srgb(100.0, 0.1), 700u);
}

TEST_F(Window10, PqRampCodesReachTheScreenExactly) {
    // A linear ramp to 1000 cd/m² spans PQ codes 0..769, compressed at the top: fewer distinct codes.
    check_ramp(DisplayModel::pq(1000.0, 0.0), 300u);
}

}  // namespace
}  // namespace atonlab::test
