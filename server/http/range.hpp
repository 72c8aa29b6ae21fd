// Range requests on a file of known size (RFC 9110 section 14): one byte range is served as 206 with
// Content-Range; a range that starts past the end (or a zero-length suffix) is 416 with "Content-Range: bytes */size";
// several ranges, another unit or a syntax error are ignored (the whole file, 200), as RFC 9110 allows.
#pragma once

#include <cstdint>
#include <string>

namespace contactd {

struct ByteRange {
  enum class Kind { whole, partial, unsatisfiable };
  Kind kind = Kind::whole;
  std::uint64_t first = 0;   // partial: the first byte served
  std::uint64_t length = 0;  // partial: how many bytes
};

// `header` is the Range header's value ("" when absent); `size` the file's size.
ByteRange parse_range(const std::string& header, std::uint64_t size);

// "bytes first-last/size" for a partial range, "bytes */size" for an unsatisfiable one.
std::string content_range(const ByteRange& range, std::uint64_t size);

}  // namespace contactd
