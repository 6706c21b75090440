#pragma once
/// \file parse_util.h
/// Internal: bounds-checked scanning of text lines and binary fields, shared by the readers.

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "core/errors.h"

namespace remesh::io {

[[noreturn]] inline void fail(const std::string& message) { throw MeshError(message); }

/// Splits text into lines ('\n', with a trailing '\r' removed); counts lines from 1.
class LineScanner {
 public:
  explicit LineScanner(std::string_view text) : text_(text) {}
  /// Next line into `line`; false at the end.
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    line = text_.substr(pos_, end - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end + 1;
    ++line_;
    return true;
  }
  std::size_t line_number() const { return line_; }  ///< of the last line returned
  std::size_t position() const { return pos_ < text_.size() ? pos_ : text_.size(); }
  std::size_t remaining() const { return text_.size() - position(); }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_ = 0;
};

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// Is `tok` the lower-case `word` in any case ("SOLID" is "solid": ASCII STL keywords, which some
/// exporters write in upper case)?
inline bool is_word_in_any_case(std::string_view tok, std::string_view word) {
  if (tok.size() != word.size()) return false;
  for (std::size_t i = 0; i < tok.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(tok[i])) != word[i]) return false;
  return true;
}

/// Cuts the next whitespace-separated token off the front of `s`; false if none is left.
inline bool next_token(std::string_view& s, std::string_view& token) {
  std::size_t i = 0;
  while (i < s.size() && is_space(s[i])) ++i;
  if (i == s.size()) {
    s = {};
    return false;
  }
  std::size_t j = i;
  while (j < s.size() && !is_space(s[j])) ++j;
  token = s.substr(i, j - i);
  s.remove_prefix(j);
  return true;
}

/// For a number from_chars() parsed whole but found out of range: true if its magnitude is above
/// the largest double, false if below the smallest. The decimal exponent of its first significant
/// digit decides: out of range, it is above 300 or below -300. `t` has no leading '+'.
inline bool overflows(std::string_view t) {
  if (!t.empty() && t[0] == '-') t.remove_prefix(1);
  const std::size_t e = std::min(t.find_first_of("eE"), t.size());
  const std::string_view digits = t.substr(0, e);
  const std::size_t point = std::min(digits.find('.'), digits.size());
  const std::size_t first = digits.find_first_not_of("0.");
  if (first == std::string_view::npos) return false;  // zero: never out of range
  long long exponent = first < point ? static_cast<long long>(point - first - 1)
                                     : -static_cast<long long>(first - point);
  long long written = 0;  // the exponent after 'e', saturated: its digits may be many
  std::size_t i = e + 1;
  const bool negative = i < t.size() && t[i] == '-';
  if (i < t.size() && (t[i] == '-' || t[i] == '+')) ++i;
  for (; i < t.size(); ++i) written = std::min(written * 10 + (t[i] - '0'), 1'000'000'000LL);
  exponent += negative ? -written : written;
  return exponent > 0;
}

/// Parses a whole token as a double (accepts a leading '+', "nan", "inf"); false if malformed or
/// beyond the largest double (about 1.8e308: too_large_note() says so). A number closer to 0 than
/// any double reads as the nearest one, as strtod() gives: a denormal, or 0 with its sign.
inline bool parse_double(std::string_view t, double& v) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  if (t.empty()) return false;
  auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (p != t.data() + t.size()) return false;
  // from_chars() returns denormals itself and reports out of range what rounds to 0 or infinity.
  if (ec == std::errc::result_out_of_range && !overflows(t)) {
    v = t[0] == '-' ? -0.0 : 0.0;
    return true;
  }
  return ec == std::errc();
}

/// For the message of a token parse_double() refused: " (too large: ...)" if it is a number beyond
/// the largest double, else "".
inline std::string too_large_note(std::string_view t) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  double v = 0;
  auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (p != t.data() + t.size() || ec != std::errc::result_out_of_range || !overflows(t)) return "";
  return " (too large: the largest double is about 1.8e308)";
}

/// Parses a whole token as a signed integer; false if malformed or out of int64 range.
inline bool parse_int(std::string_view t, std::int64_t& v) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  if (t.empty()) return false;
  auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return ec == std::errc() && p == t.data() + t.size();
}

/// Quotes a token for an error message, cut to 40 characters and without control bytes.
inline std::string quote(std::string_view t) {
  std::string s = "'";
  for (std::size_t i = 0; i < t.size() && i < 40; ++i) {
    unsigned char c = static_cast<unsigned char>(t[i]);
    s += (c >= 32 && c < 127) ? static_cast<char>(c) : '?';
  }
  if (t.size() > 40) s += "...";
  return s + "'";
}

/// Reads fixed-size little- or big-endian fields from bytes, checking bounds.
class ByteReader {
 public:
  ByteReader(std::string_view bytes, std::size_t pos = 0) : bytes_(bytes), pos_(pos) {}
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return pos_ <= bytes_.size() ? bytes_.size() - pos_ : 0; }
  bool has(std::size_t n) const { return n <= remaining(); }
  void skip(std::size_t n) { pos_ += n; }

  /// Reads one T (arithmetic) in the given byte order; the caller must have checked has(sizeof(T)).
  template <class T>
  T read(bool big_endian) {
    static_assert(std::is_arithmetic_v<T>);
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    bool swap = big_endian != (std::endian::native == std::endian::big);
    if (swap)
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    T v;
    std::memcpy(&v, raw, sizeof(T));
    return v;
  }

 private:
  std::string_view bytes_;
  std::size_t pos_;
};

/// Appends the bytes of `v` in little-endian order.
template <class T>
void put_le(std::string& out, T v) {
  static_assert(std::is_arithmetic_v<T>);
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::big)
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
  out.append(reinterpret_cast<const char*>(raw), sizeof(T));
}

}  // namespace remesh::io
