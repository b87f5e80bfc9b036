// Glare on an HDR image (image_glare.h): the FFT convolution against direct
// sums over a hand-made kernel, and energy against what the kernel carries
// past the edge. Each model's own kernel: tests/unit/glare_models/.
#include <gtest/gtest.h>

#include <cmath>

#include "atonlab/stimuli/image_glare.h"

namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

ImageRGBA32F black(int w, int h) {
    ImageRGBA32F img;
    img.width = w;
    img.height = h;
    img.rgba.assign(static_cast<std::size_t>(w) * h * 4, 0.0f);
    return img;
}

// An asymmetric 5x5 kernel, channels different, each summing to 1.
GlareKernel lopsided_kernel() {
    GlareKernel k;
    k.size = 5;
    k.pixels_per_degree = 10;
    k.radius_px = 2;
    k.rgba.assign(25, glm::vec4(0.0f));
    double sum[3] = {0, 0, 0};
    for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i)
            for (int c = 0; c < 3; ++c) {
                const double v = 1.0 + i + 3 * j * (c + 1) + (i == 4 && j == 0 ? 20 : 0);
                k.rgba[static_cast<std::size_t>(j) * 5 + i][c] = static_cast<float>(v);
                sum[c] += v;
            }
    for (auto& t : k.rgba)
        for (int c = 0; c < 3; ++c) t[c] = static_cast<float>(t[c] / sum[c]);
    return k;
}

TEST(ImageGlare, APointBecomesTheKernelTheRightWayUp) {
    // Kernel texel (i, j) is the offset (i - 2, j - 2) with j upwards; image rows go down.
    const GlareKernel k = lopsided_kernel();
    ImageRGBA32F img = black(11, 9);
    const int x0 = 5, y0 = 4;
    for (int c = 0; c < 3; ++c) img.pixel(x0, y0)[c] = 1000.0f;
    const ImageGlareResult r = convolve_image_glare(img, k);
    for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i)
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(r.image.pixel(x0 + i - 2, y0 - (j - 2))[c], 1000.0 * k.at(i, j)[c], 1e-3)
                    << i << "," << j << " channel " << c;
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(r.edge_cut[c], 0.0, 1e-12);
        EXPECT_NEAR(r.output_sum[c] / r.input_sum[c], 1.0, 1e-7);  // the kernel is float: sums to 1 within ~1e-8
    }
}

TEST(ImageGlare, MatchesTheDirectSumOnARandomImage) {
    const GlareKernel k = lopsided_kernel();
    ImageRGBA32F img = black(13, 7);
    unsigned s = 12345;
    for (float& v : img.rgba) {
        s = s * 1664525u + 1013904223u;
        v = static_cast<float>((s >> 8) % 1000) * 0.5f;
    }
    const ImageGlareResult r = convolve_image_glare(img, k);
    for (int y = 0; y < 7; ++y)
        for (int x = 0; x < 13; ++x)
            for (int c = 0; c < 3; ++c) {
                double direct = 0;  // out(x, y) = Σ in(x - dx, y + dy) K(2 + dx, 2 + dy)
                for (int j = 0; j < 5; ++j)
                    for (int i = 0; i < 5; ++i) {
                        const int sx = x - (i - 2), sy = y + (j - 2);
                        if (sx < 0 || sy < 0 || sx >= 13 || sy >= 7) continue;
                        direct += img.pixel(sx, sy)[c] * static_cast<double>(k.at(i, j)[c]);
                    }
                EXPECT_NEAR(r.image.pixel(x, y)[c], direct, 1e-4 * (1 + direct)) << x << "," << y;
            }
    // Σ L·Ω: what stays in plus what the reported cut says left = what came in.
    for (int c = 0; c < 3; ++c) {
        double out = 0, in = 0;
        for (int y = 0; y < 7; ++y)
            for (int x = 0; x < 13; ++x) {
                out += r.image.pixel(x, y)[c];
                in += img.pixel(x, y)[c];
            }
        EXPECT_GT(r.edge_cut[c], 0.01);
        EXPECT_NEAR((out + r.edge_cut[c] * in) / in, 1.0, 1e-6);
    }
}

TEST(ImageGlare, APointOnTheLeftEdgeLosesTheKernelsLeftColumns) {
    // Independent of the FFT: the cut is the kernel's energy at offsets dx < 0.
    const GlareKernel k = lopsided_kernel();
    ImageRGBA32F img = black(9, 9);
    for (int c = 0; c < 3; ++c) img.pixel(0, 4)[c] = 1.0f;
    const ImageGlareResult r = convolve_image_glare(img, k);
    for (int c = 0; c < 3; ++c) {
        double left = 0;
        for (int j = 0; j < 5; ++j)
            for (int i = 0; i < 2; ++i) left += k.at(i, j)[c];
        EXPECT_NEAR(r.edge_cut[c], left, 1e-9);
    }
}

TEST(ImageGlare, RefusesApertureAndNone) {
    GlareSettings g;
    g.model = GlareModel::aperture;
    EXPECT_THROW(image_glare_kernel(g, 1.0, 0.02), atonlab::InputError);
    g.model = GlareModel::none;
    EXPECT_THROW(image_glare_kernel(g, 1.0, 0.02), atonlab::InputError);
    g.model = GlareModel::spencer;
    EXPECT_THROW(image_glare_kernel(g, 1.0, 0.0), atonlab::InputError);
}

}  // namespace
