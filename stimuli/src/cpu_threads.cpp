#include "atonlab/stimuli/cpu_threads.h"

#include <algorithm>
#include <atomic>

namespace atonlab::stimuli {

namespace {
std::atomic<int> limit{0};
}

void set_cpu_threads(int n) {
    limit = std::max(0, n);
}

int cpu_threads() {
    return limit;
}

}  // namespace atonlab::stimuli
