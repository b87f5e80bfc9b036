#pragma once
// DIR/simulation.json, a simulation folder's manifest (docs/simulate.md "The
// folder"): what was simulated. One home for its format: `atonlab simulate`
// writes it and holds a new run to its identity; `atonlab analyze` reads it
// for the report. The folder's layout:
//
//   DIR/simulation.json                        the manifest
//   DIR/tables/KEY.json                        the decision tables
//   DIR/sessions/DD/session-NNNNNN.db          one study file per session (design DD)
//   DIR/sessions/DD/session-NNNNNN.db.partial  a session being written
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace atonlab::analysis {

/// One design of a simulation (a `--vary` value, or one protocol of several).
struct ManifestDesign {
    std::string label;                   ///< "max_trials=20"; "" or the protocol's file name for one design
    std::string protocol;                ///< the protocol file, as given to simulate
    std::string protocol_sha256;         ///< of the design's protocol text (overrides applied)
    std::vector<std::string> overrides;  ///< the overrides that make it, "key=value"
    std::string table;                   ///< the decision table's key; empty when every trial is rendered
    friend bool operator==(const ManifestDesign&, const ManifestDesign&) = default;
};

struct SimulationManifest {
    std::vector<ManifestDesign> designs;
    std::uint64_t seed = 0;        ///< session i of every design has seed + i
    std::size_t sessions = 0;      ///< per design
    std::string observer_json;     ///< the simulated observer's keys and values, JSON
    std::string decisions;         ///< "table" or "rendered"
    std::string software_version;  ///< of the run that wrote it

    /// The protocol as a report names it: the designs' files, each once, joined by ", ".
    std::string protocol() const;
    /// The designs' protocol SHA-256 when they share one text, else "(one per design)".
    std::string protocol_sha256() const;

    /// The manifest's text (format "atonlab-simulation", version 1).
    std::string json() const;
    /// Parses a manifest read from `file` (named in errors). Throws InputError
    /// naming the file and key for text that is not JSON, of another format or
    /// version, without a design, or with a field missing or of the wrong type.
    static SimulationManifest parse(const std::string& text, const std::string& file);
    /// The first difference of identity (all but sessions and software), or "" when none.
    std::string identity_difference(const SimulationManifest& other) const;
};

std::filesystem::path simulation_manifest_path(const std::filesystem::path& dir);
/// DIR/sessions/DD/session-NNNNNN.db
std::filesystem::path simulation_session_file(const std::filesystem::path& dir, std::size_t design,
                                              std::size_t index);

/// Reads DIR/simulation.json: throws as SimulationManifest::parse, and InputError for a missing file.
SimulationManifest read_simulation_manifest(const std::filesystem::path& dir);

/// True when `dir` is a folder holding simulation.json.
bool is_simulation_folder(const std::filesystem::path& dir);

}  // namespace atonlab::analysis
