// Photometer readings: the CSV and ArgyllCMS .ti3 readers (docs/display-calibration.md).
#include "atonlab/display/calibration.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>

#include "atonlab/common/csv.h"
#include "atonlab/common/input_error.h"
#include "atonlab/common/input_text.h"
#include "atonlab/display/readings_text.h"

namespace atonlab::display {

const char* channel_name(Channel c) {
    switch (c) {
        case Channel::red:
            return "red";
        case Channel::green:
            return "green";
        case Channel::blue:
            return "blue";
        case Channel::grey:
            return "grey";
        case Channel::other:
            return "other";
    }
    return "?";
}

namespace {

std::string read_text(const std::filesystem::path& path) {
    text::FileText read = text::read_text_file(path);  // only up to a limit (/dev/zero is refused)
    if (!read.ok())
        throw InputError(SourceLocation{path.string(), 0, 0, ""},
                         fmt::format("the calibration file cannot be {}: {}", read.opened ? "read" : "opened",
                                     read.error));
    return std::move(read.text);
}

/// Splits text into lines (without the newline), 1-based numbering by index + 1.
std::vector<std::string_view> split_lines(std::string_view text) {
    std::vector<std::string_view> lines;
    std::size_t pos = 0;
    while (pos <= text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        lines.push_back(text.substr(pos, end - pos));
        if (end == text.size()) break;
        pos = end + 1;
    }
    return lines;
}

glm::dvec3 rgb_of(Channel c, double level) {
    switch (c) {
        case Channel::red:
            return {level, 0.0, 0.0};
        case Channel::green:
            return {0.0, level, 0.0};
        case Channel::blue:
            return {0.0, 0.0, level};
        default:
            return glm::dvec3(level);
    }
}

}  // namespace

// ---------------------------------------------------------------------------
// CSV.

const char* drive_scale_name(DriveScale scale) {
    switch (scale) {
        case DriveScale::bits8:
            return "8bit";
        case DriveScale::bits10:
            return "10bit";
        default:
            return "fraction";
    }
}

std::optional<DriveScale> drive_scale_from_name(std::string_view name) {
    if (name == "fraction") return DriveScale::fraction;
    if (name == "8bit") return DriveScale::bits8;
    if (name == "10bit") return DriveScale::bits10;
    return std::nullopt;
}

namespace {

const char* const csv_header_help =
    "the header names the drive level (level, level_fraction, level_8bit or level_10bit), channel, and the "
    "reading (cd_m2, fL, or X,Y,Z)";

/// The columns of a calibration CSV, as its header names them.
struct CsvHeader {
    // Column index of the level, channel and reading columns; -1 when absent.
    int col_level = -1, col_channel = -1, col_cd = -1, col_x = -1, col_z = -1;
    std::string level_key = "level", reading_key = "cd_m2";
    std::optional<DriveScale> named_scale;  // from the level column's name
    double reading_scale = 1.0;             // cd/m² per unit of the reading column
    DriveScale scale = DriveScale::fraction;
    std::size_t n_columns = 0;
    int header_line = 0;
};

/// A record's fields (common/csv.h: RFC 4180, trimmed, '#' comments), each with its 1-based column.
using CsvFields = std::vector<std::pair<std::string, int>>;

CsvFields csv_fields(const CsvRecord& rec) {
    CsvFields fields;
    for (const CsvField& f : rec.fields) fields.emplace_back(f.text, f.column);
    return fields;
}

/// The header (the first non-comment line, number line_no): which column holds what, and the drive scale.
CsvHeader parse_csv_header(const CsvFields& fields, int line_no, const std::string& file_name,
                           const CalibrationFileOptions& options) {
    CsvHeader h;
    h.header_line = line_no;
    h.n_columns = fields.size();
    int col_y = -1;
    for (std::size_t i = 0; i < fields.size(); ++i) {
        const auto name = fields[i].first;
        const bool level_name =
            name == "level" || name == "level_fraction" || name == "level_8bit" || name == "level_10bit";
        const bool reading_name = name == "cd_m2" || name == "fL";
        int* slot = level_name              ? &h.col_level
                    : name == "channel"     ? &h.col_channel
                    : reading_name          ? &h.col_cd
                    : name == "X"           ? &h.col_x
                    : name == "Y"           ? &col_y
                    : name == "Z"           ? &h.col_z
                                            : nullptr;
        if (slot == nullptr)
            throw InputError(SourceLocation{file_name, line_no, fields[i].second, std::string(name)},
                             fmt::format("unknown column; {}", csv_header_help));
        if (*slot >= 0)
            throw InputError(SourceLocation{file_name, line_no, fields[i].second, std::string(name)},
                             level_name || reading_name ? "a second drive-level or reading column"
                                                        : "this column appears twice in the header");
        *slot = static_cast<int>(i);
        if (level_name) {
            h.level_key = std::string(name);
            if (name != "level") h.named_scale = drive_scale_from_name(name.substr(6));  // after "level_"
        }
        if (reading_name) {
            h.reading_key = std::string(name);
            h.reading_scale = name == "fL" ? kCdM2PerFootLambert : 1.0;
        }
    }
    const bool xyz = h.col_x >= 0 || col_y >= 0 || h.col_z >= 0;
    if (xyz && (h.col_x < 0 || col_y < 0 || h.col_z < 0))
        throw InputError(SourceLocation{file_name, line_no, 0, h.col_x < 0 ? "X" : col_y < 0 ? "Y" : "Z"},
                         "XYZ readings need all three columns X, Y and Z");
    if (xyz && h.col_cd >= 0)
        throw InputError(SourceLocation{file_name, line_no, 0, h.reading_key},
                         "the header has both X,Y,Z and a luminance column; give one reading per row");
    if (xyz) {
        h.col_cd = col_y;
        h.reading_key = std::string("Y");  // moved in: GCC 12 misreads assigning a literal (-Wrestrict)
    }
    for (const auto& [slot, name] :
         {std::pair{h.col_level, "level"}, {h.col_channel, "channel"}, {h.col_cd, "cd_m2"}})
        if (slot < 0)
            throw InputError(SourceLocation{file_name, line_no, 0, name},
                             fmt::format("the header lacks this column; {}", csv_header_help));
    if (h.named_scale && options.drive_scale && *h.named_scale != *options.drive_scale)
        throw InputError(SourceLocation{file_name, line_no, fields[static_cast<std::size_t>(h.col_level)].second,
                                        h.level_key},
                         fmt::format("the column says the drive levels are {} but --drive-scale says {}",
                                     drive_scale_name(*h.named_scale), drive_scale_name(*options.drive_scale)));
    h.scale = h.named_scale.value_or(options.drive_scale.value_or(DriveScale::fraction));
    return h;
}

}  // namespace

std::vector<Measurement> parse_calibration_csv(std::string_view text, const std::string& file_name,
                                               const CalibrationFileOptions& options) {
    std::vector<Measurement> out;
    std::optional<CsvHeader> header;  // once the header line is read
    CsvReader reader(text, file_name, CsvOptions{.trim = true, .comments = true});
    while (const auto rec = reader.next()) {
        if (rec->blank()) continue;  // an empty or comment line
        const int line_no = rec->line;
        const CsvFields fields = csv_fields(*rec);
        if (!header) {
            header = parse_csv_header(fields, line_no, file_name, options);
            continue;
        }
        const auto& [col_level, col_channel, col_cd, col_x, col_z, level_key, reading_key, named_scale,
                     reading_scale, scale, n_columns, header_line] = *header;

        if (fields.size() != n_columns)
            throw InputError(SourceLocation{file_name, line_no, 0, ""},
                             fmt::format("this row has {} fields but the header (line {}) has {}", fields.size(),
                                         header_line, n_columns));
        const auto& [level_text, level_col] = fields[static_cast<std::size_t>(col_level)];
        const auto& [channel_text, channel_col] = fields[static_cast<std::size_t>(col_channel)];
        const auto& [cd_text, cd_col] = fields[static_cast<std::size_t>(col_cd)];

        const auto raw_level = reading_number(level_text);
        if (!raw_level)
            throw InputError(SourceLocation{file_name, line_no, level_col, level_key},
                             fmt::format("'{}' is not a number", level_text));
        double level_value = *raw_level;
        if (scale == DriveScale::fraction) {
            if (*raw_level < 0.0 || *raw_level > 1.0) {
                const bool codes = !named_scale && !options.drive_scale && *raw_level > 1.0 &&
                                   *raw_level == std::floor(*raw_level) && *raw_level <= 1023.0;
                throw InputError(
                    SourceLocation{file_name, line_no, level_col, level_key},
                    codes ? fmt::format("the drive level {} is not a fraction in [0, 1]; drive levels are fractions "
                                        "(0 to 1), 8-bit codes (0 to 255) or 10-bit codes (0 to 1023): name the "
                                        "column level_8bit or level_10bit, or give --drive-scale 8bit or 10bit",
                                        *raw_level)
                          : fmt::format("the drive level must be a fraction in [0, 1], not {}", *raw_level));
            }
        } else {
            const int max_code = scale == DriveScale::bits8 ? 255 : 1023;
            if (*raw_level < 0.0 || *raw_level > max_code || *raw_level != std::floor(*raw_level))
                throw InputError(SourceLocation{file_name, line_no, level_col, level_key},
                                 fmt::format("a {} drive level is a whole code from 0 to {}, not {}",
                                             drive_scale_name(scale), max_code, *raw_level));
            level_value = *raw_level / max_code;
        }
        const double* level = &level_value;
        Channel channel = Channel::other;
        if (channel_text == "red") {
            channel = Channel::red;
        } else if (channel_text == "green") {
            channel = Channel::green;
        } else if (channel_text == "blue") {
            channel = Channel::blue;
        } else if (channel_text == "grey" || channel_text == "white" || channel_text == "black") {
            channel = Channel::grey;
            const double want = channel_text == "white" ? 1.0 : 0.0;
            if (channel_text != "grey" && *level != want)
                throw InputError(SourceLocation{file_name, line_no, level_col, level_key},
                                 fmt::format("a '{}' reading must have level {}, not {}", channel_text, want, *level));
        } else {
            throw InputError(
                SourceLocation{file_name, line_no, channel_col, "channel"},
                fmt::format("unknown channel '{}'; use red, green, blue, grey, white or black", channel_text));
        }
        const auto cd = reading_number(cd_text);
        if (!cd)
            throw InputError(SourceLocation{file_name, line_no, cd_col, reading_key},
                             fmt::format("'{}' is not a number", cd_text));
        if (*cd < 0.0)
            throw InputError(SourceLocation{file_name, line_no, cd_col, reading_key},
                             fmt::format("a luminance cannot be negative ({} {})", *cd,
                                         reading_key == "fL" ? "fL" : "cd/m²"));
        Measurement m{*level, channel, *cd * reading_scale, line_no, rgb_of(channel, *level), file_name};
        if (col_x >= 0) {
            double xz[2] = {};
            for (int k = 0; k < 2; ++k) {
                const auto& [text_k, col_k] = fields[static_cast<std::size_t>(k == 0 ? col_x : col_z)];
                const auto v = reading_number(text_k);
                if (!v || *v < 0.0)
                    throw InputError(SourceLocation{file_name, line_no, col_k, k == 0 ? "X" : "Z"},
                                     fmt::format("'{}' is not a number >= 0", text_k));
                xz[k] = *v;
            }
            m.xyz_cd_m2 = glm::dvec3(xz[0], *cd, xz[1]);
        }
        out.push_back(m);
    }
    if (!header)
        throw InputError(SourceLocation{file_name, 0, 0, ""},
                         fmt::format("the file is empty; {}", csv_header_help));
    if (out.empty())
        throw InputError(SourceLocation{file_name, header->header_line, 0, ""}, "the file has no measurements");
    return out;
}

std::vector<Measurement> read_calibration_csv(const std::filesystem::path& path,
                                              const CalibrationFileOptions& options) {
    return parse_calibration_csv(read_text(path), path.string(), options);
}

// ---------------------------------------------------------------------------
// ArgyllCMS .ti3 (CGATS). Layout per Argyll's doc/ti3_format.html: identifier
// CTI3, keywords (DEVICE_CLASS "DISPLAY", LUMINANCE_XYZ_CDM2 "X Y Z",
// NORMALIZED_TO_Y_100 "YES"), NUMBER_OF_FIELDS, BEGIN_DATA_FORMAT ...
// END_DATA_FORMAT, NUMBER_OF_SETS, BEGIN_DATA ... END_DATA.

namespace {

struct Keyword {
    std::string value;
    int line;
};

InputError ti3_error(const std::string& file_name, int line, int column, std::string key, const std::string& message) {
    return InputError(SourceLocation{file_name, line, column, std::move(key)}, message);
}

/// A .ti3 file's structure: its keywords, data format and data lines, not yet read as measurements.
struct Ti3Table {
    std::map<std::string, Keyword> keywords;
    std::vector<std::string> fields;
    int format_line = 0, data_line = 0, end_line = 0;
    std::optional<std::pair<long, int>> number_of_fields, number_of_sets;  // value, line
    std::vector<std::pair<std::vector<ReadingToken>, int>> rows;           // tokens, line
};

/// Reads the lines of a .ti3 file into its table; throws where the file's structure is broken (no CTI3,
/// an unclosed data format or table, no table).
Ti3Table read_ti3_table(const std::vector<std::string_view>& lines, const std::string& file_name) {
    auto error = [&](int line, int column, std::string key, const std::string& message) {
        return ti3_error(file_name, line, column, std::move(key), message);
    };
    enum class State { identifier, header, format, data, done } state = State::identifier;
    Ti3Table table;
    auto& [keywords, fields, format_line, data_line, end_line, number_of_fields, number_of_sets, rows] = table;

    auto parse_count = [&](const std::vector<ReadingToken>& t, int line_no) {
        const auto v = t.size() == 2 ? reading_number(t[1].text) : std::nullopt;
        if (!v || *v < 0.0 || *v != std::floor(*v))
            throw error(line_no, t[0].column, t[0].text, "expects one whole number");
        return std::pair{static_cast<long>(*v), line_no};
    };

    for (std::size_t li = 0; li < lines.size() && state != State::done; ++li) {
        const int line_no = static_cast<int>(li) + 1;
        const auto tokens = reading_tokens(lines[li]);
        if (tokens.empty()) continue;
        const std::string& head = tokens[0].text;
        switch (state) {
            case State::identifier:
                if (head != "CTI3")
                    throw error(line_no, 1, "",
                                "this is not an Argyll .ti3 file: it must begin with the identifier CTI3");
                state = State::header;
                break;
            case State::header:
                if (head == "KEYWORD") {
                    // Declares a non-standard keyword; its value follows on its own line.
                } else if (head == "NUMBER_OF_FIELDS") {
                    number_of_fields = parse_count(tokens, line_no);
                } else if (head == "NUMBER_OF_SETS") {
                    number_of_sets = parse_count(tokens, line_no);
                } else if (head == "BEGIN_DATA_FORMAT") {
                    format_line = line_no;
                    state = State::format;
                    for (std::size_t i = 1; i < tokens.size(); ++i) {
                        if (tokens[i].text == "END_DATA_FORMAT") {
                            state = State::header;
                            break;
                        }
                        fields.push_back(tokens[i].text);
                    }
                } else if (head == "BEGIN_DATA") {
                    if (fields.empty())
                        throw error(line_no, 1, "BEGIN_DATA_FORMAT", "BEGIN_DATA comes before any BEGIN_DATA_FORMAT");
                    data_line = line_no;
                    state = State::data;
                } else {
                    std::string value;
                    for (std::size_t i = 1; i < tokens.size(); ++i) value += (i > 1 ? " " : "") + tokens[i].text;
                    keywords[head] = Keyword{value, line_no};
                }
                break;
            case State::format:
                for (const auto& t : tokens) {
                    if (t.text == "END_DATA_FORMAT") {
                        state = State::header;
                        break;
                    }
                    fields.push_back(t.text);
                }
                break;
            case State::data:
                if (head == "END_DATA") {
                    end_line = line_no;
                    state = State::done;
                } else {
                    rows.emplace_back(tokens, line_no);
                }
                break;
            case State::done:
                break;
        }
    }
    switch (state) {
        case State::identifier:
            throw error(0, 0, "", "the file is empty; an Argyll .ti3 file begins with CTI3");
        case State::format:
            throw error(format_line, 1, "END_DATA_FORMAT",
                        fmt::format("BEGIN_DATA_FORMAT at line {} is never closed by END_DATA_FORMAT", format_line));
        case State::header:
            throw error(static_cast<int>(lines.size()), 0, "BEGIN_DATA", "the file has no data table (BEGIN_DATA)");
        case State::data:
            throw error(data_line, 1, "END_DATA",
                        fmt::format("the data table that begins at line {} is never closed by END_DATA", data_line));
        case State::done:
            break;
    }
    return table;
}

/// cd/m² per unit of the file's XYZ values: 1, or white's Y / 100 when NORMALIZED_TO_Y_100 is YES.
double ti3_absolute_scale(const std::map<std::string, Keyword>& keywords, const std::string& file_name) {
    // XYZ are absolute cd/m² unless NORMALIZED_TO_Y_100 is YES; then white Y = 100 and
    // LUMINANCE_XYZ_CDM2 holds white's absolute XYZ (Argyll's own readers do the same).
    double scale = 1.0;
    if (const auto it = keywords.find("NORMALIZED_TO_Y_100"); it != keywords.end() && it->second.value == "YES") {
        const auto lum = keywords.find("LUMINANCE_XYZ_CDM2");
        if (lum == keywords.end())
            throw ti3_error(file_name, it->second.line, 1, "LUMINANCE_XYZ_CDM2",
                            "NORMALIZED_TO_Y_100 is YES but there is no LUMINANCE_XYZ_CDM2 to give the absolute scale");
        std::istringstream ss(lum->second.value);
        std::string xs, ys, zs, extra;
        ss >> xs >> ys >> zs;
        const auto x = reading_number(xs), y = reading_number(ys), z = reading_number(zs);
        if (!x || !y || !z || (ss >> extra) || *y <= 0.0)
            throw ti3_error(file_name, lum->second.line, 1, "LUMINANCE_XYZ_CDM2",
                            fmt::format("expects the white's X Y Z in cd/m² (three numbers, Y > 0), not \"{}\"",
                                        lum->second.value));
        scale = *y / 100.0;
    }
    return scale;
}

}  // namespace

std::vector<Measurement> parse_argyll_ti3(std::string_view text, const std::string& file_name) {
    auto error = [&](int line, int column, std::string key, const std::string& message) {
        return ti3_error(file_name, line, column, std::move(key), message);
    };
    const Ti3Table table = read_ti3_table(split_lines(text), file_name);
    // References, not a structured binding: clang 14 (the fuzz build) cannot capture one in a lambda.
    const auto& keywords = table.keywords;
    const auto& fields = table.fields;
    const int format_line = table.format_line, data_line = table.data_line, end_line = table.end_line;
    const auto& number_of_fields = table.number_of_fields;
    const auto& number_of_sets = table.number_of_sets;
    const auto& rows = table.rows;

    if (number_of_fields && static_cast<std::size_t>(number_of_fields->first) != fields.size())
        throw error(number_of_fields->second, 1, "NUMBER_OF_FIELDS",
                    fmt::format("NUMBER_OF_FIELDS is {} but BEGIN_DATA_FORMAT (line {}) names {} fields",
                                number_of_fields->first, format_line, fields.size()));
    auto field_index = [&](const char* name) {
        const auto it = std::find(fields.begin(), fields.end(), name);
        if (it == fields.end())
            throw error(format_line, 1, "BEGIN_DATA_FORMAT",
                        fmt::format("the data format lacks the field {} (needed: RGB_R RGB_G RGB_B XYZ_Y)", name));
        return static_cast<std::size_t>(it - fields.begin());
    };
    const std::size_t i_r = field_index("RGB_R"), i_g = field_index("RGB_G"), i_b = field_index("RGB_B"),
                      i_y = field_index("XYZ_Y");
    // X and Z are optional: kept with the reading when both are there.
    const auto i_x = std::find(fields.begin(), fields.end(), "XYZ_X"),
               i_z = std::find(fields.begin(), fields.end(), "XYZ_Z");
    const bool has_xz = i_x != fields.end() && i_z != fields.end();

    if (const auto it = keywords.find("DEVICE_CLASS"); it != keywords.end() && it->second.value != "DISPLAY")
        throw error(it->second.line, 1, "DEVICE_CLASS",
                    fmt::format("the measurements are of a '{}' device, not a DISPLAY", it->second.value));
    const double scale = ti3_absolute_scale(keywords, file_name);

    std::vector<Measurement> out;
    out.reserve(rows.size());
    for (const auto& row : rows) {
        // Not a structured binding: clang 14 (the fuzz build) cannot capture one in the lambda below.
        const auto& tokens = row.first;
        const auto line_no = row.second;
        if (tokens.size() != fields.size())
            throw error(line_no, 0, "",
                        fmt::format("this data line has {} values but BEGIN_DATA_FORMAT (line {}) names {} fields",
                                    tokens.size(), format_line, fields.size()));
        auto number = [&](std::size_t i) {
            const auto v = reading_number(tokens[i].text);
            if (!v)
                throw error(line_no, tokens[i].column, fields[i], fmt::format("'{}' is not a number", tokens[i].text));
            return *v;
        };
        glm::dvec3 rgb(number(i_r), number(i_g), number(i_b));
        for (int c = 0; c < 3; ++c) {
            const std::size_t idx = c == 0 ? i_r : c == 1 ? i_g : i_b;
            if (rgb[c] < 0.0 || rgb[c] > 100.0)
                throw error(line_no, tokens[idx].column, fields[idx],
                            fmt::format("device values are percentages in [0, 100], not {}", rgb[c]));
        }
        rgb /= 100.0;
        const double Y = number(i_y);
        if (Y < 0.0)
            throw error(line_no, tokens[i_y].column, "XYZ_Y", fmt::format("a luminance cannot be negative ({})", Y));

        Channel channel = Channel::other;
        double level = std::max({rgb.r, rgb.g, rgb.b});
        if (rgb.r == rgb.g && rgb.g == rgb.b) {
            channel = Channel::grey;
        } else if (rgb.g == 0.0 && rgb.b == 0.0) {
            channel = Channel::red;
        } else if (rgb.r == 0.0 && rgb.b == 0.0) {
            channel = Channel::green;
        } else if (rgb.r == 0.0 && rgb.g == 0.0) {
            channel = Channel::blue;
        }
        out.push_back(Measurement{level, channel, Y * scale, line_no, rgb, file_name});
        if (has_xz)
            out.back().xyz_cd_m2 = glm::dvec3(number(static_cast<std::size_t>(i_x - fields.begin())), Y,
                                              number(static_cast<std::size_t>(i_z - fields.begin()))) *
                                   scale;
    }
    if (number_of_sets && static_cast<std::size_t>(number_of_sets->first) != rows.size())
        throw error(number_of_sets->second, 1, "NUMBER_OF_SETS",
                    fmt::format("NUMBER_OF_SETS is {} but the table (lines {}-{}) has {} data lines",
                                number_of_sets->first, data_line, end_line, rows.size()));
    if (out.empty()) throw error(data_line, 1, "BEGIN_DATA", "the data table is empty");
    return out;
}

std::vector<Measurement> read_argyll_ti3(const std::filesystem::path& path) {
    return parse_argyll_ti3(read_text(path), path.string());
}

std::vector<Measurement> read_calibration_file(const std::filesystem::path& path,
                                               const CalibrationFileOptions& options) {
    const auto ext = path.extension().string();
    if (ext == ".ti3") {
        if (options.drive_scale)
            throw InputError(SourceLocation{path.string(), 0, 0, ""},
                             "--drive-scale applies to a CSV file; an ArgyllCMS .ti3 gives RGB_R, RGB_G, RGB_B in "
                             "percent");
        return read_argyll_ti3(path);
    }
    if (ext == ".csv") return read_calibration_csv(path, options);
    throw InputError(SourceLocation{path.string(), 0, 0, ""},
                     fmt::format("unknown calibration file type '{}'; use .csv or an ArgyllCMS .ti3", ext));
}

}  // namespace atonlab::display
