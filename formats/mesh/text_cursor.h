#pragma once
// Strict, locale-independent tokenizer over a whole file held in memory. Every failure throws
// MeshError naming the file and the line; counts read from the file are checked against the
// bytes that remain before anything is allocated for them, so hostile files cannot make a
// reader reserve gigabytes.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "common/mesh_error.h"

namespace quiver {

class TextCursor {
public:
  // `commentChar` (e.g. '#') starts a comment that runs to the end of the line; 0 for none.
  TextCursor(std::string_view text, std::string file, char commentChar = 0);

  bool atEnd();                       // true when only whitespace/comments remain
  std::string_view token(const char* what);  // next whitespace-separated token
  std::string_view peekToken();       // next token without consuming it ("" at end)
  int64_t integer(const char* what);  // whole token must be a decimal integer
  int64_t integerInRange(const char* what, int64_t lo, int64_t hi);
  double real(const char* what);      // whole token must be a number (nan/inf accepted here)
  double finiteReal(const char* what);  // as real(), but NaN and infinities are errors
  void expect(std::string_view keyword);
  std::string_view restOfLine();      // rest of the current line (trimmed, comment removed), then moves past it
  bool atLineEnd();                   // only blanks (or a comment) before the next newline

  // A count read from the file, bounded by what the remaining bytes could possibly hold when each
  // item takes at least `minBytesEach` bytes.
  int64_t count(const char* what, int64_t minBytesEach);

  int line() const { return tokenLine_; }       // line of the last token (1-based)
  size_t position() const { return pos_; }
  void seek(size_t pos);                        // keeps the line count right
  std::string_view text() const { return text_; }
  const std::string& file() const { return file_; }
  std::string where() const;                    // "file:line"
  [[noreturn]] void fail(const std::string& message) const;

private:
  void skipSpace();
  std::string_view text_;
  std::string file_;
  char comment_;
  size_t pos_ = 0;
  int line_ = 1;
  int tokenLine_ = 1;
};

// A line's whitespace-separated words.
std::vector<std::string_view> words(std::string_view line);

// A token from the file made safe for a message: at most 40 characters, non-printable ones as '?'.
std::string printableToken(std::string_view token);

// Parses a whole string as a number; false when it is not exactly one.
bool parseInteger(std::string_view s, int64_t& out);
bool parseReal(std::string_view s, double& out);

} // namespace quiver
