#pragma once
// The anchored spectral path's recipe (spectral_path.h): for every spectral
// sample, the anchors it is made from, each with its Lagrange weight in 1/λ,
// the gain (λk/λ)² and the Lanczos-3 taps of K2012 eq 4.9's rescaling. One
// recipe for both placements: the CPU's banded fp32 sum (spectral_path.cpp)
// and the GPU generator's compute shader (psf_generator.cpp, psf_anchored.comp).
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "atonlab/stimuli/psf.h"

namespace atonlab::stimuli::detail {

/// Taps per output texel and axis (Lanczos-3: a windowed sinc of 3 lobes).
constexpr int kLanczosTaps = 6;

/// Lanczos-3 weights of one axis: for output index i, the source coordinate
/// c + (i − c)·ratio (c = n/2), its first tap and the kLanczosTaps weights
/// (normalised to sum 1, so a constant stays constant).
struct LanczosTaps {
    std::vector<int> first;
    std::vector<double> weight;  // kLanczosTaps per output index
};
LanczosTaps lanczos_taps(int n, double ratio);

/// One term of a sample: an anchor's PSF rescaled by `ratio` (eq 4.9's lookup
/// F_λk(x·λk/λ)) times `scale` (the Lagrange weight and the gain (λk/λ)²).
/// ratio == 1 (the sample is the anchor): no taps, the anchor as it is.
struct SpectralTerm {
    std::size_t anchor = 0;
    double ratio = 1.0;
    float scale = 0.0f;
    LanczosTaps taps;  // both axes alike; empty when ratio == 1
};
struct SpectralSample {
    glm::vec3 xyz{0.0f};  // the sample's CMF × SPD weight
    std::vector<SpectralTerm> terms;
};

/// The recipe for these samples from anchors at `anchor_nm` (ascending) on an
/// n × n grid: samples in the order of `samples`, terms with zero weight left out.
std::vector<SpectralSample> spectral_recipe(const std::vector<double>& anchor_nm, const SpectralSamples& samples,
                                            int n);

}  // namespace atonlab::stimuli::detail
