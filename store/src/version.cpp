// The atonlab version this library was built from; see version.h.
#include "atonlab/store/version.h"

#ifndef ATONLAB_VERSION
#error "store/CMakeLists.txt defines ATONLAB_VERSION from PROJECT_VERSION"
#endif

namespace atonlab::store {
const char* software_version() noexcept {
    return ATONLAB_VERSION;
}
}  // namespace atonlab::store
