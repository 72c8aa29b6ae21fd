#include "common/public_message.hpp"

#include <cctype>

namespace contactd {

std::string public_message(const std::string& text, const std::string& data_dir) {
  std::string out;
  for (std::size_t k = 0; k < text.size();) {
    if (!data_dir.empty() && text.compare(k, data_dir.size(), data_dir) == 0) {
      out += "<data-dir>";
      k += data_dir.size();
      continue;
    }
    if (text[k] == '0' && k + 1 < text.size() && (text[k + 1] == 'x' || text[k + 1] == 'X')) {
      std::size_t e = k + 2;
      while (e < text.size() && std::isxdigit(static_cast<unsigned char>(text[e]))) ++e;
      if (e - k - 2 >= 6) {  // an address, not a small constant
        out += "0x...";
        k = e;
        continue;
      }
    }
    out += text[k++];
  }
  return out;
}

}  // namespace contactd
