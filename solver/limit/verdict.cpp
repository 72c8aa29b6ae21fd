#include "verdict.hpp"

#include "elastic_mechanism.hpp"
#include "mechanism.hpp"
#include "statics.hpp"

#include <limits>

namespace contact::limit {

namespace {

// What statics leaves open when the blocks carry the loads: without friction the elastic bodies carry them too, so
// the solver failed; with Coulomb friction, which does not dilate, the elastic joints can give way below the
// associated bound as well.
std::string open_cause(const ddm::ContactSystem& system) {
  return system.has_friction() ? "so either the solver failed (smaller load steps may help) or the joints' Coulomb "
                                 "friction, which does not dilate, gives way below the associated bound (a collapse "
                                 "analysis brackets that load)"
                               : "so the solver failed";
}

// Where on the load path a point is: "96.88 % of load step 2".
std::string position(const fem::LoadPoint& p) {
  return shown(100 * p.t) + " % of load step " + std::to_string(p.step + 1);
}

// A failed step where statics carries the loads: the mechanism the elastic states that held last show, if any passes
// its check (the loads' increment from the last held state to `at` doing positive work on it).
bool judge_by_the_elastic_states(const ddm::ContactSystem& system, const RigidBlocks& blocks, const fem::LoadPoint& at,
                                 const ddm::HeldPath& path, const std::string& carried, CollapseResult& out) {
  if (!system.has_friction() || path.before.empty() || path.last.u.empty()) return false;
  const std::vector<Resultant> to = load_resultants(system, blocks, at);
  std::vector<Resultant> increment = load_resultants(system, blocks, path.last_state.load);
  for (size_t a = 0; a < increment.size(); ++a) increment[a] = to[a] - increment[a];
  const Step held = ddm::step_of(system, path.last, path.last_state);
  ElasticMechanism elastic = elastic_mechanism(system, blocks, path.before, path.last.u, held, increment);
  if (!elastic.admissible) return false;
  out.verdict = "collapse";  // (held and failed stay unset: a plain job has no multiplier; the words say where)
  out.mechanism = std::move(elastic.mechanism);
  out.words = "a collapse: the states that held last (the last at " + position(path.last_state.load) +
              ", the solve failed at " + position(at) +
              ") show a mechanism on which the loads' increment does work, checked admissible (no joint overlaps, "
              "the sliding joints slide against their friction): " +
              out.mechanism.words + "; " + carried +
              ", so it is the joints' Coulomb friction, which does not dilate, that gives way below the associated "
              "bound (a collapse analysis, \"collapse\": {} with the growing loads \"live\", brackets the load)";
  return true;
}

}  // namespace

CollapseResult judge_failed_step(const ddm::ContactSystem& system, const fem::LoadPoint& at, const std::string& what,
                                 const std::function<bool()>& cancelled, const ddm::HeldPath* path) {
  CollapseResult out;
  out.analysed = true;
  out.verdict = "solver_failed";
  const RigidBlocks blocks = rigid_blocks(system);
  const std::vector<Resultant> none(blocks.bodies.size(), Resultant::Zero());
  const std::vector<Resultant> loads = load_resultants(system, blocks, at);
  const StaticsAnswer statics = largest_multiplier(blocks, none, loads, cancelled);
  std::string carried;  // what statics carries, where it carries the loads
  switch (statics.status) {
    case StaticsAnswer::Status::bounded:
      out.statics_bound = statics.multiplier;
      out.statics_mechanism = describe_mechanism(system, blocks, statics.velocity);
      out.statics_mechanism.source = "statics";
      if (statics.multiplier < 1 - 1e-9) {
        out.verdict = "no_equilibrium";
        out.mechanism = out.statics_mechanism;
        out.words =
            "no equilibrium by statics: the bodies as rigid blocks, with no-tension joints and their "
            "friction, carry at most " +
            shown(100 * statics.multiplier) + " % of " + what +
            " where the step stopped, whatever the solver (a collapse, or a modelling mistake: a missing "
            "contact or support, a load the wrong way); mechanism: " +
            (out.mechanism.words.empty() ? std::string("none found") : out.mechanism.words);
        return out;
      }
      carried = "the bodies as rigid blocks with associated friction carry " + what + " (up to " +
                shown(statics.multiplier) + " times)";
      break;
    case StaticsAnswer::Status::unbounded:
      out.statics_bound = std::numeric_limits<double>::infinity();
      carried = "the bodies as rigid blocks" + std::string(system.has_friction() ? " with associated friction" : "") +
                " carry any multiple of " + what + " (they press the joints shut)";
      break;
    case StaticsAnswer::Status::infeasible:
      out.verdict = "no_equilibrium";
      out.words = "no equilibrium by statics: the bodies as rigid blocks carry none of " + what;
      return out;
    case StaticsAnswer::Status::failed:  // the LP library, or a cancel
      out.words = statics.message == "cancelled" ? "the statics' verdict was cancelled" : statics.message;
      return out;
  }
  // (no cancel check here: the fit is a collective call on MPI ranks, and cheap)
  if (!path || !judge_by_the_elastic_states(system, blocks, at, *path, carried, out))
    out.words = "statics does not explain it: " + carried + ", " + open_cause(system);
  return out;
}

}  // namespace contact::limit
