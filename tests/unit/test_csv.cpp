// The one CSV reader (common/csv.h) against RFC 4180's cases (§2: fields,
// quoting, doubled quotes, CRLF, line breaks in quotes) and its errors'
// line and column.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "atonlab/common/csv.h"
#include "atonlab/common/input_error.h"

namespace atonlab {
namespace {

std::vector<CsvRecord> read_all(std::string_view text, CsvOptions options = {}) {
    CsvReader reader(text, "t.csv", options);
    std::vector<CsvRecord> out;
    while (auto r = reader.next()) out.push_back(std::move(*r));
    return out;
}

using Texts = std::vector<std::vector<std::string>>;
Texts texts(const std::vector<CsvRecord>& records) {
    Texts out;
    for (const CsvRecord& r : records) out.push_back(r.texts());
    return out;
}

/// The location of the InputError that reading `text` throws.
SourceLocation error_at(std::string_view text, std::string* message = nullptr, CsvOptions options = {}) {
    try {
        (void)read_all(text, options);
    } catch (const InputError& e) {
        if (message) *message = e.what();
        return e.where().value_or(SourceLocation{});
    }
    ADD_FAILURE() << "no error reading: " << text;
    return {};
}

TEST(Csv, FieldsRecordsAndTheLastLineBreakIsOptional) {
    // RFC 4180 §2.1–2.2: records end at a line break, the last one may lack it.
    EXPECT_EQ(texts(read_all("aaa,bbb,ccc\nzzz,yyy,xxx\n")), (Texts{{"aaa", "bbb", "ccc"}, {"zzz", "yyy", "xxx"}}));
    EXPECT_EQ(texts(read_all("aaa,bbb,ccc\nzzz,yyy,xxx")), (Texts{{"aaa", "bbb", "ccc"}, {"zzz", "yyy", "xxx"}}));
    EXPECT_EQ(texts(read_all("")), Texts{});
    EXPECT_EQ(texts(read_all("a,,\n")), (Texts{{"a", "", ""}}));
}

TEST(Csv, CrLfEndsARecordAndIsNotPartOfTheLastField) {
    // §2.1: CRLF is the record separator (LF alone is read the same).
    const auto r = read_all("a,b\r\nc,d\r\n");
    EXPECT_EQ(texts(r), (Texts{{"a", "b"}, {"c", "d"}}));
    ASSERT_EQ(r.size(), 2u);
    EXPECT_EQ(r[1].line, 2);
}

TEST(Csv, QuotedFieldsHoldCommasDoubledQuotesAndLineBreaks) {
    // §2.5–2.7: a field in quotes may hold commas, CRLF and LF; a quote inside is doubled.
    const auto r = read_all("\"aaa\",\"b,bb\",\"c\"\"cc\"\n\"x\ny\",\"p\r\nq\",z\nlast,\"\",\"\"\"\"\n");
    EXPECT_EQ(texts(r), (Texts{{"aaa", "b,bb", "c\"cc"}, {"x\ny", "p\r\nq", "z"}, {"last", "", "\""}}));
    ASSERT_EQ(r.size(), 3u);
    // A record's line is where it starts; a field's line and column are where it starts.
    EXPECT_EQ(r[1].line, 2);
    EXPECT_EQ(r[2].line, 5);
    EXPECT_TRUE(r[0].fields[1].quoted);
    EXPECT_EQ(r[0].fields[1].column, 7);
    EXPECT_EQ(r[1].fields[1].line, 3);
    EXPECT_EQ(r[1].fields[1].column, 4);
    EXPECT_EQ(r[1].fields[2].line, 4);
    EXPECT_EQ(r[1].fields[2].column, 4);
}

TEST(Csv, AByteOrderMarkIsDroppedAndColumnsCountFromTheText) {
    const auto r = read_all("\xEF\xBB\xBFname,x\n");
    EXPECT_EQ(texts(r), (Texts{{"name", "x"}}));
    EXPECT_EQ(r[0].fields[0].column, 1);
}

TEST(Csv, TrimmingAndCommentsAreOptions) {
    // Without options, blanks are data (RFC 4180 §2.4); with trim, blanks around a field are not,
    // and a quoted field keeps its own.
    EXPECT_EQ(texts(read_all(" a , b \n")), (Texts{{" a ", " b "}}));
    const auto trimmed = read_all(" a , \" b \" ,\tc\n", {.trim = true});
    EXPECT_EQ(texts(trimmed), (Texts{{"a", " b ", "c"}}));
    EXPECT_EQ(trimmed[0].fields[0].column, 2);
    EXPECT_EQ(trimmed[0].fields[2].column, 14);
    // Comments: '#' outside quotes runs to the line's end; a comment line is blank.
    const auto commented =
        read_all("# header next\nlevel,cd_m2 # cd/m2\n0.5,\"#1\"\n", {.trim = true, .comments = true});
    EXPECT_EQ(texts(commented), (Texts{{""}, {"level", "cd_m2"}, {"0.5", "#1"}}));
    EXPECT_TRUE(commented[0].blank());
    EXPECT_FALSE(commented[1].blank());
    EXPECT_EQ(commented[2].line, 3);
    EXPECT_TRUE(read_all("\n")[0].blank());
    EXPECT_FALSE(read_all("\"\"\n")[0].blank());  // an empty quoted field is a value
}

TEST(Csv, AnUnclosedQuoteIsAnErrorAtItsOpeningQuote) {
    std::string message;
    const SourceLocation w = error_at("a,b\nc,\"open\nmore\n", &message);
    EXPECT_EQ(w.file, "t.csv");
    EXPECT_EQ(w.line, 2);
    EXPECT_EQ(w.column, 3);
    EXPECT_NE(message.find("never closed"), std::string::npos) << message;
}

TEST(Csv, TextAfterAClosingQuoteIsAnErrorAtIt) {
    std::string message;
    const SourceLocation w = error_at("a,b\n\"x\"y,z\n", &message);
    EXPECT_EQ(w.line, 2);
    EXPECT_EQ(w.column, 4);
    EXPECT_NE(message.find("after a closing quote"), std::string::npos) << message;
    // After a line break inside quotes, the line and column count on.
    const SourceLocation later = error_at("\"a\nb\" c\n");
    EXPECT_EQ(later.line, 2);
    EXPECT_EQ(later.column, 3);
    // Blanks after the quote are allowed when trimming, not otherwise.
    EXPECT_EQ(texts(read_all("\"x\"  ,y\n", {.trim = true})), (Texts{{"x", "y"}}));
    EXPECT_EQ(error_at("\"x\"  ,y\n").column, 4);
}

TEST(Csv, WritingQuotesOnlyWhatMustBeAndReadsBack) {
    EXPECT_EQ(csv_field("plain"), "plain");
    EXPECT_EQ(csv_field("a,b"), "\"a,b\"");
    EXPECT_EQ(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
    EXPECT_EQ(csv_field("two\nlines"), "\"two\nlines\"");
    const std::vector<std::string> fields{"plain", "a,b", "say \"hi\"", "two\r\nlines", ""};
    std::string line;
    for (const std::string& f : fields) line += (line.empty() ? "" : ",") + csv_field(f);
    const auto back = read_all(line + "\r\n");
    ASSERT_EQ(back.size(), 1u);
    EXPECT_EQ(back[0].texts(), fields);
}

}  // namespace
}  // namespace atonlab
