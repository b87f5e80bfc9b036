// The moving pupil's kernel cache (pupil_kernel_cache.h): grid kernels and the
// Lagrange cubic in the pupil diameter between them (issue 27 item 2).
#include "atonlab/stimuli/pupil_kernel_cache.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <system_error>

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
    ahead_.clear();  // a std::async future waits for its job here
    grid_.clear();
    builds_ = builds_ahead_ = 0;
    has_last_ = false;
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
    Ahead ahead;
    if (auto a = ahead_.find(k); a != ahead_.end()) {
        try {
            ahead = a->second.get();
        } catch (...) {
            // The work failed on the worker: the build below does it here and
            // reports its error on this thread, as it would have without it.
        }
        ahead_.erase(a);
    }
    GlareKernel kernel = build(static_cast<double>(k) * step_mm_, ahead.get());
    ++builds_;
    if (ahead) ++builds_ahead_;
    return grid_.emplace(k, std::move(kernel)).first->second;
}

void PupilKernelCache::start_ahead(double x, long k0, double previous_pupil_mm, const Planner& plan) {
    const double moved = x - previous_pupil_mm / step_mm_;  // in grid steps since the last call
    if (moved == 0) return;
    // Work that way for as many nodes beyond the stencil as the pupil moved
    // steps (at least one, at most kMaxAhead): k0 + 3, k0 + 4, … opening,
    // k0 − 2, k0 − 3, … closing. Work for nodes it has turned away from
    // (behind the stencil) is dropped once done: dropping a job still running
    // would wait for it here.
    const int dir = moved > 0 ? 1 : -1;
    const long first = moved > 0 ? k0 + 3 : k0 - 2;
    std::erase_if(ahead_, [&](const auto& a) {
        return (a.first - k0) * dir < (dir > 0 ? -1 : -2) &&
               a.second.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
    });
    const auto reach = static_cast<long>(std::clamp(std::ceil(std::abs(moved)), 1.0, static_cast<double>(kMaxAhead)));
    for (long j = 0; j < reach; ++j) {
        const long next = first + dir * j;
        if (grid_.count(next) || ahead_.count(next)) continue;
        GlareKernelAheadJob job = plan(static_cast<double>(next) * step_mm_);
        if (!job) return;  // the model has nothing to do ahead
        try {
            ahead_.emplace(next, std::async(std::launch::async, std::move(job)));
        } catch (const std::system_error&) {
            return;  // no thread to be had: those builds do all their work in their frames
        }
    }
}

GlareKernel PupilKernelCache::kernel_at(double pupil_mm, const Builder& build, const Planner& plan) {
    const double previous = last_pupil_mm_;
    const bool had_last = has_last_;
    last_pupil_mm_ = pupil_mm;
    has_last_ = true;
    const double x = pupil_mm / step_mm_;
    const double fl = std::floor(x);
    const auto k0 = static_cast<long>(fl);
    GlareKernel out;
    if (x == fl) {
        out = grid_kernel(k0, build);  // on the grid: that kernel exactly
    } else {
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
        out = combine_kernels(kernels, weights);
    }
    if (plan && had_last) start_ahead(x, k0, previous, plan);
    return out;
}

}  // namespace atonlab::stimuli
