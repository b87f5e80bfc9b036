#pragma once
// The designs a simulation compares (docs/simulate.md "Designs"): each
// protocol file, and for each a design per combination of --vary values,
// with --set and --observer applied; then each design's decision table,
// loaded from the cache or built from renders, its true values and the facts
// its stimulus records need.
#include <functional>
#include <vector>

#include "simulate/simulate_options.h"
#include "simulate/simulated_session.h"

namespace atonlab::runner {

/// Reads and checks every design (protocol, scene, --set, --vary,
/// --observer): InputError naming the file or option. No GL, nothing written.
std::vector<SimulationDesign> read_designs(const SimulateOptions& o);

/// The decision tables for the designs: each from `cache` (a folder) when
/// there, else built from renders on a headless GL context made here
/// (gl::ContextUnavailable when there is none). A design whose protocol this
/// display cannot show is refused as `atonlab run` refuses it: the
/// displayability table and the refusal on stdout/stderr, and false returned,
/// with nothing written. Built tables are returned unsaved (save_tables).
bool prepare_tables(std::vector<SimulationDesign>& designs, const SimulateOptions& o,
                    const std::filesystem::path& cache);

/// Writes each design's table into `cache` (KEY.json, whole or not at all).
void save_tables(const std::vector<SimulationDesign>& designs, const std::filesystem::path& cache);

/// The true values of every design's conditions from renders (for
/// --render-every-trial, which builds no table): a headless GL context is made here.
void render_true_values(std::vector<SimulationDesign>& designs);

}  // namespace atonlab::runner
