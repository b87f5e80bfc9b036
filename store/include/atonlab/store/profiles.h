#pragma once
// Profiles: a lab's display-profile file (docs/store.md, "The display-profile
// file"): every display's calibrations, the readings behind them and their
// checks, in one SQLite file shared by all studies. `atonlab calibrate` writes
// it; `atonlab run` reads the protocol's display from it and copies the
// calibration (with its readings and latest check) into the study file, so a
// study stays self-contained.
//
// The file has its own application_id and migrations (schema.h's
// profile_migrations()); a study file is refused where a profile file is
// expected and the other way round. Its display tables are the study file's,
// column for column, so the same Store methods read and write them: display()
// is that Store.
#include <filesystem>

#include "atonlab/store/store.h"

namespace atonlab::store {

class Profiles {
public:
    /// As Store's factories of the same names, for a display-profile file.
    static Profiles create_or_open(const std::filesystem::path& path, const StoreOptions& options = {});
    static Profiles open_existing(const std::filesystem::path& path, const StoreOptions& options = {});
    static Profiles open_read_only(const std::filesystem::path& path, const StoreOptions& options = {});

    const std::filesystem::path& path() const noexcept { return store_.path(); }

    /// The file's displays, calibrations, readings and checks, through Store's
    /// "Displays" methods (put_calibration ... display_names) and
    /// file_schema_version(). Only those: the file has no sessions or trials.
    Store& displays() noexcept { return store_; }
    const Store& displays() const noexcept { return store_; }

private:
    explicit Profiles(Store store) : store_(std::move(store)) {}
    Store store_;
};

}  // namespace atonlab::store
