#pragma once
// A simulation's folder (docs/simulate.md "The folder"; its layout and the
// manifest's format: atonlab/analysis/simulation_manifest.h).
//
// A folder holds one simulation: the manifest's identity (its designs'
// protocols and overrides, the seed, the observer, how decisions are made)
// must match a new run's, which then continues it.
#include <filesystem>
#include <optional>

#include "atonlab/analysis/simulation_manifest.h"

namespace atonlab::runner {

/// DIR/tables, the decision tables' folder (decision_table.h).
std::filesystem::path tables_dir(const std::filesystem::path& dir);

/// The manifest in `dir`, none when the folder has none. Throws InputError
/// naming --out for a folder that holds other files but no manifest, or a
/// manifest that does not parse.
std::optional<analysis::SimulationManifest> read_manifest(const std::filesystem::path& dir);

/// Checks that `dir` can be written (an existing folder: a probe file is made
/// and removed; a new one: its nearest existing parent), writing nothing
/// else. Throws InputError naming --out.
void check_writable(const std::filesystem::path& dir);

}  // namespace atonlab::runner
