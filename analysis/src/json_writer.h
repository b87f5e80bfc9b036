#pragma once
// A small streaming JSON writer for summary.json: objects, arrays, strings
// (escaped per RFC 8259), numbers in their shortest round-trip form, and null
// for every value that is absent or not finite (JSON has no NaN).
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "csv.h"

namespace atonlab::analysis::detail {

class JsonWriter {
public:
    JsonWriter& begin_object() { return open('{'); }
    JsonWriter& end_object() { return close('}'); }
    JsonWriter& begin_array() { return open('['); }
    JsonWriter& end_array() { return close(']'); }

    JsonWriter& key(std::string_view k) {
        comma();
        out_ += quote(k) + ":";
        after_key_ = true;
        return *this;
    }
    JsonWriter& value(std::string_view s) { return raw(quote(s)); }
    JsonWriter& value(const char* s) { return raw(quote(s)); }
    JsonWriter& value(const std::string& s) { return raw(quote(s)); }
    JsonWriter& value(bool b) { return raw(b ? "true" : "false"); }
    JsonWriter& value(int v) { return raw(std::to_string(v)); }
    JsonWriter& value(std::int64_t v) { return raw(std::to_string(v)); }
    JsonWriter& value(double v) { return raw(std::isfinite(v) ? number_text(v) : std::string("null")); }
    JsonWriter& value(const std::optional<double>& v) { return v ? value(*v) : null(); }
    JsonWriter& null() { return raw("null"); }

    template <class T>
    JsonWriter& field(std::string_view k, const T& v) {
        key(k);
        return value(v);
    }
    JsonWriter& field_null(std::string_view k) {
        key(k);
        return null();
    }

    const std::string& text() const noexcept { return out_; }

    static std::string quote(std::string_view s) {
        std::string o = "\"";
        for (const char ch : s) {
            const auto c = static_cast<unsigned char>(ch);
            switch (ch) {
                case '"':
                    o += "\\\"";
                    break;
                case '\\':
                    o += "\\\\";
                    break;
                case '\n':
                    o += "\\n";
                    break;
                case '\r':
                    o += "\\r";
                    break;
                case '\t':
                    o += "\\t";
                    break;
                default:
                    if (c < 0x20) {
                        static const char* hex = "0123456789abcdef";
                        o += "\\u00";
                        o += hex[c >> 4];
                        o += hex[c & 15];
                    } else {
                        o += ch;
                    }
            }
        }
        return o + "\"";
    }

private:
    void comma() {
        if (after_key_) return;
        if (!first_.empty()) {
            if (!first_.back()) out_ += ",";
            first_.back() = false;
            out_ += "\n" + std::string(2 * first_.size(), ' ');
        }
    }
    JsonWriter& raw(const std::string& text) {
        comma();
        after_key_ = false;
        out_ += text;
        return *this;
    }
    JsonWriter& open(char c) {
        comma();
        after_key_ = false;
        out_ += c;
        first_.push_back(true);
        return *this;
    }
    JsonWriter& close(char c) {
        const bool empty = first_.back();
        first_.pop_back();
        if (!empty) out_ += "\n" + std::string(2 * first_.size(), ' ');
        out_ += c;
        return *this;
    }

    std::string out_;
    std::vector<bool> first_;
    bool after_key_ = false;
};

}  // namespace atonlab::analysis::detail
