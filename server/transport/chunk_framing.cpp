#include "transport/chunk_framing.hpp"

namespace contactd {

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

bool ChunkFraming::fail(std::string why) {
  state_ = State::broken;
  error_ = std::move(why);
  return false;
}

bool ChunkFraming::feed(const char* data, std::size_t size) {
  for (std::size_t k = 0; k < size; ++k) {
    const char c = data[k];
    switch (state_) {
      case State::done:
        return true;
      case State::broken:
        return false;
      case State::size_start:
        if (hex_value(c) < 0)
          return fail("a chunk size must be hexadecimal digits (RFC 9112 7.1), not a line starting with '" +
                      std::string(1, c >= 0x20 && c < 0x7f ? c : '?') + "'");
        remaining_ = static_cast<std::uint64_t>(hex_value(c));
        digits_ = 1;
        state_ = State::size;
        break;
      case State::size:
        if (hex_value(c) >= 0) {
          if (++digits_ > 16) return fail("a chunk size of more than 16 hexadecimal digits");
          remaining_ = remaining_ * 16 + static_cast<std::uint64_t>(hex_value(c));
        } else if (c == ';' || c == ' ' || c == '\t') {
          state_ = State::extension;
        } else if (c == '\r') {
          state_ = State::size_lf;
        } else {
          return fail("a chunk size line with something other than hexadecimal digits and extensions");
        }
        break;
      case State::extension:
        if (c == '\r') state_ = State::size_lf;
        break;
      case State::size_lf:
        if (c != '\n') return fail("a chunk size line not ended by CRLF");
        state_ = remaining_ == 0 ? State::trailer_start : State::data;
        break;
      case State::data: {
        // The chunk's bytes: skipped in one go.
        const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(remaining_, size - k));
        remaining_ -= take;
        k += take - 1;
        if (remaining_ == 0) state_ = State::data_cr;
        break;
      }
      case State::data_cr:
        if (c != '\r') return fail("a chunk's data longer than its size (no CRLF after it)");
        state_ = State::data_lf;
        break;
      case State::data_lf:
        if (c != '\n') return fail("a chunk's data not followed by CRLF");
        state_ = State::size_start;
        break;
      case State::trailer_start:
        state_ = c == '\r' ? State::final_lf : State::trailer;
        break;
      case State::trailer:
        if (c == '\r') state_ = State::trailer_lf;
        break;
      case State::trailer_lf:
        if (c != '\n') return fail("a trailer field line not ended by CRLF");
        state_ = State::trailer_start;
        break;
      case State::final_lf:
        if (c != '\n') return fail("the chunked body's last line not ended by CRLF");
        state_ = State::done;
        break;
    }
  }
  return state_ != State::broken;
}

}  // namespace contactd
