// StoreError and the names of its kinds.
#include "atonlab/store/error.h"

#include <utility>

#include "atonlab/common/input_text.h"
#include "atonlab/store/records.h"

namespace atonlab::store {

StoreError::StoreError(StoreErrc kind, std::filesystem::path file, const std::string& message, int sqlite_code)
    // One line of valid UTF-8 whatever a message quotes (a path, SQLite's
    // report, a value read from the file): docs/fuzzing.md, "Echoed values".
    : std::runtime_error(text::one_line(message)), kind_(kind), file_(std::move(file)), sqlite_code_(sqlite_code) {}

const char* to_string(StoreErrc kind) noexcept {
    switch (kind) {
        case StoreErrc::cannot_open:
            return "cannot_open";
        case StoreErrc::not_a_database:
            return "not_a_database";
        case StoreErrc::not_a_study:
            return "not_a_study";
        case StoreErrc::newer_schema:
            return "newer_schema";
        case StoreErrc::older_schema:
            return "older_schema";
        case StoreErrc::schema_altered:
            return "schema_altered";
        case StoreErrc::read_only:
            return "read_only";
        case StoreErrc::disk_full:
            return "disk_full";
        case StoreErrc::io_error:
            return "io_error";
        case StoreErrc::busy:
            return "busy";
        case StoreErrc::corrupt:
            return "corrupt";
        case StoreErrc::constraint:
            return "constraint";
        case StoreErrc::invalid_argument:
            return "invalid_argument";
        case StoreErrc::not_found:
            return "not_found";
        case StoreErrc::other:
            return "other";
    }
    return "other";
}

const char* to_string(SessionStatus status) noexcept {
    switch (status) {
        case SessionStatus::running:
            return "running";
        case SessionStatus::quit:
            return "quit";
        case SessionStatus::completed:
            return "completed";
        case SessionStatus::crashed:
            return "crashed";
    }
    return "running";
}

std::optional<SessionStatus> session_status_from_string(std::string_view text) noexcept {
    for (SessionStatus s :
         {SessionStatus::running, SessionStatus::quit, SessionStatus::completed, SessionStatus::crashed}) {
        if (text == to_string(s)) return s;
    }
    return std::nullopt;
}

}  // namespace atonlab::store
