// The display-profile file's schema (docs/store.md, "The display-profile
// file"): a lab's displays with their calibrations, the readings behind them
// and their checks, shared by every study. Its own file kind (application_id
// 'ATPF') with its own migrations, so that it can evolve apart from the study
// file. Its tables are the study file's tables of the same names, made from
// the same SQL (display_tables.h), so that one set of Store methods reads and
// writes both, and a session can copy a calibration from one into the other
// unchanged.
#include <array>

#include "atonlab/store/schema.h"
#include "display_tables.h"

namespace atonlab::store {
namespace {

// The study file's tables as its versions 1 to 3 left them, in one step.
constexpr auto profile_v1 =
    sql::join(sql::schema_history, sql::displays, sql::calibrations, sql::calibration_readings,
              sql::calibration_readings_transcript, sql::calibration_checks, sql::calibrations_append_only);

constexpr std::array<Migration, 1> migrations = {
    Migration{1, "displays, calibrations, calibration readings and checks", sql::text(profile_v1)},
};

}  // namespace

std::span<const Migration> profile_migrations() noexcept {
    return migrations;
}

int profile_schema_version() noexcept {
    return migrations.back().to_version;
}

}  // namespace atonlab::store
