#pragma once
// What the protocol file adds to the strict TOML reader of common/
// (toml_reader.h): conditions read from a conditions file (CSV) whose errors
// name the CSV file, the row and the column; scene keys and "key=value" scene
// overrides as condition values.
#include <toml++/toml.h>

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "atonlab/common/toml_reader.h"
#include "atonlab/protocols/protocol.h"

namespace atonlab::protocols::detail {

using toml_reader::KeyList;
using toml_reader::Section;

/// The protocol file being read.
class Document : public toml_reader::Document {
public:
    using toml_reader::Document::Document;

    /// A condition read from a row of a conditions file (CSV): its errors name
    /// the CSV file, the row's line and the column instead of the TOML path.
    struct CsvRow {
        std::string file;
        int line = 0;                                      ///< 1-based line of the row in the CSV file
        std::vector<std::pair<std::string, int>> columns;  ///< (column name, 1-based column) of the row's cells
        std::vector<int> set, test_set, reference_set;     ///< the column of each override, in order
    };
    /// Registers the condition at `path` ("block[0].condition[2]") as `row`.
    void add_csv_row(std::string path, CsvRow row) { csv_rows_.emplace_back(std::move(path), std::move(row)); }

protected:
    /// The error at `w`: in the CSV file when the key is a conditions-file row's.
    void relocate(SourceLocation& w, std::string& message) const override;

public:

    /// One "section.key=value" scene override (value: one TOML value).
    SceneOverride scene_override(const toml::node* n, const std::string& key, const std::string& context = {}) const;
    /// An array of overrides (a single string is one override).
    std::vector<SceneOverride> scene_overrides(const toml::node* n, const std::string& key,
                                               const std::string& context = {}) const;
    /// A dotted scene key ("light.reference.intensity_cd").
    std::string scene_key(const toml::node* n, const std::string& key, const std::string& context = {}) const;

private:
    std::vector<std::pair<std::string, CsvRow>> csv_rows_;
};

}  // namespace atonlab::protocols::detail
