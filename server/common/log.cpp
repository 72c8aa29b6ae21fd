#include "common/log.hpp"

#include "common/time.hpp"

#include <cstdio>

namespace contactd {

void log_line(const std::string& text) {
  const std::string line = now_iso8601() + " contactd: " + text + "\n";
  std::fwrite(line.data(), 1, line.size(), stderr);  // one call per line: lines from threads do not interleave
  std::fflush(stderr);
}

}  // namespace contactd
