// CSV (RFC 4180), read and written (csv.h).
#include "atonlab/common/csv.h"

#include <fmt/format.h>

#include <algorithm>

#include "atonlab/common/input_error.h"

namespace atonlab {

namespace {

bool is_blank(char c) {
    return c == ' ' || c == '\t';
}

}  // namespace

std::vector<std::string> CsvRecord::texts() const {
    std::vector<std::string> out;
    out.reserve(fields.size());
    for (const CsvField& f : fields) out.push_back(f.text);
    return out;
}

CsvReader::CsvReader(std::string_view text, std::string file, CsvOptions options)
    : text_(text), file_(std::move(file)), options_(options) {
    if (text_.starts_with("\xEF\xBB\xBF")) at_ = line_start_ = 3;  // a UTF-8 byte-order mark
}

void CsvReader::fail(int line, int column, const std::string& message) const {
    throw InputError(SourceLocation{file_, line, column, ""}, message);
}

std::optional<CsvRecord> CsvReader::next() {
    if (at_ >= text_.size()) return std::nullopt;
    CsvRecord rec;
    rec.line = line_;
    const auto column = [this](std::size_t i) { return static_cast<int>(i - line_start_) + 1; };
    // Whether text_[i] ends the line: LF, or CR before LF (or a CR that ends the text).
    const auto line_end = [this](std::size_t i) {
        return text_[i] == '\n' || (text_[i] == '\r' && (i + 1 == text_.size() || text_[i + 1] == '\n'));
    };
    const auto new_line = [this](std::size_t after_lf) {
        ++line_;
        line_start_ = after_lf;
    };
    while (true) {
        CsvField f;
        std::size_t i = at_;
        if (options_.trim)
            while (i < text_.size() && is_blank(text_[i])) ++i;
        f.line = line_;
        f.column = column(i);
        bool ends_record = false;
        if (i < text_.size() && text_[i] == '"') {
            f.quoted = true;
            const int open_line = line_, open_column = column(i);
            ++i;
            while (true) {
                if (i >= text_.size())
                    fail(open_line, open_column,
                         fmt::format("the quoted field that opens on line {} is never closed.", open_line));
                const char c = text_[i++];
                if (c == '"') {
                    if (i < text_.size() && text_[i] == '"') {
                        f.text += '"';
                        ++i;
                        continue;
                    }
                    break;
                }
                if (c == '\n') new_line(i);
                f.text += c;
            }
            if (options_.trim)
                while (i < text_.size() && is_blank(text_[i])) ++i;
            if (i < text_.size() && text_[i] != ',' && !line_end(i) && !(options_.comments && text_[i] == '#'))
                fail(line_, column(i),
                     "text after a closing quote: a quoted field ends at its quote (a quote inside it is doubled).");
        } else {
            const std::size_t start = i;
            while (i < text_.size() && text_[i] != ',' && !line_end(i) && !(options_.comments && text_[i] == '#')) ++i;
            std::string_view t = text_.substr(start, i - start);
            if (options_.trim)
                while (!t.empty() && is_blank(t.back())) t.remove_suffix(1);
            f.text = std::string(t);
        }
        if (options_.comments && i < text_.size() && text_[i] == '#')
            while (i < text_.size() && !line_end(i)) ++i;
        if (i >= text_.size()) {
            ends_record = true;
        } else if (text_[i] == ',') {
            ++i;
        } else {  // the line's end
            i = std::min(text_.size(), i + (text_[i] == '\r' ? 2 : 1));
            new_line(i);
            ends_record = true;
        }
        at_ = i;
        rec.fields.push_back(std::move(f));
        if (ends_record) return rec;
    }
}

std::string csv_field(std::string_view text) {
    if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
    std::string out = "\"";
    for (const char ch : text) {
        if (ch == '"') out += '"';
        out += ch;
    }
    return out + '"';
}

}  // namespace atonlab
