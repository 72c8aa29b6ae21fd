#include "fixed_point.hpp"

#include "../linalg/anderson.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <utility>

namespace contact::ddm {

namespace {

Eigen::VectorXd stacked_zone_normals(const ContactSystem& system, const Displacements& u) {
  std::vector<Eigen::VectorXd> parts(u.size());
  Eigen::Index n = 0;
  for (size_t a = 0; a < u.size(); ++a) {
    parts[a] = system.zone_normals(a, u[a]);
    n += parts[a].size();
  }
  Eigen::VectorXd out(n);
  Eigen::Index at = 0;
  for (const auto& p : parts) {
    out.segment(at, p.size()) = p;
    at += p.size();
  }
  return out;
}

// a + s * b, body by body.
Displacements axpy(const Displacements& a, double s, const Displacements& b) {
  Displacements out(a.size());
  for (size_t i = 0; i < a.size(); ++i) out[i] = a[i] + s * b[i];
  return out;
}

Displacements difference(const Displacements& a, const Displacements& b) { return axpy(a, -1.0, b); }

std::string format(const char* fmt, double a, double b = 0, double c = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

}  // namespace

Pressures linear_pressures(const ContactSystem& system, const Displacements& du) {
  Pressures dz(system.pairs().size());
  for (size_t k = 0; k < dz.size(); ++k) {
    const auto& pair = system.pairs()[k];
    const Eigen::VectorXd dg =
        pair.Gm * du[static_cast<size_t>(pair.master_body)] - pair.Gs * du[static_cast<size_t>(pair.slave_body)];
    dz[k] = -dg.cwiseQuotient(pair.area) / pair.theta;
  }
  return dz;
}

Displacements NeumannMap::apply(const Displacements& u) {
  return system_.solve_bodies(system_.contact_loads(u, state_), state_.load);
}

Displacements NeumannMap::linear_response(const Displacements& du) {
  const Displacements loads = system_.loads_from_pressures(linear_pressures(system_, du));
  Displacements out(loads.size());
  runner_.run_bodies(
      loads.size(), [&](size_t a) { out[a] = system_.body(a).solve_homogeneous(loads[a]); }, share_vectors(out));
  return out;
}

Displacements initial_iterate(const ContactSystem& system, const RunFrame& frame, int& solves) {
  if (frame.warm_start()) return *frame.warm_start();
  if (frame.settings().initial_guess == InitialGuess::elastic_layer) {
    solves += 2;
    return system.elastic_layer_guess(frame.state().load);
  }
  Displacements u(system.n_bodies());
  for (size_t a = 0; a < u.size(); ++a) u[a] = Eigen::VectorXd::Zero(system.body(a).n_dofs());
  return u;
}

double estimate_spectral_radius(const ContactSystem& system, BodyMap& map, int iterations, int& solves) {
  // Start from a random interface perturbation pushed once through the map (so it lies in its range).
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Displacements v(system.n_bodies());
  for (size_t a = 0; a < v.size(); ++a) {
    v[a] = Eigen::VectorXd(system.body(a).n_dofs());
    for (Eigen::Index i = 0; i < v[a].size(); ++i) v[a][i] = unit(rng);
  }
  v = map.linear_response(v);
  ++solves;
  double rho = 0.0;
  for (int it = 0; it < iterations; ++it) {
    const double norm_v = stacked_zone_normals(system, v).norm();
    if (!(norm_v > 0)) return 0.0;
    for (auto& x : v) x /= norm_v;
    Displacements w = map.linear_response(v);
    ++solves;
    const double previous = rho;
    rho = stacked_zone_normals(system, w).norm();
    v = std::move(w);
    if (it > 2 && std::abs(rho - previous) <= 1e-2 * rho) break;  // gamma needs no more than two digits
  }
  return rho;
}

namespace {

// The map's image of the current iterate and how far it moved: the interface residual r (contact-zone normal
// displacements), its relative norm, and the whole-body difference R = u~ - u.
struct Image {
  Eigen::VectorXd r;
  double residual = 0.0;
  Displacements R;
};

// One run of the relaxed fixed point: the iterate, the relaxation with its safeguards (gamma backing off, Anderson
// restarts) and the record of residuals the stop tests read. run() is the loop; each member below is one phase.
class FixedPointIteration {
 public:
  FixedPointIteration(const ContactSystem& system, RunFrame& frame, BodyMap& map, Displacements u)
      : system_(system),
        settings_(frame.settings()),
        frame_(frame),
        map_(map),
        n_(system.n_bodies()),
        out_(frame.outcome()),
        gamma_(settings_.gamma),
        anderson_requested_(settings_.acceleration == Acceleration::anderson),
        anderson_(anderson_requested_),
        u_(std::move(u)),
        zone_(stacked_zone_normals(system, u_)),
        zone_per_body_(n_),
        history_(static_cast<size_t>(std::max(1, settings_.anderson_depth))),
        best_u_(u_) {
    for (size_t a = 0; a < n_; ++a) zone_per_body_[a] = system.zone_normals(a, u_[a]);
  }

  // Builds the frame's outcome.
  void run() {
    choose_gamma();
    for (int k = 1; k <= settings_.max_iterations; ++k) {
      if (frame_.stop_requested()) {
        out_.stop_reason = StopReason::cancelled;
        out_.message = "cancelled";
        break;
      }
      const Image image = apply_map();
      std::string note = std::move(pending_note_);
      pending_note_.clear();
      record_progress(k, image.residual);
      const double paper = advance(next_iterate(k, image, note));
      report(k, paper, image.residual, note);
      if (test_for_stop(k, paper, image.residual)) break;
    }
    if (anderson_requested_ && !anderson_)
      out_.message += " (Anderson acceleration was abandoned for plain relaxation)";
    out_.u = std::move(u_);
    out_.gamma = gamma_;
    out_.subdomain_solves = solves_;
  }

 private:
  static constexpr int max_backoffs = 8;
  static constexpr int stagnation_window = 100;

  // gamma "auto": the eigenvalues of the relaxed map are 1 - gamma (1 - lambda) for F's eigenvalues lambda in
  // [-rho, rho']; gamma = 2 / (2 + rho) balances the stiffest and the slowest modes. 0.9 of it covers the
  // estimate's error.
  void choose_gamma() {
    if (!settings_.gamma_auto) return;
    const double rho = estimate_spectral_radius(system_, map_, 12, solves_);
    gamma_ = std::min(1.0, 1.8 / (2.0 + rho));
    pending_note_ = format("gamma auto: spectral radius %.4g of the interface map, gamma = %.4g", rho, gamma_);
  }

  // u~ = F(u) (one solve per body) and the residual it leaves.
  Image apply_map() {
    const Displacements u_tilde = map_.apply(u_);
    ++solves_;
    const Eigen::VectorXd zone_tilde = stacked_zone_normals(system_, u_tilde);
    Image image;
    image.r = zone_tilde - zone_;
    const double scale = std::max(zone_.norm(), zone_tilde.norm());
    image.residual = scale > 0 ? image.r.norm() / scale : 0.0;
    image.R = difference(u_tilde, u_);
    return image;
  }

  // Progress is a 0.1 % improvement on the residual at the last marked best (not on the running minimum, which a
  // slow steady decrease would move every step without ever counting as progress).
  void record_progress(int k, double residual) {
    if (residual < 0.999 * marked_best_) {
      best_iteration_ = k;
      marked_best_ = residual;
      best_u_ = u_;
    }
    growth_ = residual > last_residual_ ? growth_ + 1 : 0;
    last_residual_ = residual;
    smallest_residual_ = std::min(smallest_residual_, residual);
  }

  // The next iterate: backed off if the residual grows or stalls under gamma "auto", else Anderson-mixed or the
  // plain relaxation of paper (17).
  Displacements next_iterate(int k, const Image& image, std::string& note) {
    // Anderson residuals are not monotone (its own restart handles overshoots), so under it only a large
    // growth counts.
    const double residual = image.residual;
    const bool growing = !std::isfinite(residual) || (anderson_ ? residual > 100.0 * smallest_residual_
                                                                : growth_ >= 3 && residual > 1.5 * smallest_residual_);
    const bool stalled = k - best_iteration_ >= stagnation_window / 2;
    if (settings_.gamma_auto && backoffs_ < max_backoffs && (growing || stalled))
      return back_off(k, growing, residual, note);
    if (anderson_) return mix(image, note);
    return axpy(u_, gamma_, image.R);  // paper (17)
  }

  // Back off: a smaller gamma from the best iterate, history forgotten. A stall counts too: the penalty switching
  // points on and off can hold a too-large gamma in a cycle without any growth.
  Displacements back_off(int k, bool growing, double residual, std::string& note) {
    gamma_ *= 0.5;
    ++backoffs_;
    note = format(growing ? "gamma reduced to %.4g: the residual grew from %.3g to %.3g"
                          : "gamma reduced to %.4g: no progress below %.3g (now %.3g)",
                  gamma_, smallest_residual_, residual);
    best_iteration_ = k;
    history_.clear();
    previous_u_.clear();
    growth_ = 0;
    return best_u_;
  }

  // Anderson mixing of the relaxed update: min || r - dr c || by QR; columns that make it ill-conditioned are
  // dropped (oldest first).
  Displacements mix(const Image& image, std::string& note) {
    if (!previous_u_.empty())
      history_.push(image.r - previous_r_, {difference(u_, previous_u_), difference(image.R, previous_R_)});
    previous_u_ = u_;
    previous_R_ = image.R;
    previous_r_ = image.r;
    Displacements next = axpy(u_, gamma_, image.R);
    history_.mix(image.r, [&](double c, const std::pair<Displacements, Displacements>& d) {
      for (size_t a = 0; a < n_; ++a) next[a] -= c * (d.first[a] + gamma_ * d.second[a]);
    });
    // Safeguard: an accelerated residual ten times the best restarts the history from the best iterate; four
    // restarts in a row without a 10 % improvement of the best in between fall back to plain relaxation.
    if (image.residual > 10.0 * smallest_residual_ && !history_.empty()) {
      failed_restarts_ = smallest_residual_ < 0.9 * best_at_restart_ ? 0 : failed_restarts_ + 1;
      best_at_restart_ = smallest_residual_;
      note = "Anderson restarted (residual " + format("%.3g", image.residual) + " above ten times the best)";
      if (failed_restarts_ >= 4) {
        anderson_ = false;
        note = "Anderson acceleration abandoned after 4 restarts without progress: plain relaxation";
      }
      history_.clear();
      previous_u_.clear();
      next = axpy(best_u_, gamma_, difference(map_.apply(best_u_), best_u_));
      ++solves_;
    }
    return next;
  }

  // u <- next; returns the paper's criterion: the largest relative change of a body's contact-zone displacements.
  double advance(Displacements next) {
    double paper = 0.0;
    for (size_t a = 0; a < n_; ++a) {
      const Eigen::VectorXd z_new = system_.zone_normals(a, next[a]);
      paper = std::max(paper, relative_change(z_new, zone_per_body_[a]));
      zone_per_body_[a] = z_new;
    }
    u_ = std::move(next);
    zone_ = stacked_zone_normals(system_, u_);
    return paper;
  }

  void report(int k, double paper, double residual, const std::string& note) {
    IterationReport rep = system_.report(k, u_, frame_.state(), active_);
    rep.paper_criterion = paper;
    rep.fixed_point_residual = residual;
    rep.gamma = gamma_;
    rep.note = note;
    frame_.report(std::move(rep));
    out_.iterations = k;
  }

  // Converged, stagnating, diverging (fixed gamma) or out of iterations: sets the outcome's stop; true to stop now.
  bool test_for_stop(int k, double paper, double residual) {
    const double measure = settings_.criterion == Criterion::paper ? paper : residual;
    if (measure <= settings_.tolerance) {
      out_.converged = true;
      out_.stop_reason = StopReason::converged;
      std::ostringstream os;
      os << (settings_.criterion == Criterion::paper ? "paper's criterion " : "fixed-point residual ") << measure
         << " <= " << settings_.tolerance;
      out_.message = os.str();
      return true;
    }
    if (k - best_iteration_ >= stagnation_window) {
      // A relaxation above the stability bound does not always blow up: the penalty switching contact on and
      // off can lock it into a cycle (seen with gamma = 1 on seed_layers).
      std::ostringstream os;
      os << "the iteration stagnates: the fixed-point residual has not fallen below " << smallest_residual_
         << " (reached at iteration " << best_iteration_ << ") in " << stagnation_window << " iterations";
      if (smallest_residual_ > 1e-6)
        os << "; gamma = " << gamma_ << " is probably above the stability bound: reduce it";
      out_.stop_reason = StopReason::stagnation;
      out_.message = os.str();
      return true;
    }
    if (!settings_.gamma_auto &&
        (!std::isfinite(residual) || (k > 5 && residual > 1e3 * smallest_residual_ && residual > 1.0))) {
      std::ostringstream os;
      os << "the iteration diverges: the fixed-point residual grew from " << smallest_residual_ << " to " << residual
         << " at iteration " << k << "; reduce gamma (now " << gamma_ << ") or use gamma \"auto\"";
      out_.stop_reason = StopReason::error;
      out_.message = os.str();
      return true;
    }
    if (k == settings_.max_iterations) {
      out_.stop_reason = StopReason::max_iterations;
      std::ostringstream os;
      os << "max_iterations = " << k << " reached; fixed-point residual " << residual << ", paper's criterion "
         << paper;
      out_.message = os.str();
    }
    return false;
  }

  const ContactSystem& system_;
  const SolverSettings& settings_;
  RunFrame& frame_;
  BodyMap& map_;
  const size_t n_;
  MethodOutcome& out_;  // the frame's
  int solves_ = 0;
  double gamma_;
  std::string pending_note_;  // for the first report: how gamma was chosen
  const bool anderson_requested_;
  bool anderson_;                          // false once Anderson was abandoned for plain relaxation
  std::vector<std::vector<char>> active_;  // per pair, the contact nodes in contact at the last report
  Displacements u_;
  Eigen::VectorXd zone_;                        // u's contact-zone normal displacements, all bodies stacked
  std::vector<Eigen::VectorXd> zone_per_body_;  // the same per body
  // Anderson history: iterate and residual differences (full bodies) and interface-residual differences.
  linalg::AndersonHistory<std::pair<Displacements, Displacements>> history_;
  Displacements previous_u_, previous_R_;
  Eigen::VectorXd previous_r_;
  int failed_restarts_ = 0, growth_ = 0, backoffs_ = 0;
  double smallest_residual_ = std::numeric_limits<double>::infinity();
  double last_residual_ = std::numeric_limits<double>::infinity();
  double best_at_restart_ = std::numeric_limits<double>::infinity();
  Displacements best_u_;
  int best_iteration_ = 0;
  double marked_best_ = std::numeric_limits<double>::infinity();  // the residual at best_iteration_
};

}  // namespace

void run_fixed_point(const ContactSystem& system, RunFrame& frame, BodyMap& map, Displacements u) {
  FixedPointIteration(system, frame, map, std::move(u)).run();
}

}  // namespace contact::ddm
