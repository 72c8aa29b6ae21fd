#include "pressure_estimate.hpp"

#include <algorithm>
#include <cmath>

namespace contact::adapt {

namespace {

constexpr int kMaxIterations = 200;
constexpr double kTolerance = 1e-3;  // relative residual of the correction: the estimate's third digit

using ddm::Pressures;

// Rows that carry pressure: the correction lives on them (the open rows' gaps are not closed by the exact
// pressure either).
std::vector<std::vector<char>> active_rows(const Pressures& z) {
  std::vector<std::vector<char>> active(z.size());
  for (size_t k = 0; k < z.size(); ++k) {
    active[k].assign(static_cast<size_t>(z[k].size()), 0);
    for (Eigen::Index r = 0; r < z[k].size(); ++r) active[k][static_cast<size_t>(r)] = z[k][r] > 0.0;
  }
  return active;
}

// The D-weighted inner product over the active rows.
double dot(const ddm::ContactSystem& system, const std::vector<std::vector<char>>& active, const Pressures& a,
           const Pressures& b) {
  double s = 0.0;
  for (size_t k = 0; k < a.size(); ++k)
    for (Eigen::Index r = 0; r < a[k].size(); ++r)
      if (active[k][static_cast<size_t>(r)]) s += system.pairs()[k].D[r] * a[k][r] * b[k][r];
  return s;
}

void axpy(double alpha, const Pressures& x, Pressures& y) {
  for (size_t k = 0; k < y.size(); ++k) y[k] += alpha * x[k];
}

// The FE bodies' contact compliance G: the change of the nodal gaps on the active rows from pressures v (zero on
// the other rows), one solve per body; `free_gaps` are the gaps of the bodies' response to no contact force (both
// under the bodies' loads at `at`, which cancel in the difference).
class Compliance {
 public:
  Compliance(const ddm::ContactSystem& system, const fem::LoadPoint& at, const std::vector<std::vector<char>>& active)
      : system_(system), at_(at), active_(active) {
    ddm::Displacements none(system.n_bodies());
    for (size_t a = 0; a < none.size(); ++a) none[a] = Eigen::VectorXd::Zero(system.body(a).n_dofs());
    free_gaps_ = system.nodal_gaps(system.solve_bodies(none, at_));
  }
  Pressures apply(const Pressures& v) const {
    Pressures g = system_.nodal_gaps(system_.solve_bodies(system_.loads_from_pressures(v), at_));
    for (size_t k = 0; k < g.size(); ++k) {
      g[k] -= free_gaps_[k];
      for (Eigen::Index r = 0; r < g[k].size(); ++r)
        if (!active_[k][static_cast<size_t>(r)]) g[k][r] = 0.0;
    }
    return g;
  }

 private:
  const ddm::ContactSystem& system_;
  const fem::LoadPoint at_;
  const std::vector<std::vector<char>>& active_;
  Pressures free_gaps_;
};

// G dz = rhs on the active rows by conjugate gradients (D-weighted); returns the iterations, -1 if not converged,
// -2 if stopped.
int solve_correction(const ddm::ContactSystem& system, const fem::LoadPoint& at,
                     const std::vector<std::vector<char>>& active, const Pressures& rhs, Pressures& dz,
                     const std::function<bool()>& stop) {
  const Compliance G(system, at, active);
  dz = rhs;
  for (auto& v : dz) v.setZero();
  Pressures r = rhs, p = rhs;
  double rr = dot(system, active, r, r);
  const double small = kTolerance * kTolerance * rr;
  if (rr == 0.0) return 0;
  for (int it = 1; it <= kMaxIterations; ++it) {
    if (stop && stop()) return -2;
    const Pressures Gp = G.apply(p);
    const double pGp = dot(system, active, p, Gp);
    if (!(pGp > 0.0)) return -1;  // not positive on the active rows (a body free to move along them)
    const double alpha = rr / pGp;
    axpy(alpha, p, dz);
    axpy(-alpha, Gp, r);
    const double rr_new = dot(system, active, r, r);
    if (rr_new <= small) return it;
    for (size_t k = 0; k < p.size(); ++k) p[k] = r[k] + (rr_new / rr) * p[k];
    rr = rr_new;
  }
  return -1;
}

// The nodal pressure profile along a pair's slave edge (what the result shows: each slave node's value from the
// rows, piecewise linear in the arc length between nodes).
Eigen::VectorXd nodal_profile(const mortar::PairDiscretization& pair, const Eigen::VectorXd& z) {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(pair.slave_nodes.size()));
  for (size_t j = 0; j < pair.node_from_rows.size(); ++j)
    for (const auto& [row, weight] : pair.node_from_rows[j]) p[static_cast<Eigen::Index>(j)] += weight * z[row];
  return p;
}

// Integral over [a, b] of (m(t) - l(t))^2 with m the square-root model sqrt(max(0, c0 + c1 t)) and l linear
// through (a, la) and (b, lb): Gauss-Legendre on pieces graded towards the model's zero, where it is not smooth.
double squared_misfit(double a, double b, double la, double lb, double c0, double c1) {
  static const double xg[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double wg[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  const auto f = [&](double t) {
    const double m = std::sqrt(std::max(0.0, c0 + c1 * t)), l = la + (lb - la) * (t - a) / (b - a);
    return (m - l) * (m - l);
  };
  const double zero = c1 < 0.0 ? -c0 / c1 : b;  // where the model vanishes
  double sum = 0.0;
  const auto gauss = [&](double lo, double hi) {
    for (int q = 0; q < 4; ++q) sum += 0.5 * (hi - lo) * wg[q] * f(0.5 * (lo + hi) + 0.5 * (hi - lo) * xg[q]);
  };
  const auto graded = [&](double lo, double hi, bool towards_hi) {  // 12 pieces halving towards one end
    double len = hi - lo, pos = towards_hi ? hi : lo;
    for (int piece = 0; piece < 12; ++piece) {
      const double half = piece == 11 ? len : 0.5 * len;
      gauss(towards_hi ? pos - len : pos + len - half, towards_hi ? pos - len + half : pos + len);
      len -= half;
    }
  };
  if (zero > a && zero < b) {
    graded(a, zero, true);
    graded(zero, b, false);
  } else {
    graded(a, b, zero <= a);
  }
  return sum;
}

// The contact edges' share of the error: where the pressure falls to zero at the end of a contact zone it
// falls like the square root of the distance to the edge (a smooth contact: Hertz, the paper's test), which the
// piecewise-linear profile cannot follow and whose position it misses by up to a segment. Each such end (an
// active node i between a node with a larger pressure and an open one) gets the square-root model through
// its last two nodes (p^2 linear in the arc length, as contact_extent.hpp extrapolates the zone's end) and the
// integral of (model - profile)^2 over its last two segments. A zone whose pressure does not fall towards its
// end (a punch's corner) has no such term. The nodes are the multiplier nodes: where the slave is finer than the
// master, its nodes inside a multiplier segment only interpolate the segment's end values (docs/algorithm.md,
// "coarse-grained multipliers"), and the profile's resolution at the edge is the multiplier segment's, not the
// slave's (the two-cylinder example with the steel refined to 1.2e-4 at the edge and the aluminium not: a linear
// tail over five slave segments that the slave's last two segments hardly saw).
// `rows`: the profile's values per row (the pressure, or the tangential slack below).
double edge_error2(const mortar::PairDiscretization& pair, const Eigen::VectorXd& rows, const mesh::Mesh& slave,
                   const mesh::Mesh& master, double thickness, std::vector<PressureEstimate::EdgeShare>& shares) {
  const Eigen::VectorXd all = nodal_profile(pair, rows);
  std::vector<size_t> nodes;  // the multiplier nodes (positions in slave_nodes), each once
  for (const size_t k : pair.multiplier_nodes)
    if (k < pair.slave_nodes.size() && (nodes.empty() || nodes.back() != k)) nodes.push_back(k);
  if (nodes.empty())
    for (size_t k = 0; k < pair.slave_nodes.size(); ++k) nodes.push_back(k);
  const Eigen::Index n = static_cast<Eigen::Index>(nodes.size());
  Eigen::VectorXd p(n);
  for (Eigen::Index j = 0; j < n; ++j) p[j] = all[static_cast<Eigen::Index>(nodes[static_cast<size_t>(j)])];
  const auto neighbour = [&](Eigen::Index j, int step) -> Eigen::Index {
    const Eigen::Index k = j + step;
    if (k >= 0 && k < n) return k;
    return pair.closed ? (k + n) % n : -1;
  };
  const auto distance = [&](Eigen::Index from, Eigen::Index to) {
    const auto at = [&](Eigen::Index j) {
      return pair.node_arc[static_cast<Eigen::Index>(nodes[static_cast<size_t>(j)])];
    };
    double d = std::abs(at(to) - at(from));
    return pair.closed ? std::min(d, pair.loop_length - d) : d;
  };
  double sum = 0.0;
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!(p[j] > 0.0)) continue;
    for (const int step : {1, -1}) {
      const Eigen::Index open = neighbour(j, step), inner = neighbour(j, -step);
      if (open < 0 || inner < 0 || p[open] != 0.0 || !(p[inner] > p[j])) continue;
      const double h1 = distance(inner, j), h2 = distance(j, open);
      if (!(h1 > 0.0) || !(h2 > 0.0)) continue;
      // t from the inner node towards the open one: model^2 = p_j^2 + slope (t - h1).
      const double slope = (p[j] * p[j] - p[inner] * p[inner]) / h1;
      const double c0 = p[j] * p[j] - slope * h1;
      const double e2 = thickness * (squared_misfit(0.0, h1, p[inner], p[j], c0, slope) +
                                     squared_misfit(h1, h1 + h2, p[j], 0.0, c0, slope));
      PressureEstimate::EdgeShare share;
      share.slave_body = pair.slave_body;
      share.master_body = pair.master_body;
      share.at = slave.nodes[static_cast<size_t>(pair.slave_nodes[nodes[static_cast<size_t>(j)]])];
      share.master_at = share.at;  // (a row without master terms: none to find)
      if (const int row = pair.row_of_node[nodes[static_cast<size_t>(j)]]; row >= 0) {
        Eigen::Vector2d centre = Eigen::Vector2d::Zero();
        double weight = 0.0;
        for (mortar::SparseRows::InnerIterator it(pair.M, row); it; ++it) {
          centre += std::abs(it.value()) *
                    master.nodes[static_cast<size_t>(pair.master_nodes[static_cast<size_t>(it.col())])];
          weight += std::abs(it.value());
        }
        if (weight > 0.0) share.master_at = centre / weight;
      }
      share.length = h1 + h2;
      share.relative2 = e2;
      shares.push_back(share);
      sum += e2;
    }
  }
  return sum;
}

// A frictional pair's slack per row: the friction bound less |q| where the row is in contact and sticks, 0 where
// it slips (within 1e-9 of the bound) or is open. In the stick zone it rises from a stick-slip point like a square
// root of the distance (Mindlin: mu p0 (c / a) sqrt(1 - x^2 / c^2) for |x| < c), as the pressure does from a
// contact edge, so edge_error2 on it measures what the piecewise-linear tangential traction misses there.
Eigen::VectorXd slack_rows(const mortar::PairDiscretization& pair, const Eigen::VectorXd& z, const Eigen::VectorXd& q) {
  Eigen::VectorXd s = Eigen::VectorXd::Zero(z.size());
  for (Eigen::Index r = 0; r < z.size() && r < q.size(); ++r) {
    if (!(z[r] > 0.0)) continue;
    const double bound =
        pair.friction.law == FrictionSpec::Law::coulomb ? pair.friction.coefficient * z[r] : pair.friction.bound;
    const double slack = bound - std::abs(q[r]);
    if (slack > 1e-9 * bound) s[r] = slack;
  }
  return s;
}

}  // namespace

PressureEstimate pressure_estimate(const ddm::ContactSystem& system, const fem::LoadPoint& at,
                                   const ddm::Displacements& u, const Pressures& z,
                                   const std::vector<IndicatorResult>& eta, const std::function<bool()>& stop,
                                   const Pressures* q) {
  PressureEstimate out;
  ddm::Displacements ub = u;
  int replaced = 0;
  for (size_t a = 0; a < ub.size() && a < eta.size(); ++a)
    if (eta[a].bem_displacement.size() == u[a].size()) {
      ub[a] = eta[a].bem_displacement;
      ++replaced;
    }
  if (replaced == 0) {
    out.relative = std::nan("");
    out.note = "no pressure estimate: it needs the fem_bem indicator's boundary-element solutions";
    return out;
  }
  const auto active = active_rows(z);
  const double norm2 = dot(system, active, z, z);
  if (!(norm2 > 0.0)) return out;  // no pressure, nothing to be wrong
  // The right-hand side: the gaps the boundary-element bodies leave open (or overlapping) under z.
  const Pressures gF = system.nodal_gaps(u), gB = system.nodal_gaps(ub);
  Pressures rhs(z.size());
  for (size_t k = 0; k < z.size(); ++k) {
    rhs[k] = gF[k] - gB[k];
    for (Eigen::Index r = 0; r < rhs[k].size(); ++r)
      if (!active[k][static_cast<size_t>(r)]) rhs[k][r] = 0.0;
  }
  Pressures dz;
  out.iterations = solve_correction(system, at, active, rhs, dz, stop);
  if (out.iterations < 0) {
    out.relative = std::nan("");
    out.note = out.iterations == -2 ? "no pressure estimate: cancelled"
                                    : "no pressure estimate: the correction's conjugate gradients did not converge";
    out.iterations = kMaxIterations;
    return out;
  }
  const Model& model = system.problem().model;
  const double thickness = model.plane == Plane::stress ? model.thickness : 1.0;  // D is length x thickness
  double edges2 = 0.0, stick_slip2 = 0.0;
  for (size_t k = 0; k < z.size(); ++k) {
    const auto& pair = system.pairs()[k];
    const auto& bodies = system.problem().bodies;
    const mesh::Mesh& slave = bodies[static_cast<size_t>(pair.slave_body)].mesh;
    const mesh::Mesh& master = bodies[static_cast<size_t>(pair.master_body)].mesh;
    edges2 += edge_error2(pair, z[k], slave, master, thickness, out.edge_shares);
    if (q && k < q->size() && pair.has_friction())
      stick_slip2 += edge_error2(pair, slack_rows(pair, z[k], (*q)[k]), slave, master, thickness, out.edge_shares);
  }
  for (auto& share : out.edge_shares) share.relative2 /= norm2;
  out.defect = std::sqrt(dot(system, active, dz, dz) / norm2);
  out.edges = std::sqrt(edges2 / norm2);
  out.stick_slip = std::sqrt(stick_slip2 / norm2);
  out.relative = std::sqrt(out.defect * out.defect + out.edges * out.edges + out.stick_slip * out.stick_slip);
  out.correction = std::move(dz);
  return out;
}

}  // namespace contact::adapt
