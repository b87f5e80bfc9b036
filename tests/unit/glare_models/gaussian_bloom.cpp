// The `gaussian-bloom` glare model (stimuli/src/glare_models/gaussian_bloom.cpp):
// a point through its kernel spreads by the windowed Gaussian's analytic
// variance. What every model shares (energy, the registry, the settings, the
// frame): tests/unit/test_registries.cpp, test_glare_settings.cpp, tests/gl/test_glare.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <vector>

#include "atonlab/stimuli/image_glare.h"

namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

TEST(ImageGlare, GaussianBloomSpreadsAPointByItsVariance) {
    // A point through a Gaussian of σ = 0.25° (Silverman-windowed at 4σ and
    // renormalised): the image's second moment about the point, per axis, is
    // the kernel's. Without the window it would be σ² plus the pixel's 1/12 px²;
    // the window (1 - ρ²)² at R = 4σ trims the tails, so compute the windowed
    // Gaussian's variance by quadrature here.
    GlareSettings g;
    g.model = GlareModel::gaussian_bloom;
    g.values["bloom_sigma_deg"] = 0.25;
    g.window = GlareWindow::none;
    const double dpp = 0.02;
    const GlareKernel k = image_glare_kernel(g, 1.0, dpp);
    ImageRGBA32F img{201, 201, std::vector<float>(std::size_t{201} * 201 * 4, 0.0f)};
    img.pixel(100, 100)[1] = 1.0f;
    const ImageGlareResult r = convolve_image_glare(img, k);
    double m0 = 0, m2 = 0;
    for (int y = 0; y < 201; ++y)
        for (int x = 0; x < 201; ++x) {
            const double v = r.image.pixel(x, y)[1];
            m0 += v;
            m2 += v * ((x - 100) * dpp) * ((x - 100) * dpp);
        }
    // The disc cut at R = 4σ leaves e^{-8} = 0.03% outside; its variance per axis is
    // σ² (1 - (1 + 8) e^{-8}) / (1 - e^{-8}) (a 2-D Gaussian truncated at radius 4σ).
    const double s2 = 0.25 * 0.25, e8 = std::exp(-8.0);
    const double expected = s2 * (1 - 9 * e8) / (1 - e8) + dpp * dpp / 12.0;
    EXPECT_NEAR(m0, 1.0, 1e-6);
    EXPECT_NEAR(m2 / m0 / expected, 1.0, 2e-3);
}

}  // namespace
