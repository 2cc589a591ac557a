#include "formats/mesh/text_cursor.h"

#include <charconv>
#include <cmath>

namespace quiver {

namespace {
bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
} // namespace

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && isSpace(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !isSpace(line[i])) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

std::string printableToken(std::string_view token) {
  std::string out;
  for (char c : token.substr(0, 40)) out += (c >= 32 && c < 127) ? c : '?';
  if (token.size() > 40) out += "...";
  return out;
}

bool parseInteger(std::string_view s, int64_t& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && end == s.data() + s.size() && !s.empty();
}

bool parseReal(std::string_view s, double& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  if (ec == std::errc::result_out_of_range) return false;
  return ec == std::errc() && end == s.data() + s.size() && !s.empty();
}

TextCursor::TextCursor(std::string_view text, std::string file, char commentChar)
    : text_(text), file_(std::move(file)), comment_(commentChar) {}

void TextCursor::skipSpace() {
  while (pos_ < text_.size()) {
    char c = text_[pos_];
    if (c == '\n') {
      ++line_;
      ++pos_;
    } else if (isSpace(c)) {
      ++pos_;
    } else if (comment_ && c == comment_) {
      while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    } else {
      break;
    }
  }
}

bool TextCursor::atEnd() {
  skipSpace();
  return pos_ >= text_.size();
}

std::string_view TextCursor::token(const char* what) {
  skipSpace();
  tokenLine_ = line_;
  if (pos_ >= text_.size()) fail(std::string("unexpected end of file while reading ") + what);
  size_t start = pos_;
  while (pos_ < text_.size() && !isSpace(text_[pos_]) && !(comment_ && text_[pos_] == comment_)) ++pos_;
  return text_.substr(start, pos_ - start);
}

std::string_view TextCursor::peekToken() {
  size_t savePos = pos_;
  int saveLine = line_, saveTokenLine = tokenLine_;
  std::string_view t = atEnd() ? std::string_view() : token("");
  pos_ = savePos;
  line_ = saveLine;
  tokenLine_ = saveTokenLine;
  return t;
}

int64_t TextCursor::integer(const char* what) {
  std::string_view t = token(what);
  int64_t v;
  if (!parseInteger(t, v)) fail(std::string("expected an integer for ") + what + ", found '" + printableToken(t) + "'");
  return v;
}

int64_t TextCursor::integerInRange(const char* what, int64_t lo, int64_t hi) {
  int64_t v = integer(what);
  if (v < lo || v > hi)
    fail(std::string(what) + " " + std::to_string(v) + " is out of range [" + std::to_string(lo) + ", " +
         std::to_string(hi) + "]");
  return v;
}

double TextCursor::real(const char* what) {
  std::string_view t = token(what);
  double v;
  if (!parseReal(t, v)) fail(std::string("expected a number for ") + what + ", found '" + printableToken(t) + "'");
  return v;
}

double TextCursor::finiteReal(const char* what) {
  double v = real(what);
  if (!std::isfinite(v)) fail(std::string(what) + " is not finite");
  return v;
}

void TextCursor::expect(std::string_view keyword) {
  std::string kw(keyword);
  std::string_view t = token(kw.c_str());
  if (t != keyword) fail("expected '" + kw + "', found '" + printableToken(t) + "'");
}

bool TextCursor::atLineEnd() {
  size_t p = pos_;
  while (p < text_.size() && text_[p] != '\n' && isSpace(text_[p])) ++p;
  return p >= text_.size() || text_[p] == '\n' || (comment_ && text_[p] == comment_);
}

std::string_view TextCursor::restOfLine() {
  while (pos_ < text_.size() && text_[pos_] != '\n' && isSpace(text_[pos_])) ++pos_;
  tokenLine_ = line_;
  size_t start = pos_;
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  std::string_view s = text_.substr(start, pos_ - start);
  if (comment_) s = s.substr(0, s.find(comment_));
  while (!s.empty() && isSpace(s.back())) s.remove_suffix(1);
  if (pos_ < text_.size()) {
    ++pos_;
    ++line_;
  }
  return s;
}

int64_t TextCursor::count(const char* what, int64_t minBytesEach) {
  int64_t n = integer(what);
  if (n < 0) fail(std::string(what) + " " + std::to_string(n) + " is negative");
  int64_t remaining = static_cast<int64_t>(text_.size() - pos_);
  if (minBytesEach > 0 && n > remaining / minBytesEach)
    fail(std::string(what) + " " + std::to_string(n) + " cannot fit in the " + std::to_string(remaining) +
         " bytes left in the file (truncated?)");
  return n;
}

void TextCursor::seek(size_t pos) {
  if (pos > text_.size()) fail("internal: seek past end of file");
  if (pos < pos_) {
    pos_ = 0;
    line_ = 1;
  }
  for (; pos_ < pos; ++pos_)
    if (text_[pos_] == '\n') ++line_;
  tokenLine_ = line_;
}

std::string TextCursor::where() const { return file_ + ":" + std::to_string(tokenLine_); }

void TextCursor::fail(const std::string& message) const { throw MeshError(where() + ": " + message); }

} // namespace quiver
