// The model checks before the solve: each contact pair's initial gaps as drawn, measured at the slave nodes the pair
// carries, and the warnings for a drawing that does not say what the pair declares (docs/job-format.md, "fit" and
// "Warnings").
//
// Why: the model is linear and small-displacement, contact measured on the drawn geometry. An overlap the user did
// not mean is an interference fit all the same: the solver presses the edges apart with the force the overlap takes,
// before any load (a stone 0.1 mm too long in a wall carried 75 times the joint force of its neighbours). A pair
// open everywhere closes only by a rigid motion, which the linear model takes at face value (a stack drawn 1 cm above
// its support "fell" 1 cm). Neither stops a solve, so both are said before it.
//
// The gap at a node is the pair's own (mortar::PairDiscretization::initial_gap: along the slave's normal to the
// master, on the edges' true curves, plus the analytic gap), so a cylinder drawn on a plane, or two meshes of one
// circle, measure 0 where they touch. Values within 1e-6 of the joint's length (the sixth significant digit of a
// drawing) count as touching.
#pragma once

#include "contact/problem.hpp"

#include <Eigen/Core>

#include <functional>
#include <limits>
#include <vector>

namespace contact::check {

// One pair's initial gaps over the slave nodes it carries (not those opposite no master side, nor those another pair
// of its group carries). Signed: negative where the edges overlap.
struct PairGaps {
  int nodes = 0;        // nodes measured (0: none faces the master; nothing else is set)
  int overlapping = 0;  // nodes overlapping by more than the tolerance
  double min_gap = std::numeric_limits<double>::quiet_NaN(), max_gap = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector2d min_at = Eigen::Vector2d::Zero(), max_at = Eigen::Vector2d::Zero();  // slave node positions
  double length = 0.0;     // the slave edge's length opposite the master (the joint's)
  double size = 0.0;       // the smaller of the two bodies' sizes (their bounding boxes' diagonals)
  double tolerance = 0.0;  // 1e-6 x length: smaller gaps and overlaps count as touching

  double max_overlap() const { return nodes > 0 && min_gap < -tolerance ? -min_gap : 0.0; }
  // Open everywhere: no node within the tolerance, and the gap not the growing gap of a curve drawn touching (the
  // smallest gap more than a tenth of the spread between the smallest and the largest: a block drawn above its
  // support, a pin centred in a larger hole; a cylinder on a plane has a smallest gap far below its spread).
  bool open() const { return nodes > 0 && min_gap > tolerance && min_gap > 0.1 * (max_gap - min_gap); }
};

// Every pair's gaps, in the job's order. `stop` (optional) is polled every 64 pairs: true ends the measuring (the
// pairs left are not measured: nodes 0).
std::vector<PairGaps> measure_initial_gaps(const Problem& problem, const std::function<bool()>& stop = {});

// The warnings for what the gaps say against each pair's fit, at "/contacts/<k>": an overlap a touching or clearance
// pair does not declare, a touching pair open everywhere, an interference pair that does not overlap.
std::vector<Warning> initial_gap_warnings(const Problem& problem, const std::vector<PairGaps>& gaps);

}  // namespace contact::check
