#pragma once
// A simulation's folder (docs/simulate.md "The folder"):
//
//   DIR/simulation.json                      the manifest: what was simulated
//   DIR/tables/KEY.json                      the decision tables (decision_table.h)
//   DIR/sessions/DD/session-NNNNNN.db        one study file per session (design DD)
//   DIR/sessions/DD/session-NNNNNN.db.partial  a session being written
//
// A folder holds one simulation: the manifest's identity (its designs'
// protocols and overrides, the seed, the observer, how decisions are made)
// must match a new run's, which then continues it.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace atonlab::runner {

struct ManifestDesign {
    std::string label;
    std::string protocol;         ///< the file, as given
    std::string protocol_sha256;  ///< of the design's protocol text (overrides applied)
    std::vector<std::string> overrides;
    std::string table;  ///< the decision table's key; empty when every trial is rendered
    friend bool operator==(const ManifestDesign&, const ManifestDesign&) = default;
};

struct SimulationManifest {
    std::vector<ManifestDesign> designs;
    std::uint64_t seed = 0;        ///< session i of every design has seed + i
    std::size_t sessions = 0;      ///< per design
    std::string observer_json;     ///< the observer's keys and values, JSON
    std::string decisions;         ///< "table" or "rendered"
    std::string software_version;  ///< of the run that wrote it

    std::string json() const;
    /// Throws std::runtime_error for text that is not a manifest.
    static SimulationManifest parse(const std::string& text);
    /// The first difference of identity (all but sessions and software), or "" when none.
    std::string identity_difference(const SimulationManifest& other) const;
};

std::filesystem::path manifest_path(const std::filesystem::path& dir);
std::filesystem::path tables_dir(const std::filesystem::path& dir);
/// DIR/sessions/DD/session-NNNNNN.db
std::filesystem::path session_file(const std::filesystem::path& dir, std::size_t design, std::size_t index);

/// The manifest in `dir`, none when the folder has none. Throws InputError
/// naming --out for a folder that holds other files but no manifest, or a
/// manifest that does not parse.
std::optional<SimulationManifest> read_manifest(const std::filesystem::path& dir);

/// Checks that `dir` can be written (an existing folder: a probe file is made
/// and removed; a new one: its nearest existing parent), writing nothing
/// else. Throws InputError naming --out.
void check_writable(const std::filesystem::path& dir);

}  // namespace atonlab::runner
