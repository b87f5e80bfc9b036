#pragma once
// The area binning of a finer PSF grid onto a coarser one (psf.h bin_into):
// the shares of each fine texel in the coarse texels it overlaps, per axis.
// Shared by the CPU's bin_into (psf.cpp) and the GPU generator's gather
// (psf_generator.cpp, psf_anchored.comp).
#include <vector>

namespace atonlab::stimuli::detail {

/// The coarse texels (first index, share of the fine texel) that fine texel k
/// overlaps on one axis: its square [u − r/2, u + r/2] in coarse units, u its
/// centre, against coarse texel m's [m − 1/2, m + 1/2]; r = `ratio`, the fine
/// texel's width in coarse texels. Both grids are centred on texel n/2.
struct AxisShare {
    int first = 0;
    std::vector<double> share;
};
std::vector<AxisShare> axis_shares(int n_fine, int n_coarse, double ratio);

}  // namespace atonlab::stimuli::detail
