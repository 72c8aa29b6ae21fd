// The framing of a chunked request body (RFC 9112 7.1), checked as its bytes pass to httplib: httplib reads a
// chunk size with strtoul, which takes "-5" for 2^64 - 5 and then waits for that many bytes until its read timeout
// (a 10 s stall before a 400); here a size that is not 1 to 16 hex digits, or a chunk not followed by CRLF, is
// refused the moment it arrives. Only the framing: the extensions and the trailer fields are passed over.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace contactd {

class ChunkFraming {
 public:
  // The next bytes of the body, in order. False once the framing is broken (`error()` says how); after the last
  // chunk and its trailer section, whatever follows (the next pipelined request) is not looked at.
  bool feed(const char* data, std::size_t size);
  bool done() const { return state_ == State::done; }
  const std::string& error() const { return error_; }

 private:
  enum class State {
    size_start,
    size,
    extension,
    size_lf,
    data,
    data_cr,
    data_lf,
    trailer_start,
    trailer,
    trailer_lf,
    final_lf,
    done,
    broken
  };
  bool fail(std::string why);

  State state_ = State::size_start;
  std::uint64_t remaining_ = 0;  // data bytes left in the current chunk
  int digits_ = 0;
  std::string error_;
};

}  // namespace contactd
