#include "transport/request_head.hpp"

#include <cctype>

namespace contactd {

namespace {

HeadCheck refuse(int status, std::string detail) {
  HeadCheck c;
  c.verdict = HeadCheck::Verdict::refused;
  c.status = status;
  c.detail = std::move(detail);
  return c;
}

// RFC 9110 5.6.2: the characters of a token (a field name, a method).
bool is_tchar(unsigned char c) {
  if ((c >= '0' && c <= '9') || (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z')) return true;
  for (char t : std::string_view("!#$%&'*+-.^_`|~"))
    if (c == static_cast<unsigned char>(t)) return true;
  return false;
}

// A control character (NUL included) or DEL; HTAB only where `tab_ok`.
bool is_control(unsigned char c, bool tab_ok) { return (c < 0x20 && !(tab_ok && c == '\t')) || c == 0x7f; }

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

}  // namespace

HeadCheck check_head(std::string_view received, const HeadLimits& limits) {
  std::size_t pos = 0;
  // Empty lines before the request line are ignored (a client's stray CRLF after a previous body).
  while (received.size() - pos >= 2 && received[pos] == '\r' && received[pos + 1] == '\n' && pos < 64) pos += 2;
  const std::size_t skip = pos;
  std::size_t fields = 0;
  bool first = true;
  std::string_view request_line;
  while (true) {
    // One line: [pos, eol) followed by CRLF.
    std::size_t eol = pos;
    while (eol < received.size() && received[eol] != '\r' && received[eol] != '\n') ++eol;
    const std::size_t line_length = eol - pos;
    if (first && line_length > limits.max_request_line)
      return refuse(414, "the request line is longer than " + std::to_string(limits.max_request_line) + " bytes");
    if (eol - skip > limits.max_head_bytes)
      return refuse(431, "the request head is larger than " + std::to_string(limits.max_head_bytes) + " bytes");
    if (!first && line_length > limits.max_header_line)
      return refuse(431, "a header field line is longer than " + std::to_string(limits.max_header_line) + " bytes");
    const std::string_view line = received.substr(pos, line_length);
    // Characters: checked as they arrive, so that a NUL is refused at once, not when the line ends.
    for (std::size_t k = 0; k < line.size(); ++k) {
      const auto c = static_cast<unsigned char>(line[k]);
      if (is_control(c, !first))
        return refuse(400, std::string(c == 0 ? "a NUL byte" : "a control character") + " in the request " +
                               (first ? "line" : "header fields"));
    }
    if (eol == received.size()) return {};  // the line is not complete yet
    if (received[eol] == '\n') return refuse(400, "a bare LF in the request head: lines must end with CRLF");
    if (eol + 1 == received.size()) return {};  // CR received, LF not yet
    if (received[eol + 1] != '\n') return refuse(400, "a bare CR in the request head: lines must end with CRLF");
    const std::size_t next = eol + 2;
    if (first) {
      if (line.empty()) return refuse(400, "the request line is empty");
      request_line = line;
      first = false;
    } else if (line.empty()) {
      HeadCheck done;
      done.verdict = HeadCheck::Verdict::complete;
      done.skip = skip;
      done.head_end = next;
      done.probe = starts_with(request_line, "GET /healthz ") || starts_with(request_line, "GET /readyz ") ||
                   starts_with(request_line, "HEAD /healthz ") || starts_with(request_line, "HEAD /readyz ");
      return done;
    } else {
      if (++fields > limits.max_header_fields)
        return refuse(431, "more than " + std::to_string(limits.max_header_fields) + " header fields");
      if (line[0] == ' ' || line[0] == '\t')
        return refuse(400, "a header field line starts with whitespace (obsolete line folding is not accepted)");
      std::size_t k = 0;
      while (k < line.size() && is_tchar(static_cast<unsigned char>(line[k]))) ++k;
      if (k == 0 || k == line.size() || line[k] != ':')
        return refuse(400, "a header field line is not 'name: value' (no whitespace before the colon)");
    }
    pos = next;
  }
}

std::size_t shorten_range_positions(std::string& buffer, std::size_t head_end) {
  static const std::string kLargest = "999999999999999999";
  std::size_t pos = buffer.find("\r\n");  // past the request line
  while (pos != std::string::npos && pos + 2 < head_end) {
    const std::size_t start = pos + 2, end = buffer.find("\r\n", start);
    if (end == std::string::npos || end > head_end) break;
    std::string line = buffer.substr(start, end - start);
    bool range = line.size() > 6;
    for (std::size_t k = 0; range && k < 6; ++k)
      range = std::tolower(static_cast<unsigned char>(line[k])) == "range:"[k];
    if (range) {
      std::string shortened;
      for (std::size_t k = 0; k < line.size();) {
        std::size_t digits = k;
        while (digits < line.size() && line[digits] >= '0' && line[digits] <= '9') ++digits;
        if (digits == k) {
          shortened += line[k++];
          continue;
        }
        shortened += digits - k >= 19 ? kLargest : line.substr(k, digits - k);
        k = digits;
      }
      buffer.replace(start, line.size(), shortened);
      head_end = head_end + shortened.size() - line.size();
      pos = start + shortened.size();
      continue;
    }
    pos = end;
  }
  return head_end;
}

}  // namespace contactd
