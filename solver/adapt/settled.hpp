// The adaptive loop's default stop (issue 50; docs/job-format.md, "When the loop stops"): the run stops where the
// answer a user reads has settled, not where an error indicator stops changing.
//
// What is read of a step, per pair: the normal force, the peak pressure, the contact zone's ends along the slave
// edge (contact_extent.hpp) and, with friction, the stick zone's ends and the tangential force. A step's changes
// are taken against the last earlier step with at most half its unknowns, not against the step before: the
// goal-oriented marking adds a tenth to a half of the unknowns a step, and over so small a step a quantity the
// step did not refine for hardly moves however wrong it is (the two-cylinder example's step 3 changed each by
// less than 0.5 % with the pressure 8.9 % wrong). Against a mesh with half the unknowns the change is about the
// coarser step's error (for errors falling like 1 / unknowns), the size of what is still to come. The rule holds
// when the changes are below the tolerance at two steps in a row: one quiet step among loud ones (the paper's
// test with the contact marking: 0.25 % at 1.7 % error, then 0.95 %) does not stop the run.
//
// Scales: a pair's force and tangential force against the largest pair's (a pair that barely touches does not hold
// the run), its peak pressure against the largest peak, its zones' ends against the width of its contact zone.
#pragma once

#include "contact/result.hpp"

#include <string>
#include <vector>

namespace contact::adapt {

struct PairReading {
  double force = 0.0, peak = 0.0, tangential = 0.0;
  double begin = 0.0, end = 0.0;              // the contact zone (arc lengths; both 0 without contact)
  double stick_begin = 0.0, stick_end = 0.0;  // the stick zone: its first and last sticking node
  double loop = 0.0;                          // the slave edge's length where it is closed (ends compared round it)
  bool contact = false, stick = false;
};

struct AnswerReading {
  double unknowns = 0.0;  // 2 x nodes over all bodies
  std::vector<PairReading> pairs;
};

AnswerReading read_answer(const Step& step);

// The largest relative change over the pairs of each quantity (0 for a quantity no pair has; 1 where a zone
// appears or vanishes); NaN throughout when there is no step to compare with.
struct AnswerChanges {
  int compared_with = -1;  // the index of the step compared with
  double force = 0.0, peak = 0.0, extent = 0.0, stick = 0.0, tangential = 0.0;
  double largest() const;
};

// Step k's changes against the last step before it with at most half its unknowns.
AnswerChanges answer_changes(const std::vector<AnswerReading>& readings, size_t k);

// The stop test: the changes of step k and of step k - 1 each below `tolerance` (0: never). The message when it
// holds, else "".
std::string answer_settled(const std::vector<AnswerReading>& readings, size_t k, double tolerance);

}  // namespace contact::adapt
