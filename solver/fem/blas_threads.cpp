#include "blas_threads.hpp"

#include <dlfcn.h>

#include <mutex>

namespace contact::fem {

bool limit_blas_threads() {
  static std::once_flag once;
  static bool limited = false;
  std::call_once(once, [] {
    using SetThreads = void (*)(int);
    if (auto f = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) {
      f(1);
      limited = true;
    }
  });
  return limited;
}

}  // namespace contact::fem
