// How the model checks' messages write their figures: three significant digits for a size or a ratio, six for a
// point (where a user finds it in the drawing).
#pragma once

#include <Eigen/Core>

#include <sstream>
#include <string>

namespace contact::check {

inline std::string number(double x) {
  std::ostringstream os;
  os.precision(3);
  os << x;
  return os.str();
}

inline std::string point(const Eigen::Vector2d& p) {
  std::ostringstream os;
  os.precision(6);
  os << "(" << p.x() << ", " << p.y() << ")";
  return os.str();
}

}  // namespace contact::check
