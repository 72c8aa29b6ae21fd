// The request head (request line and header fields, RFC 9112 section 2) as the connection gate sees it before
// any HTTP thread does: is it complete, within the limits, and free of what a request head must never contain?
// A pure function of the bytes received so far, so it can be asked again after every read.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace contactd {

struct HeadLimits {
  std::size_t max_head_bytes = 16 * 1024;  // request line + header fields + the empty line (431 beyond)
  std::size_t max_request_line = 4096;     // (414 beyond)
  // One header field line (431 beyond): httplib reads a line of at most 8,192 bytes with its CRLF and fails a longer
  // one only after its read timeout, with 400; refused here first, at once and with the right status.
  std::size_t max_header_line = 8000;
  std::size_t max_header_fields = 64;  // (431 beyond)
};

struct HeadCheck {
  enum class Verdict { incomplete, complete, refused };
  Verdict verdict = Verdict::incomplete;
  std::size_t skip = 0;      // empty lines before the request line (RFC 9112 2.2: ignored)
  std::size_t head_end = 0;  // complete: bytes of the head from the start of the buffer, skip and "\r\n\r\n" included
  bool probe = false;        // complete: GET or HEAD of /healthz or /readyz (served by the probe threads)
  int status = 0;            // refused: 400, 414 or 431
  std::string detail;        // refused: what is wrong, for the problem document
};

// Checks `received` (the bytes read so far on a connection, starting at a request). Refuses: a bare CR or LF (every
// line must end in CRLF), a control character or DEL in the request line or a field (NUL included; HTAB is allowed
// in field values), obs-fold (a line starting with a space), a field line without a name and colon or with a
// space before the colon, and anything over the limits. Says `incomplete` until the empty line arrives.
HeadCheck check_head(std::string_view received, const HeadLimits& limits);

// A complete head's Range field lines with a byte position of 19 digits or more get 999999999999999999 (10^18 - 1)
// there instead; returns the head's new length. httplib parses Range before any handler runs, with stoll, and
// answers 416 to a position past 2^63 - 1 where RFC 9110 (14.1.2) clamps a last position to the file's end (206);
// 10^18 - 1 is past the end of any file this server keeps, as a first position (416) and as a last one (clamped),
// so the answer is the same as for the number given (http/range.cpp parses it).
std::size_t shorten_range_positions(std::string& buffer, std::size_t head_end);

}  // namespace contactd
