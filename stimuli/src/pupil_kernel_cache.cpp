// The moving pupil's kernel cache (pupil_kernel_cache.h): grid kernels and the
// Lagrange cubic in the pupil diameter between them (issue 27 item 2).
#include "atonlab/stimuli/pupil_kernel_cache.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace atonlab::stimuli {

GlareKernel combine_kernels(const std::vector<const GlareKernel*>& kernels, const std::vector<double>& weights) {
    if (kernels.empty() || kernels.size() != weights.size())
        throw std::invalid_argument("combine_kernels: one weight per kernel, at least one");
    GlareKernel out;
    for (const GlareKernel* k : kernels) out.size = std::max(out.size, k->size);
    out.pixels_per_degree = kernels.front()->pixels_per_degree;
    const auto m = static_cast<std::size_t>(out.size);
    std::vector<glm::dvec3> sum(m * m, glm::dvec3(0.0));
    for (std::size_t n = 0; n < kernels.size(); ++n) {
        const GlareKernel& k = *kernels[n];
        const double w = weights[n];
        out.radius_px += w * k.radius_px;
        out.window_cut += w * k.window_cut;
        const int offset = out.half() - k.half();  // centre on centre
        for (int j = 0; j < k.size; ++j)
            for (int i = 0; i < k.size; ++i) {
                const glm::vec4& v = k.at(i, j);
                sum[static_cast<std::size_t>(j + offset) * m + static_cast<std::size_t>(i + offset)] +=
                    w * glm::dvec3(v.r, v.g, v.b);
            }
    }
    out.rgba.resize(m * m);
    for (std::size_t t = 0; t < m * m; ++t) {
        const glm::dvec3 v = glm::max(sum[t], glm::dvec3(0.0));  // no negative light (the cubic's dips)
        out.rgba[t] = glm::vec4(glm::vec3(v), 0.0f);
    }
    return out;
}

double kernel_relative_l2(const GlareKernel& a, const GlareKernel& reference) {
    const int half = std::max(a.half(), reference.half());
    auto texel = [](const GlareKernel& k, int dx, int dy) {
        const int i = dx + k.half(), j = dy + k.half();
        if (i < 0 || j < 0 || i >= k.size || j >= k.size) return glm::dvec3(0.0);
        const glm::vec4& v = k.at(i, j);
        return glm::dvec3(v.r, v.g, v.b);
    };
    double num = 0, den = 0;
    for (int dy = -half; dy <= half; ++dy)
        for (int dx = -half; dx <= half; ++dx) {
            const glm::dvec3 b = texel(reference, dx, dy), d = texel(a, dx, dy) - b;
            num += glm::dot(d, d);
            den += glm::dot(b, b);
        }
    return den > 0 ? std::sqrt(num / den) : std::sqrt(num);
}

void PupilKernelCache::clear() {
    grid_.clear();
    builds_ = 0;
}

const GlareKernel& PupilKernelCache::grid_kernel(long k, const Builder& build) {
    auto it = grid_.find(k);
    if (it != grid_.end()) return it->second;
    if (grid_.size() >= kMaxGridKernels) {
        // Drop the grid kernel farthest from the pupil asked for.
        const double p = last_pupil_mm_ / step_mm_;
        auto far = std::max_element(grid_.begin(), grid_.end(), [&](const auto& a, const auto& b) {
            return std::abs(static_cast<double>(a.first) - p) < std::abs(static_cast<double>(b.first) - p);
        });
        grid_.erase(far);
    }
    GlareKernel kernel = build(static_cast<double>(k) * step_mm_);
    ++builds_;
    return grid_.emplace(k, std::move(kernel)).first->second;
}

GlareKernel PupilKernelCache::kernel_at(double pupil_mm, const Builder& build) {
    last_pupil_mm_ = pupil_mm;
    const double x = pupil_mm / step_mm_;
    const double fl = std::floor(x);
    const auto k0 = static_cast<long>(fl);
    if (x == fl) return grid_kernel(k0, build);  // on the grid: that kernel exactly
    // Lagrange cubic in p through k0 − 1 … k0 + 2 (x lies between the middle two).
    std::vector<long> nodes;
    std::vector<double> weights;
    for (long k = k0 - 1; k <= k0 + 2; ++k) {
        double w = 1;
        for (long j = k0 - 1; j <= k0 + 2; ++j)
            if (j != k) w *= (x - static_cast<double>(j)) / static_cast<double>(k - j);
        nodes.push_back(k);
        weights.push_back(w);
    }
    // Build first (building may evict), then take the pointers.
    for (long k : nodes) grid_kernel(k, build);
    std::vector<const GlareKernel*> kernels;
    for (long k : nodes) kernels.push_back(&grid_.at(k));
    return combine_kernels(kernels, weights);
}

}  // namespace atonlab::stimuli
