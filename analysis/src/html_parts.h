#pragma once
// What the two reports (report.html of a study, report.html of a simulation)
// share: HTML escaping, the page's inline style, and a figure embedded as a
// base64 PNG with a link to its SVG.
#include <filesystem>
#include <string>
#include <string_view>

#include "atonlab/analysis/plots.h"

namespace atonlab::analysis::detail {

/// Text with & < > " ' escaped for HTML.
std::string esc(std::string_view s);

/// The reports' style sheet (inline: the page needs nothing else).
extern const char* const kReportStyle;

/// A <figure> embedding out_dir/f.png as base64 with its caption and file
/// links; "" when the PNG is absent (not drawn).
std::string figure_html(const std::filesystem::path& out_dir, const Figure& f);

}  // namespace atonlab::analysis::detail
