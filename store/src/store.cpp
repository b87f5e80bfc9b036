// Store: opening, moving, and the helpers every part of it shares.
#include "atonlab/store/store.h"

#include <fmt/format.h>

#include "atonlab/store/schema.h"
#include "open.h"
#include "store_impl.h"

namespace atonlab::store {

void Store::Impl::require_writable(std::string_view doing) const {
    if (read_only) {
        throw StoreError(StoreErrc::read_only, path(),
                         fmt::format("{}: cannot {}: the {} was opened read-only", path().string(), doing, noun));
    }
}

void Store::Impl::invalid(std::string_view doing, std::string_view why) const {
    throw StoreError(StoreErrc::invalid_argument, path(),
                     fmt::format("{}: cannot {}: {}", path().string(), doing, why));
}

void Store::Impl::not_found(std::string_view doing, std::string_view what) const {
    throw StoreError(StoreErrc::not_found, path(),
                     fmt::format("{}: cannot {}: {} is not in the file", path().string(), doing, what));
}

bool json_valid(sql::Connection& db, std::string_view text, std::string_view doing) {
    sql::Use s(db.cached("SELECT json_valid(?1)"));
    s->bind(1, text);
    s->step(doing);
    return s->int64(0) == 1;
}

Store::Store(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Store::Store(Store&&) noexcept = default;
Store& Store::operator=(Store&&) noexcept = default;
Store::~Store() = default;

namespace {
std::unique_ptr<Store::Impl> make_impl(const std::filesystem::path& path, detail::Access access,
                                       const StoreOptions& options) {
    auto impl = std::make_unique<Store::Impl>();
    impl->db = detail::open_study(path, access, options, schema_migrations());
    impl->read_only = access == detail::Access::read_only;
    return impl;
}
}  // namespace

Store Store::create_or_open(const std::filesystem::path& path, const StoreOptions& options) {
    return Store(make_impl(path, detail::Access::create_or_open, options));
}

Store Store::open_existing(const std::filesystem::path& path, const StoreOptions& options) {
    return Store(make_impl(path, detail::Access::open_existing, options));
}

Store Store::open_read_only(const std::filesystem::path& path, const StoreOptions& options) {
    return Store(make_impl(path, detail::Access::read_only, options));
}

const std::filesystem::path& Store::path() const noexcept {
    return impl_->path();
}

bool Store::read_only() const noexcept {
    return impl_->read_only;
}

std::string Store::integrity_check() const {
    return impl_->db->query_text("PRAGMA integrity_check", "check the file's integrity");
}

int Store::file_schema_version() const {
    return static_cast<int>(impl_->db->query_int("PRAGMA user_version", "read the schema version"));
}

}  // namespace atonlab::store
