#include "contact/result.hpp"

namespace contact {

const char* to_string(StopReason r) {
  switch (r) {
    case StopReason::converged:
      return "converged";
    case StopReason::max_iterations:
      return "max_iterations";
    case StopReason::stagnation:
      return "stagnation";
    case StopReason::cancelled:
      return "cancelled";
    case StopReason::error:
      return "error";
  }
  return "error";
}

const char* to_string(Measure m) {
  switch (m) {
    case Measure::fixed_point:
      return "fixed_point";
    case Measure::complementarity:
      return "complementarity";
    case Measure::gradient:
      return "gradient";
  }
  return "fixed_point";
}

}  // namespace contact
