#include "verdict.hpp"

#include "mechanism.hpp"
#include "statics.hpp"

#include <limits>

namespace contact::limit {

CollapseResult judge_failed_step(const ddm::ContactSystem& system, const fem::LoadPoint& at, const std::string& what,
                                 const std::function<bool()>& cancelled) {
  CollapseResult out;
  out.analysed = true;
  out.verdict = "solver_failed";
  const RigidBlocks blocks = rigid_blocks(system);
  const std::vector<Resultant> none(blocks.bodies.size(), Resultant::Zero());
  const std::vector<Resultant> loads = load_resultants(system, blocks, at);
  const StaticsAnswer statics = largest_multiplier(blocks, none, loads, cancelled);
  switch (statics.status) {
    case StaticsAnswer::Status::bounded:
      out.statics_bound = statics.multiplier;
      if (statics.multiplier < 1 - 1e-9) {
        out.verdict = "no_equilibrium";
        out.mechanism = describe_mechanism(system, blocks, statics.velocity);
        out.mechanism.source = "statics";
        out.statics_mechanism = out.mechanism;
        out.words =
            "no equilibrium by statics: the bodies as rigid blocks, with no-tension joints and their "
            "friction, carry at most " +
            shown(100 * statics.multiplier) + " % of " + what +
            " where the step stopped, whatever the solver (a collapse, or a modelling mistake: a missing "
            "contact or support, a load the wrong way); mechanism: " +
            (out.mechanism.words.empty() ? std::string("none found") : out.mechanism.words);
      } else {
        out.words = "statics does not explain it: the bodies as rigid blocks with associated friction carry " + what +
                    " (up to " + shown(statics.multiplier) +
                    " times), so either the solver failed (smaller load steps may help) or the non-associated "
                    "friction of the solve fails below that bound";
      }
      break;
    case StaticsAnswer::Status::unbounded:
      out.statics_bound = std::numeric_limits<double>::infinity();
      out.words = "statics does not explain it: the bodies as rigid blocks carry any multiple of " + what +
                  " (they press the joints shut), so the solver failed";
      break;
    case StaticsAnswer::Status::infeasible:
      out.verdict = "no_equilibrium";
      out.words = "no equilibrium by statics: the bodies as rigid blocks carry none of " + what;
      break;
    case StaticsAnswer::Status::failed:  // the LP library, or a cancel
      out.words = statics.message == "cancelled" ? "the statics' verdict was cancelled" : statics.message;
      break;
  }
  return out;
}

}  // namespace contact::limit
