#include "file_util.hpp"

#include "contact/files.hpp"

#include <unistd.h>

#include <stdexcept>

namespace contact::io::detail {

void write_atomically(const std::string& path, const std::string& what,
                      const std::function<void(const std::string& tmp)>& write) {
  try {
    replace_file_atomically(path, write, /*durable=*/true);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot write " + what + " '" + path + "': " + e.what());
  }
}

std::string host_name() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "";
  return name;
}

}  // namespace contact::io::detail
