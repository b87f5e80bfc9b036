#pragma once
namespace atonlab::store {
/// The atonlab version this library was built from (CMake's PROJECT_VERSION);
/// recorded in every session that does not name its own.
const char* software_version() noexcept;
}  // namespace atonlab::store
