#include "friction_newton.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

namespace contact::linalg {

namespace {

constexpr int kWatchdog = 4;          // full steps without a new low of the merit before the line search
constexpr double kSufficient = 1e-4;  // Armijo's constant
constexpr double kGrowth = 1e4;       // a full step may raise the merit at most this far above its lowest value
constexpr int kMaxBacktracks = 30;    // step lengths down to 2^-30

double trial_bound(const FrictionRow& r, const Eigen::VectorXd& lambda, const Eigen::VectorXd& h,
                   const Eigen::VectorXd& c) {
  return r.coulomb ? r.mu * std::max(0.0, lambda[r.normal] - c[r.normal] * h[r.normal]) : r.bound;
}

// A set as a key for the visited set: the active flags, then each row's state and sign.
std::vector<signed char> key_of(const FrictionSets& s) {
  std::vector<signed char> key(s.active.begin(), s.active.end());
  for (size_t t = 0; t < s.state.size(); ++t)
    key.push_back(static_cast<signed char>(3 * static_cast<int>(s.state[t]) + s.sign[t]));
  return key;
}

FrictionIterate along(const FrictionIterate& x, const FrictionIterate& y, double t) {
  FrictionIterate out;
  out.lambda = x.lambda + t * (y.lambda - x.lambda);
  out.h = x.h + t * (y.h - x.h);
  out.other = x.other.size() == y.other.size() ? Eigen::VectorXd(x.other + t * (y.other - x.other)) : y.other;
  return out;
}

// One change from `from` to `to`: a normal unknown (row < 0) or a friction row, and how far past its switching
// point the prediction lies (the larger, the surer).
struct Change {
  Eigen::Index normal = -1;
  long row = -1;
  double distance = 0.0;
};

std::vector<Change> changes_between(const FrictionSets& from, const FrictionSets& to, const FrictionIterate& x,
                                    const FrictionNewtonProblem& problem) {
  std::vector<Change> out;
  for (size_t j = 0; j < from.active.size(); ++j)
    if (from.active[j] != to.active[j] && !problem.mask[j]) {
      const auto i = static_cast<Eigen::Index>(j);
      out.push_back({i, -1, std::abs(x.lambda[i] - problem.c[i] * x.h[i]) * std::sqrt(1.0 / problem.c[i])});
    }
  for (size_t t = 0; t < from.state.size(); ++t) {
    const auto& r = problem.rows[t];
    const auto normal = static_cast<size_t>(r.normal);
    if (r.coulomb && from.active[normal] != to.active[normal]) continue;  // follows its normal's change
    if (from.state[t] != to.state[t] || from.sign[t] != to.sign[t]) {
      const double trial = x.lambda[r.tangential] - problem.c[r.tangential] * x.h[r.tangential];
      out.push_back({-1, static_cast<long>(t),
                     std::abs(std::abs(trial) - trial_bound(r, x.lambda, x.h, problem.c)) *
                         std::sqrt(1.0 / problem.c[r.tangential])});
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const Change& a, const Change& b) { return a.distance > b.distance; });
  return out;
}

// The first `count` changes applied; a normal's change takes its Coulomb rows' states along (a row is open exactly
// where its normal is inactive).
FrictionSets apply_changes(FrictionSets sets, const FrictionSets& to, const std::vector<Change>& changes, size_t count,
                           const std::vector<FrictionRow>& rows) {
  std::vector<char> normal_changed(sets.active.size(), 0);
  for (size_t k = 0; k < count; ++k) {
    const Change& ch = changes[k];
    if (ch.normal >= 0) {
      sets.active[static_cast<size_t>(ch.normal)] = to.active[static_cast<size_t>(ch.normal)];
      normal_changed[static_cast<size_t>(ch.normal)] = 1;
    } else {
      sets.state[static_cast<size_t>(ch.row)] = to.state[static_cast<size_t>(ch.row)];
      sets.sign[static_cast<size_t>(ch.row)] = to.sign[static_cast<size_t>(ch.row)];
    }
  }
  for (size_t t = 0; t < rows.size(); ++t)
    if (rows[t].coulomb && normal_changed[static_cast<size_t>(rows[t].normal)]) {
      sets.state[t] = to.state[t];
      sets.sign[t] = to.sign[t];
    }
  return sets;
}

class Newton {
 public:
  Newton(const FrictionNewtonProblem& problem, const FrictionNewtonSettings& settings,
         const FrictionStepCallback& on_step)
      : p_(problem), s_(settings), on_step_(on_step) {}

  FrictionNewtonResult run(FrictionSets start);

 private:
  double merit(const FrictionIterate& x) const { return friction_merit(x.lambda, x.h, p_.c, p_.rows, p_.mask); }
  bool solve(const FrictionSets& sets, FrictionIterate& out) {
    if (p_.cancelled && p_.cancelled()) {
      cancelled_ = true;
      return false;
    }
    ++result_.report.iterations;
    return p_.solve(parametrize(sets, p_.rows, p_.mask), out);
  }
  // The system of `target`, or, where it is singular, of a set part of the way from the current sets to it.
  bool solve_towards(FrictionSets& target, FrictionIterate& out);
  // The Newton point n from x: taken whole, or damped by the line search.
  FrictionIterate globalise(const FrictionIterate& n, bool visited, bool& damped);
  void record_merit(double theta);
  // The stall rule (FrictionNewtonSettings::stall_steps) on the lowest merits after each accepted step.
  bool stalled() const;

  const FrictionNewtonProblem& p_;
  const FrictionNewtonSettings& s_;
  const FrictionStepCallback& on_step_;
  FrictionNewtonResult result_;
  FrictionIterate x_;
  bool have_x_ = false;
  double best_merit_ = std::numeric_limits<double>::infinity();
  std::vector<double> best_history_;  // best_merit_ after each accepted step
  int steps_since_best_ = 0;
  bool tied_retreat_ = false;
  bool cancelled_ = false;
};

bool Newton::solve_towards(FrictionSets& target, FrictionIterate& out) {
  if (solve(target, out)) return true;
  if (!have_x_ || cancelled_) return false;
  // The most changes (surest first) whose set is solvable, by bisection between the current sets (solvable) and
  // the target (singular).
  const std::vector<Change> changes = changes_between(result_.sets, target, x_, p_);
  size_t lo = 0, hi = changes.size();
  FrictionSets best;
  FrictionIterate best_out;
  while (hi - lo > 1 && result_.report.iterations < s_.max_steps && !cancelled_) {
    const size_t mid = lo + (hi - lo) / 2;
    FrictionSets partial = apply_changes(result_.sets, target, changes, mid, p_.rows);
    FrictionIterate candidate;
    if (solve(partial, candidate)) {
      lo = mid;
      best = std::move(partial);
      best_out = std::move(candidate);
    } else {
      hi = mid;
    }
  }
  if (lo > 0) {
    target = std::move(best);
    out = std::move(best_out);
    return true;
  }
  if (tied_retreat_ || cancelled_ || result_.report.iterations >= s_.max_steps) return false;
  // Not even one change is solvable: once, the target's contact with every node in it sticking.
  tied_retreat_ = true;
  FrictionSets tied = target;
  stick_where_in_contact(tied, p_.rows);
  if (!solve(tied, out)) return false;
  target = std::move(tied);
  return true;
}

FrictionIterate Newton::globalise(const FrictionIterate& n, bool visited, bool& damped) {
  damped = false;
  if (!have_x_) return n;
  // Full steps while the sets are new, the merit has reached a new low within the last few steps and the step does
  // not throw it far above that low.
  const double theta_x = merit(x_), theta_n = merit(n);
  if (!visited && steps_since_best_ < kWatchdog && theta_n <= kGrowth * best_merit_) return n;
  if (theta_n <= (1 - 2 * kSufficient) * theta_x) return n;  // the full step decreases the merit enough
  double t = 1.0;
  for (int k = 0; k < kMaxBacktracks; ++k) {
    t *= 0.5;
    FrictionIterate y = along(x_, n, t);
    if (merit(y) <= (1 - 2 * kSufficient * t) * theta_x) {
      damped = true;
      return y;
    }
  }
  return n;  // no decrease along d (rounding at the solution): the full step
}

void Newton::record_merit(double theta) {
  if (theta < best_merit_) {
    best_merit_ = theta;
    steps_since_best_ = 0;
  } else {
    ++steps_since_best_;
  }
  best_history_.push_back(best_merit_);
}

bool Newton::stalled() const {
  const size_t k = best_history_.size(), window = static_cast<size_t>(std::max(0, s_.stall_steps));
  return window > 0 && k > window && best_history_[k - 1] > s_.stall_fall * best_history_[k - 1 - window];
}

FrictionNewtonResult Newton::run(FrictionSets sets) {
  std::set<std::vector<signed char>> visited;
  while (result_.report.iterations < s_.max_steps) {
    FrictionIterate n;
    if (!solve_towards(sets, n)) {
      result_.report.stop = cancelled_                                  ? SolveStop::cancelled
                            : result_.report.iterations >= s_.max_steps ? SolveStop::max_iterations
                                                                        : SolveStop::singular;
      if (result_.report.stop == SolveStop::singular) result_.unsolvable = sets;
      if (have_x_) result_.iterate = x_;
      return result_;
    }
    const bool seen = !visited.insert(key_of(sets)).second;
    bool damped = false;
    FrictionIterate x = globalise(n, seen, damped);
    result_.damped_steps += damped;
    result_.sets = sets;
    ++result_.accepted_steps;
    x_ = std::move(x);
    have_x_ = true;
    record_merit(merit(x_));
    const FrictionSets next = predict_friction_sets(x_.lambda, x_.h, p_.c, p_.rows, p_.mask);
    ActiveSetStep info;
    info.step = static_cast<int>(result_.report.iterations);
    info.changes = next.changes(sets);
    for (size_t j = 0; j < next.active.size(); ++j) info.active += next.active[j] && !p_.mask[j];
    info.complementarity = friction_complementarity(x_.lambda, x_.h, p_.c, p_.rows, p_.mask);
    result_.iterate = x_;
    if (on_step_ && on_step_(x_, info)) {
      result_.report.stop = SolveStop::cancelled;
      return result_;
    }
    if ((!damped && next == sets) || info.complementarity <= s_.tolerance) {
      result_.report.stop = SolveStop::converged;
      return result_;
    }
    if (stalled()) {
      result_.stalled = true;
      result_.report.stop = SolveStop::max_iterations;
      return result_;
    }
    sets = next;
  }
  result_.report.stop = SolveStop::max_iterations;
  return result_;
}

}  // namespace

double friction_merit(const Eigen::VectorXd& lambda, const Eigen::VectorXd& h, const Eigen::VectorXd& c,
                      const std::vector<FrictionRow>& rows, const std::vector<char>& mask) {
  return complementarity_squared(lambda, h, c, rows, mask, CoulombBound::trial);
}

FrictionNewtonResult friction_newton(const FrictionNewtonProblem& problem, FrictionSets start,
                                     const FrictionNewtonSettings& settings, const FrictionStepCallback& on_step) {
  return Newton(problem, settings, on_step).run(std::move(start));
}

}  // namespace contact::linalg
