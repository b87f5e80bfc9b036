// What the two reports (report_html.cpp, simulation_report.cpp) share:
// escaping, the page's style and an embedded figure.
#include "html_parts.h"

#include <fmt/format.h>

#include "atonlab/analysis/report.h"
#include "atonlab/common/input_text.h"

namespace atonlab::analysis::detail {

std::string esc(std::string_view s) {
    std::string o;
    for (const char ch : s) {
        switch (ch) {
            case '&':
                o += "&amp;";
                break;
            case '<':
                o += "&lt;";
                break;
            case '>':
                o += "&gt;";
                break;
            case '"':
                o += "&quot;";
                break;
            case '\'':
                o += "&#39;";
                break;
            default:
                o += ch;
        }
    }
    return o;
}

std::string figure_html(const std::filesystem::path& out_dir, const Figure& f) {
    const std::string png = text::read_text_file(out_dir / f.png).text;  // empty when it was not drawn
    if (png.empty()) return {};
    std::string h = "<figure>\n";
    h += fmt::format("<img alt=\"{}\" src=\"data:image/png;base64,{}\">\n", esc(f.title), base64(png));
    h += fmt::format("<figcaption><b>{}.</b> {}", esc(f.title), esc(f.caption));
    h += fmt::format(" <span class=\"files\">Files: <a href=\"{0}\">{0}</a>", esc(f.png.generic_string()));
    if (!f.svg.empty()) h += fmt::format(", <a href=\"{0}\">{0}</a>", esc(f.svg.generic_string()));
    h += ".</span></figcaption>\n</figure>\n";
    return h;
}

const char* const kReportStyle =
    R"(body { font-family: "DejaVu Sans", Arial, sans-serif; margin: 2em auto; max-width: 72em; padding: 0 1em; color: #222; line-height: 1.4; overflow-wrap: anywhere; }
h1 { font-size: 1.6em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 2em; }
.table-wrap { max-width: 100%; overflow-x: auto; margin: 0.8em 0; }
table { border-collapse: collapse; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.5em; text-align: left; vertical-align: top; overflow-wrap: normal; }
th { background: #f2f2f2; }
td.num { text-align: right; font-family: "DejaVu Sans Mono", monospace; white-space: nowrap; }
ol.notes { font-size: 0.85em; color: #444; margin-top: 0; }
.ok { color: #1a7f37; font-weight: bold; } .bad { color: #b3261e; font-weight: bold; }
.warn { background: #fff4e5; border-left: 4px solid #f0a020; padding: 0.5em 1em; }
figure { margin: 1em 0; } figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #444; max-width: 60em; } .files { color: #777; }
code { background: #f4f4f4; padding: 0 0.2em; }
@media print {
  body { margin: 0; max-width: none; padding: 0; font-size: 10pt; }
  .table-wrap { overflow: visible; }
  table { font-size: 8pt; width: 100%; }
  th, td { overflow-wrap: anywhere; padding: 0.15em 0.3em; }
  td.num { white-space: normal; }
  tr, figure, .warn { break-inside: avoid; }
  h2 { break-after: avoid; }
  a { color: inherit; text-decoration: none; }
  .files { display: none; }
})";

}  // namespace atonlab::analysis::detail
