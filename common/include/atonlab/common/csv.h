#pragma once
// CSV (RFC 4180), the one reader and writer of it: conditions files
// (protocols), trials CSVs (analysis) and calibration readings (display).
// Fields are separated by commas; a field holding a comma, a quote or a line
// break is written in double quotes, a quote inside doubled; records end at
// LF or CRLF, and a quoted field may span lines. What the RFC leaves open: a
// UTF-8 byte-order mark before the first record is dropped, a quote inside an
// unquoted field is kept as written, and a file's last record need not end
// with a line break. A quoted field never closed, or text after a closing
// quote, is an InputError at its file, line and column.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace atonlab {

struct CsvField {
    std::string text;
    int line = 0;         ///< 1-based line of its first character (a quoted field may span lines)
    int column = 0;       ///< 1-based column of its first character (its opening quote when quoted)
    bool quoted = false;  ///< written in quotes
};

struct CsvRecord {
    int line = 0;  ///< 1-based line where the record starts
    std::vector<CsvField> fields;
    /// An empty line, or one of only blanks (CsvOptions::trim) or a comment (CsvOptions::comments).
    bool blank() const { return fields.size() == 1 && !fields[0].quoted && fields[0].text.empty(); }
    /// The fields' texts.
    std::vector<std::string> texts() const;
};

struct CsvOptions {
    /// Spaces and tabs around an unquoted field are not its text (and around a
    /// quoted one are allowed): hand-written files (conditions, calibration readings).
    bool trim = false;
    /// '#' outside quotes starts a comment that runs to the end of its line
    /// (calibration readings, which instruments annotate so).
    bool comments = false;
};

class CsvReader {
public:
    /// `text` must outlive the reader; `file` names it in errors.
    CsvReader(std::string_view text, std::string file, CsvOptions options = {});
    /// The next record; nullopt at the end of the text. Throws InputError as above.
    std::optional<CsvRecord> next();

private:
    void fail(int line, int column, const std::string& message) const;
    std::string_view text_;
    std::string file_;
    CsvOptions options_;
    std::size_t at_ = 0;
    int line_ = 1;                ///< the line of text_[at_]
    std::size_t line_start_ = 0;  ///< where that line starts
};

/// The field as CSV writes it: quoted when it holds a comma, quote or line break.
std::string csv_field(std::string_view text);

}  // namespace atonlab
