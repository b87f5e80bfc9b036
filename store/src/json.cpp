// JsonReader: json_type() / json_extract() on a private in-memory SQLite
// connection (see json.h).
#include "atonlab/store/json.h"

#include <fmt/format.h>

#include "sqlite.h"

namespace atonlab::store {

struct JsonReader::Impl {
    std::string text;
    std::string what;
    sql::Connection db{":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_MEMORY};

    /// json_type and the value at `path`; type "" when the path is absent.
    template <class F>
    auto at(std::string_view path, F&& read) {
        sql::Use s(db.cached("SELECT json_type(?1, ?2), json_extract(?1, ?2)"));
        s->bind(1, text);
        s->bind(2, path);
        const std::string doing = fmt::format("read {} from {}", path, what);
        s->step(doing);
        const std::string type = s->is_null(0) ? std::string() : s->text(0);
        return read(type, *s);
    }
};

JsonReader::JsonReader(std::string text, std::string what) : impl_(std::make_unique<Impl>()) {
    impl_->text = std::move(text);
    impl_->what = std::move(what);
    sql::Use s(impl_->db.cached("SELECT json_valid(?1)"));
    s->bind(1, impl_->text);
    s->step("check JSON text");
    if (s->int64(0) != 1)
        throw StoreError(StoreErrc::invalid_argument, {}, fmt::format("{} is not valid JSON", impl_->what));
}

JsonReader::JsonReader(JsonReader&&) noexcept = default;
JsonReader& JsonReader::operator=(JsonReader&&) noexcept = default;
JsonReader::~JsonReader() = default;

const std::string& JsonReader::text() const noexcept {
    return impl_->text;
}

std::optional<double> JsonReader::number(std::string_view path) const {
    return impl_->at(path, [](const std::string& type, const sql::Statement& s) -> std::optional<double> {
        if (type != "integer" && type != "real") return std::nullopt;
        return s.real(1);
    });
}

std::optional<std::string> JsonReader::string(std::string_view path) const {
    return impl_->at(path, [](const std::string& type, const sql::Statement& s) -> std::optional<std::string> {
        if (type != "text") return std::nullopt;
        return s.text(1);
    });
}

std::optional<bool> JsonReader::boolean(std::string_view path) const {
    return impl_->at(path, [](const std::string& type, const sql::Statement&) -> std::optional<bool> {
        if (type == "true") return true;
        if (type == "false") return false;
        return std::nullopt;
    });
}

std::size_t JsonReader::array_length(std::string_view path) const {
    sql::Connection& c = impl_->db;
    sql::Use s(c.cached("SELECT json_type(?1, ?2), json_array_length(?1, ?2)"));
    s->bind(1, impl_->text);
    s->bind(2, path);
    s->step(fmt::format("read {} from {}", path, impl_->what));
    if (s->is_null(0) || s->text(0) != "array") return 0;
    return static_cast<std::size_t>(s->int64(1));
}

}  // namespace atonlab::store
