// Opening a display-profile file (profiles.h).
#include "atonlab/store/profiles.h"

#include "atonlab/store/schema.h"
#include "open.h"
#include "store_impl.h"

namespace atonlab::store {
namespace {

std::unique_ptr<Store::Impl> make_profiles_impl(const std::filesystem::path& path, detail::Access access,
                                                const StoreOptions& options) {
    auto impl = std::make_unique<Store::Impl>();
    impl->db = detail::open_file(path, access, options, profile_migrations(), detail::FileKind::profiles);
    impl->read_only = access == detail::Access::read_only;
    impl->noun = "display-profile file";
    return impl;
}

}  // namespace

Profiles Profiles::create_or_open(const std::filesystem::path& path, const StoreOptions& options) {
    return Profiles(Store(make_profiles_impl(path, detail::Access::create_or_open, options)));
}

Profiles Profiles::open_existing(const std::filesystem::path& path, const StoreOptions& options) {
    return Profiles(Store(make_profiles_impl(path, detail::Access::open_existing, options)));
}

Profiles Profiles::open_read_only(const std::filesystem::path& path, const StoreOptions& options) {
    return Profiles(Store(make_profiles_impl(path, detail::Access::read_only, options)));
}

}  // namespace atonlab::store
