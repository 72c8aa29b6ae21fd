// The adaptive loop's default stop (adapt/settled.hpp): which step a step is read against, the scales of its
// changes, and the two-in-a-row rule, on readings made up for each case.
#include "adapt/settled.hpp"

#include <gtest/gtest.h>

#include <cmath>

using contact::adapt::answer_changes;
using contact::adapt::answer_settled;
using contact::adapt::AnswerReading;
using contact::adapt::PairReading;

namespace {

AnswerReading reading(double unknowns, std::vector<PairReading> pairs) {
  AnswerReading r;
  r.unknowns = unknowns;
  r.pairs = std::move(pairs);
  return r;
}

PairReading pair(double force, double peak, double begin, double end) {
  PairReading p;
  p.force = force;
  p.peak = peak;
  p.begin = begin;
  p.end = end;
  p.contact = true;
  return p;
}

}  // namespace

TEST(AnswerSettled, EachStepIsReadAgainstTheLastStepWithAtMostHalfItsUnknowns) {
  std::vector<AnswerReading> steps;
  for (const double n : {100.0, 150.0, 210.0, 290.0, 400.0, 590.0})
    steps.push_back(reading(n, {pair(1000.0 + n, 50.0, -1.0, 1.0)}));
  EXPECT_EQ(answer_changes(steps, 0).compared_with, -1);
  EXPECT_EQ(answer_changes(steps, 1).compared_with, -1);
  EXPECT_TRUE(std::isnan(answer_changes(steps, 1).force));
  EXPECT_EQ(answer_changes(steps, 2).compared_with, 0);  // 100 <= 105
  EXPECT_EQ(answer_changes(steps, 3).compared_with, 0);  // 150 > 145
  EXPECT_EQ(answer_changes(steps, 4).compared_with, 1);  // 210 > 200: the last at most half is 150
  EXPECT_EQ(answer_changes(steps, 5).compared_with, 3);
  // The force's change against the larger of the two: (1590 - 1290) / 1590.
  EXPECT_DOUBLE_EQ(answer_changes(steps, 5).force, 300.0 / 1590.0);
  EXPECT_EQ(answer_changes(steps, 5).peak, 0.0);
}

TEST(AnswerSettled, APairThatBarelyTouchesIsMeasuredAgainstTheLargestPair) {
  // Pair 0 carries a thousand times pair 1: pair 1 doubling its force changes the answer by 1/1000.
  const std::vector<AnswerReading> steps = {reading(100, {pair(1000, 50, -1, 1), pair(1, 2, 0, 0.01)}),
                                            reading(200, {pair(1000, 50, -1, 1), pair(2, 2, 0, 0.01)})};
  const auto c = answer_changes(steps, 1);
  EXPECT_DOUBLE_EQ(c.force, 1.0 / 1000.0);
  EXPECT_EQ(c.peak, 0.0);
  EXPECT_EQ(c.extent, 0.0);
}

TEST(AnswerSettled, ZoneEndsAreMeasuredAgainstTheContactZonesWidthRoundALoopAndAZoneThatAppearsIsAWholeChange) {
  // The contact zone [-1, 1] moves its end to 1.02: 0.02 over the width 2.02.
  std::vector<AnswerReading> steps = {reading(100, {pair(10, 5, -1, 1)}), reading(200, {pair(10, 5, -1, 1.02)})};
  EXPECT_NEAR(answer_changes(steps, 1).extent, 0.02 / 2.02, 1e-15);
  // A stick zone where there was none: a whole change; the same stick zone in both: none.
  steps[1].pairs[0].stick = true;
  steps[1].pairs[0].stick_begin = -0.5;
  steps[1].pairs[0].stick_end = 0.5;
  EXPECT_EQ(answer_changes(steps, 1).stick, 1.0);
  steps[0].pairs[0].stick = true;
  steps[0].pairs[0].stick_begin = -0.5;
  steps[0].pairs[0].stick_end = 0.49;
  EXPECT_NEAR(answer_changes(steps, 1).stick, 0.01 / 2.02, 1e-15);
  // On a closed edge of length 10, a zone across its start (begin 9.9, end 0.1: width 0.2) whose begin moves to
  // 0.02 past the start, 0.12 round the loop (not 9.88).
  std::vector<AnswerReading> loop = {reading(100, {pair(10, 5, 9.9, 0.1)}), reading(200, {pair(10, 5, 0.02, 0.1)})};
  for (auto& r : loop) r.pairs[0].loop = 10.0;
  EXPECT_NEAR(answer_changes(loop, 1).extent, 0.12 / 0.2, 1e-12);
}

TEST(AnswerSettled, TheTestHoldsOnlyWhenTwoStepsInARowChangedByLessThanTheTolerance) {
  // Force 1000 at 100 unknowns, then steps of 1.5x the unknowns: each read against the one two before.
  std::vector<AnswerReading> steps;
  const std::vector<double> forces = {1000, 1100, 1003, 1103, 1104, 1105, 1106};
  double n = 100;
  for (const double f : forces) {
    steps.push_back(reading(n, {pair(f, 50, -1, 1)}));
    n *= 1.5;
  }
  // Step 2 against 0: 0.3 %; step 3 against 1: 0.27 %, but step 2's 0.3 % is over 0.28 %: step 3 does not stop.
  EXPECT_NEAR(answer_changes(steps, 2).force, 3.0 / 1003.0, 1e-15);
  EXPECT_NEAR(answer_changes(steps, 3).force, 3.0 / 1103.0, 1e-15);
  EXPECT_EQ(answer_settled(steps, 3, 0.0028), "");
  EXPECT_NE(answer_settled(steps, 3, 0.0031), "");
  // Step 4 against 2 (10 %): loud; steps 5 (against 3: 0.18 %) and 6 (against 4: 0.18 %) settle together.
  EXPECT_EQ(answer_settled(steps, 5, 0.005), "");
  const std::string message = answer_settled(steps, 6, 0.005);
  EXPECT_NE(message.find("stopped after 6 refinement steps: the answer settled: against step 4"), std::string::npos)
      << message;
  EXPECT_EQ(message.find("stick zone"), std::string::npos) << message;  // frictionless: not named
  EXPECT_EQ(answer_settled(steps, 6, 0.0), "");                         // 0: the test is off
}
