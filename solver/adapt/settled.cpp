#include "settled.hpp"

#include "../contact_extent.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace contact::adapt {

namespace {

// A pair's nodal values where it carries them: a node another pair of its group carries (status 5) lists that
// pair's values and belongs to that pair's zones (as StepSummary's extent counts it).
Eigen::VectorXd carried(const PairField& p, const Eigen::VectorXd& values) {
  Eigen::VectorXd out = values;
  for (Eigen::Index j = 0; j < out.size() && j < p.status.size(); ++j)
    if (p.status[j] == 5 || !std::isfinite(out[j])) out[j] = 0.0;
  return out;
}

// The distance between two arc lengths, round the loop where the edge is closed.
double along(double a, double b, double loop) {
  const double d = std::abs(a - b);
  return loop > 0.0 ? std::min(d, loop - d) : d;
}

double width(double begin, double end, double loop) {
  const double w = end - begin;
  return w < 0.0 && loop > 0.0 ? w + loop : w;
}

// How far a zone's ends moved, relative to `scale`: 0 where neither step has the zone, 1 where one has.
double zone_change(bool now, double b1, double e1, bool before, double b0, double e0, double loop, double scale) {
  if (!now && !before) return 0.0;
  if (now != before || !(scale > 0.0)) return 1.0;
  return std::max(along(b1, b0, loop), along(e1, e0, loop)) / scale;
}

}  // namespace

AnswerReading read_answer(const Step& step) {
  AnswerReading r;
  for (const auto& b : step.bodies) r.unknowns += 2.0 * b.mesh.num_nodes();
  for (const PairField& p : step.pairs) {
    PairReading q;
    q.force = p.force;
    q.tangential = p.tangential_force;
    q.loop = slave_loop_length(step, p);
    const Eigen::VectorXd pressure = carried(p, p.pressure);
    if (pressure.size() > 0) q.peak = std::max(0.0, pressure.maxCoeff());
    const ContactExtent zone = contact_extent(p.arc_length, pressure, q.loop);
    q.contact = zone.any;
    q.begin = zone.begin;
    q.end = zone.end;
    if (p.stick.size() == p.arc_length.size() && p.stick.size() > 0) {
      // The stick zone from its first and last sticking node: a constant "pressure" is not extrapolated.
      const ContactExtent stick = contact_extent(p.arc_length, carried(p, p.stick.cast<double>()), q.loop);
      q.stick = stick.any;
      q.stick_begin = stick.begin;
      q.stick_end = stick.end;
    }
    r.pairs.push_back(q);
  }
  return r;
}

double AnswerChanges::largest() const { return std::max({force, peak, extent, stick, tangential}); }

AnswerChanges answer_changes(const std::vector<AnswerReading>& readings, size_t k) {
  AnswerChanges c;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.force = c.peak = c.extent = c.stick = c.tangential = nan;
  if (k >= readings.size()) return c;
  const AnswerReading& now = readings[k];
  for (size_t j = k; j-- > 0;)
    if (readings[j].unknowns <= 0.5 * now.unknowns) {
      c.compared_with = static_cast<int>(j);
      break;
    }
  if (c.compared_with < 0) return c;
  const AnswerReading& before = readings[static_cast<size_t>(c.compared_with)];
  double force = 0.0, peak = 0.0, tangential = 0.0;  // the scales: the largest pair's
  for (const auto* r : {&now, &before})
    for (const PairReading& p : r->pairs) {
      force = std::max(force, std::abs(p.force));
      peak = std::max(peak, p.peak);
      tangential = std::max(tangential, std::abs(p.tangential));
    }
  const auto relative = [](double a, double b, double scale) { return scale > 0.0 ? std::abs(a - b) / scale : 0.0; };
  c.force = c.peak = c.extent = c.stick = c.tangential = 0.0;
  for (size_t i = 0; i < now.pairs.size() && i < before.pairs.size(); ++i) {
    const PairReading &p = now.pairs[i], &q = before.pairs[i];
    c.force = std::max(c.force, relative(p.force, q.force, force));
    c.peak = std::max(c.peak, relative(p.peak, q.peak, peak));
    c.tangential = std::max(c.tangential, relative(p.tangential, q.tangential, tangential));
    const double scale =
        std::max(p.contact ? width(p.begin, p.end, p.loop) : 0.0, q.contact ? width(q.begin, q.end, q.loop) : 0.0);
    c.extent = std::max(c.extent, zone_change(p.contact, p.begin, p.end, q.contact, q.begin, q.end, p.loop, scale));
    c.stick = std::max(
        c.stick, zone_change(p.stick, p.stick_begin, p.stick_end, q.stick, q.stick_begin, q.stick_end, p.loop, scale));
  }
  return c;
}

std::string answer_settled(const std::vector<AnswerReading>& readings, size_t k, double tolerance) {
  if (tolerance <= 0.0 || k < 1) return "";
  const AnswerChanges now = answer_changes(readings, k), before = answer_changes(readings, k - 1);
  if (now.compared_with < 0 || before.compared_with < 0) return "";
  if (!(now.largest() < tolerance) || !(before.largest() < tolerance)) return "";
  bool friction = false;
  for (const PairReading& p : readings[k].pairs) friction = friction || p.stick || p.tangential != 0.0;
  std::ostringstream os;
  os.precision(2);
  os << "adaptive: stopped after " << k << " refinement steps: the answer settled: against step " << now.compared_with
     << " (at most half the unknowns) the contact force changed by " << 100 * now.force << " %, the peak pressure by "
     << 100 * now.peak << " %, the contact zone's ends by " << 100 * now.extent << " % of its width";
  if (friction)
    os << ", the stick zone's ends by " << 100 * now.stick << " % and the tangential force by " << 100 * now.tangential
       << " %";
  os << "; step " << k - 1 << " against step " << before.compared_with << " by at most " << 100 * before.largest()
     << " %; all below stop_tolerance = " << 100 * tolerance << " %";
  return os.str();
}

}  // namespace contact::adapt
