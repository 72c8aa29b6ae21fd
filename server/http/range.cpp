#include "http/range.hpp"

#include <cctype>
#include <optional>

namespace contactd {

namespace {

// Digits only; nullopt for anything else, "" included. A number past 2^64 - 1 saturates there: RFC 9110 (14.1.2)
// puts no bound on a position, and a last position past the file is clamped to its end (bytes=0-99999999999999999999
// is the whole file as 206), a first one past it is unsatisfiable either way.
std::optional<std::uint64_t> number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  constexpr std::uint64_t kMax = UINT64_MAX;
  std::uint64_t value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return std::nullopt;
    const auto digit = static_cast<std::uint64_t>(c - '0');
    value = value > (kMax - digit) / 10 ? kMax : value * 10 + digit;
  }
  return value;
}

std::string trimmed(const std::string& s) {
  std::size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t')) --e;
  return s.substr(b, e - b);
}

}  // namespace

ByteRange parse_range(const std::string& header, std::uint64_t size) {
  ByteRange whole;
  const std::string value = trimmed(header);
  if (value.size() < 6 || value.compare(0, 6, "bytes=") != 0 || value.find(',') != std::string::npos) return whole;
  const std::string spec = trimmed(value.substr(6));
  const auto dash = spec.find('-');
  if (dash == std::string::npos) return whole;
  const std::string a = trimmed(spec.substr(0, dash)), b = trimmed(spec.substr(dash + 1));
  ByteRange r;
  if (a.empty()) {  // suffix: the last b bytes
    const auto suffix = number(b);
    if (!suffix) return whole;
    if (*suffix == 0 || size == 0) {
      r.kind = ByteRange::Kind::unsatisfiable;
      return r;
    }
    r.kind = ByteRange::Kind::partial;
    r.length = *suffix < size ? *suffix : size;
    r.first = size - r.length;
    return r;
  }
  const auto first = number(a);
  if (!first) return whole;
  std::uint64_t last = size == 0 ? 0 : size - 1;
  if (!b.empty()) {
    const auto given = number(b);
    if (!given || *given < *first) return whole;  // invalid: ignored
    if (*given < last) last = *given;
  }
  if (*first >= size) {
    r.kind = ByteRange::Kind::unsatisfiable;
    return r;
  }
  r.kind = ByteRange::Kind::partial;
  r.first = *first;
  r.length = last - *first + 1;
  return r;
}

std::string content_range(const ByteRange& range, std::uint64_t size) {
  if (range.kind != ByteRange::Kind::partial) return "bytes */" + std::to_string(size);
  return "bytes " + std::to_string(range.first) + "-" + std::to_string(range.first + range.length - 1) + "/" +
         std::to_string(size);
}

}  // namespace contactd
