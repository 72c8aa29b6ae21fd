#include "pair.hpp"
#include "../common/assert.hpp"

#include "corners.hpp"
#include "dual_basis.hpp"
#include "edge_curves.hpp"
#include "pair_group.hpp"
#include "segments.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>

namespace contact::mortar {

namespace {

std::vector<Eigen::Vector2d> coordinates(const mesh::Mesh& m, const std::vector<int>& nodes) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(nodes.size());
  for (int n : nodes) out.push_back(m.nodes[static_cast<size_t>(n)]);
  return out;
}

double analytic_gap(const GapSpec& spec, const Eigen::Vector2d& x) {
  double d = spec.constant;
  if (spec.parabola_r0) d += *spec.parabola_r0 * (x.x() - spec.parabola_x0) * (x.x() - spec.parabola_x0);
  return d;
}

// Three-point Gauss-Legendre on [0, 1]: exact to degree 5 (the products here are at most cubic).
constexpr std::array<double, 3> kGaussX = {0.1127016653792583, 0.5, 0.8872983346207417};
constexpr std::array<double, 3> kGaussW = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};

}  // namespace

Eigen::VectorXd PairDiscretization::penalty_pressure(const Eigen::VectorXd& g,
                                                     const Eigen::VectorXd* multipliers) const {
  Eigen::VectorXd z(g.size());
  const bool shifted = multipliers && multipliers->size() == g.size();
  for (Eigen::Index r = 0; r < g.size(); ++r) z[r] = std::max(0.0, (shifted ? (*multipliers)[r] : 0.0) - g[r] / theta);
  return z;
}

void PairDiscretization::add_forces(const Eigen::VectorXd& z, Eigen::VectorXd& fs, Eigen::VectorXd& fm) const {
  CONTACT_ASSERT_SIZE(z.size(), n_rows(), "a pair's pressures");
  CONTACT_ASSERT_SIZE(fs.size(), Gs.cols(), "the slave's load");
  CONTACT_ASSERT_SIZE(fm.size(), Gm.cols(), "the master's load");
  fs.noalias() -= Gs.transpose() * z;
  fm.noalias() += Gm.transpose() * z;
}

void PairDiscretization::add_tangential_forces(const Eigen::VectorXd& q, Eigen::VectorXd& fs,
                                               Eigen::VectorXd& fm) const {
  if (!has_friction() || q.size() != n_rows()) return;
  fs.noalias() -= Ts.transpose() * q;
  fm.noalias() += Tm.transpose() * q;
}

Eigen::Vector2d PairDiscretization::tangential_resultant(const Eigen::VectorXd& q) const {
  Eigen::Vector2d out = Eigen::Vector2d::Zero();
  if (!has_friction() || q.size() != Ts.rows()) return out;
  for (int r = 0; r < Ts.outerSize(); ++r)
    for (SparseRows::InnerIterator it(Ts, r); it; ++it) out[it.col() % 2] -= it.value() * q[r];
  return out;
}

Eigen::VectorXi PairDiscretization::sticking(const Eigen::VectorXd& z, const Eigen::VectorXd& q) const {
  Eigen::VectorXi out = Eigen::VectorXi::Zero(n_rows());
  if (!has_friction() || q.size() != n_rows() || z.size() != n_rows()) return out;
  for (Eigen::Index r = 0; r < n_rows(); ++r) {
    const double bound = friction.law == FrictionSpec::Law::coulomb ? friction.coefficient * z[r] : friction.bound;
    // A slipping node sits on the bound: to rounding by the direct solver, to about 1e-7 by the iterative one,
    // whose Coulomb bounds are the previous outer iterate's mu z (1e-8 flagged its slipping nodes near the stick
    // zone's edge as sticking: the Cattaneo-Mindlin stick zone came out 8 % wide); a sticking one inside.
    out[r] = z[r] > 0 && std::abs(q[r]) < bound * (1 - 1e-6) ? 1 : 0;
  }
  return out;
}

Eigen::Vector2d PairDiscretization::resultant(const Eigen::VectorXd& z) const {
  Eigen::Vector2d out = Eigen::Vector2d::Zero();
  if (z.size() != Gs.rows()) return out;
  for (int r = 0; r < Gs.outerSize(); ++r)
    for (SparseRows::InnerIterator it(Gs, r); it; ++it) out[it.col() % 2] -= it.value() * z[r];
  return out;
}

Eigen::VectorXd PairDiscretization::to_nodes(const Eigen::VectorXd& rows, double fill) const {
  Eigen::VectorXd out = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(slave_nodes.size()), fill);
  for (size_t i = 0; i < node_from_rows.size(); ++i) {
    if (node_from_rows[i].empty()) continue;
    double v = 0;
    for (const auto& [r, w] : node_from_rows[i]) v += w * rows[r];
    out[static_cast<Eigen::Index>(i)] = v;
  }
  return out;
}

Eigen::VectorXd PairDiscretization::rows_at_nodes(const Eigen::VectorXd& rows, double fill) const {
  Eigen::VectorXd out = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(slave_nodes.size()), fill);
  for (size_t r = 0; r < node_of_row.size(); ++r) out[node_of_row[r]] = rows[static_cast<Eigen::Index>(r)];
  return out;
}

PenaltyChoice choose_penalty(const Problem& problem, int pair_index) {
  const ContactPair& pair = problem.contacts[static_cast<size_t>(pair_index)];
  const Body& slave = problem.bodies[static_cast<size_t>(pair.slave_body)];
  const Body& master = problem.bodies[static_cast<size_t>(pair.master_body)];
  // Mean outward normal of the master edge, weighted by segment length. A closed master edge has none (its
  // normals turn all the way round and sum to zero): a body's extent is then the smaller of its extents along x
  // and y (a shaft's or a ring's diameter).
  const auto mpts = coordinates(master.mesh, master.mesh.edge_set_nodes(pair.master_edge));
  const bool closed = master.mesh.edge_set_closed(pair.master_edge);
  Eigen::Vector2d n = Eigen::Vector2d::Zero();
  for (size_t i = 0; i + 1 < mpts.size(); ++i)
    if ((mpts[i + 1] - mpts[i]).norm() > 0) n += (mpts[i + 1] - mpts[i]).norm() * outward_normal(mpts[i], mpts[i + 1]);
  if (n.norm() > 0) n.normalize();
  auto extent_along = [](const mesh::Mesh& m, const Eigen::Vector2d& d) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& p : m.nodes) {
      lo = std::min(lo, p.dot(d));
      hi = std::max(hi, p.dot(d));
    }
    return hi - lo;
  };
  auto extent = [&](const mesh::Mesh& m) {
    if (closed) return std::min(extent_along(m, Eigen::Vector2d(1, 0)), extent_along(m, Eigen::Vector2d(0, 1)));
    return extent_along(m, n);
  };
  PenaltyChoice c;
  c.slave_height = extent(slave.mesh);
  c.master_height = extent(master.mesh);
  const double E1 = slave.material.E, E2 = master.material.E;
  c.E_pair = 2 * E1 * E2 / (E1 + E2);
  const PenaltySpec& spec = problem.solver.penalty;
  c.length = spec.length ? *spec.length : std::min(c.slave_height, c.master_height);
  c.theta = spec.theta ? *spec.theta : spec.c * c.length / c.E_pair;
  return c;
}

namespace {

// The multiplier partition: the slave nodes that bound multiplier segments (positions in the slave polyline), the
// first and the last always among them, and the `breaks` (where one slave edge of a group ends and the next
// begins). Where the master is coarser than the slave, consecutive slave segments are grouped until the group is
// as long as the longest master segment opposite, to the nearest slave segment; elsewhere every slave node is a
// multiplier node (the plain dual mortar method).
std::vector<size_t> multiplier_partition(const SegmentMesh& segments, const std::vector<double>& master_length,
                                         const std::vector<size_t>& breaks) {
  const size_t n_segments = segments.slave_length.size();
  std::vector<double> opposite(n_segments, 0.0);  // the longest master segment opposite each slave segment
  for (const auto& s : segments.segments)
    opposite[static_cast<size_t>(s.slave)] =
        std::max(opposite[static_cast<size_t>(s.slave)], master_length[static_cast<size_t>(s.master)]);
  std::vector<size_t> nodes = {0};
  double run = 0, longest = 0;
  for (size_t k = 0; k < n_segments; ++k) {
    run += segments.slave_length[k];
    longest = std::max(longest, opposite[k]);
    // Close the run when one more slave segment would take it further from the master length than it is now.
    const bool at_break = std::find(breaks.begin(), breaks.end(), k + 1) != breaks.end();
    if (k + 1 == n_segments || at_break || run >= longest - 0.5 * segments.slave_length[k]) {
      nodes.push_back(k + 1);
      run = longest = 0;
    }
  }
  return nodes;
}

}  // namespace

namespace {

// discretize_pair in its phases (the mortar segment mesh's geometry first, then the algebra on it):
// cut the slave edge against the master edge, build each multiplier run's dual basis, classify the multiplier
// nodes, number the rows, integrate over the mortar segments, assemble the sparse operators.
class PairBuilder {
 public:
  PairBuilder(const Problem& problem, const ContactIndex& index, int pair_index, double theta)
      : problem_(problem),
        index_(index),
        pair_(problem.contacts[static_cast<size_t>(pair_index)]),
        slave_(problem.bodies[static_cast<size_t>(pair_.slave_body)]),
        master_(problem.bodies[static_cast<size_t>(pair_.master_body)]),
        thickness_(problem.model.plane == Plane::stress ? problem.model.thickness : 1.0),
        pair_index_(pair_index),
        group_(pair_group(problem, pair_index, &index)) {
    d_.name = pair_.name;
    d_.slave_body = pair_.slave_body;
    d_.master_body = pair_.master_body;
    d_.theta = theta;
    d_.friction = pair_.friction;
  }

  PairDiscretization build() {
    cut_segments();
    dual_bases();
    classify_nodes();
    assign_owners();
    number_rows();
    integrate();
    node_gaps();
    assemble_operators();
    close_loop();
    keep_own_edge();
    return std::move(d_);
  }

 private:
  using VectorEntries = std::map<std::pair<int, int>, Eigen::Vector2d>;  // (row, node) -> vector coefficient

  double arc(size_t i) const { return arc_[static_cast<Eigen::Index>(i)]; }

  // An edge's nodes as a polyline: its nodes, and on a closed loop its first node again at the end (the side that
  // closes the loop is then a segment like any other).
  static std::vector<int> polyline(std::vector<int> nodes, bool closed) {
    if (closed && !nodes.empty()) nodes.push_back(nodes.front());
    return nodes;
  }

  // The slave and master nodes, the segment mesh, arc lengths, and which mortar segments lie on each slave segment.
  // The builder works on the group's slave chain (pair_group.hpp: this pair's slave edge, or the edges it chains
  // with) at positions 0 .. n_ - 1, against the group's master chain; on a closed chain position n_ - 1 is position
  // 0 again (close_loop() folds it back once the operators are built), and keep_own_edge() cuts the pair's own
  // slave edge out at the end. Pieces of a slave edge opposite a master edge the group does not pair it with are
  // left out.
  void cut_segments() {
    d_.slave_nodes = group_.slave.nodes;
    d_.master_nodes = group_.master.nodes;
    closed_ = group_.slave.closed;
    poly_ = polyline(d_.slave_nodes, closed_);
    master_poly_ = polyline(d_.master_nodes, group_.master.closed);
    S_ = coordinates(slave_.mesh, poly_);
    const auto Mx = coordinates(master_.mesh, master_poly_);
    n_ = S_.size();
    segments_ = build_segment_mesh(S_, Mx);
    auto& pieces = segments_.segments;
    pieces.erase(std::remove_if(pieces.begin(), pieces.end(), [&](const MortarSegment& s) { return pair_of(s) < 0; }),
                 pieces.end());
    slave_curves_ = EdgeCurves::of_sides(slave_.mesh, poly_, edge_names(group_.slave, poly_.size()));
    master_curves_ = EdgeCurves::of_sides(master_.mesh, master_poly_, edge_names(group_.master, master_poly_.size()));
    const size_t n_segments = n_ < 2 ? 0 : n_ - 1;
    for (size_t j = 0; j + 1 < Mx.size(); ++j) master_length_.push_back((Mx[j + 1] - Mx[j]).norm());
    arc_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_));
    for (size_t k = 1; k < n_; ++k)
      arc_[static_cast<Eigen::Index>(k)] = arc_[static_cast<Eigen::Index>(k) - 1] + (S_[k] - S_[k - 1]).norm();
    on_segment_.assign(n_segments, {});
    for (const auto& s : segments_.segments) {
      on_segment_[static_cast<size_t>(s.slave)].push_back(&s);
      if (pair_of(s) == pair_index_)
        d_.covered_length += (s.xi1 - s.xi0) * segments_.slave_length[static_cast<size_t>(s.slave)];
    }
  }

  // The pair of the group a mortar segment belongs to (by its slave and master edges), or -1.
  int pair_of(const MortarSegment& s) const {
    return group_.pair_of(group_.slave.edge_of_segment(static_cast<size_t>(s.slave)),
                          group_.master.edge_of_segment(static_cast<size_t>(s.master)));
  }

  // The edge name of every segment of a chain's polyline of `points` positions.
  static std::vector<std::string> edge_names(const Chain& chain, size_t points) {
    std::vector<std::string> out;
    for (size_t k = 0; k + 1 < points; ++k) out.push_back(chain.edges[chain.edge_of_segment(k)]);
    return out;
  }

  // Multiplier segments (runs of slave segments between consecutive multiplier nodes), each with its dual basis
  // on its covered part, in the arc-length parameter s of the run.
  void dual_bases() {
    d_.multiplier_nodes = on_segment_.empty() ? std::vector<size_t>{}
                                              : multiplier_partition(segments_, master_length_, group_.slave.start);
    n_runs_ = d_.multiplier_nodes.empty() ? 0 : d_.multiplier_nodes.size() - 1;
    basis_.assign(n_runs_, std::nullopt);
    for (size_t m = 0; m < n_runs_; ++m) {
      const size_t a = d_.multiplier_nodes[m], b = d_.multiplier_nodes[m + 1];
      const double L = arc(b) - arc(a);
      std::vector<std::pair<double, double>> covered;
      for (size_t k = a; k < b; ++k)
        for (const auto* s : on_segment_[k])
          covered.emplace_back((arc(k) + s->xi0 * segments_.slave_length[k] - arc(a)) / L,
                               (arc(k) + s->xi1 * segments_.slave_length[k] - arc(a)) / L);
      if (L > 0) basis_[m] = dual_basis(covered, L);
    }
  }

  // Which multiplier nodes carry a multiplier: covered enough, and not a crosspoint. The other slave nodes lie
  // inside a multiplier segment. On a closed slave edge the start (positions 0 and n_ - 1) lies between the last
  // run and the first, as every other multiplier node between its two runs: a loop has no ends.
  void classify_nodes() {
    d_.status.assign(n_, NodeStatus::inner);
    const auto prescribed = prescribed_components(slave_);
    const auto corners = slave_corners(problem_, index_, pair_, slave_.mesh.edge_set_nodes(pair_.slave_edge));
    for (size_t m = 0; m <= n_runs_ && n_runs_ > 0; ++m) {
      const size_t i = d_.multiplier_nodes[m];
      double support = 0, covered = 0;
      Eigen::Vector2d nu = Eigen::Vector2d::Zero();
      // The runs before and after node i, with node i's end of each (1: the run's last node, 0: its first); on
      // an open edge m - 1 wraps for m = 0 and m is past the last run for m = n_runs_: skipped.
      const bool wraps = closed_ && (m == 0 || m == n_runs_);
      const std::array<std::pair<size_t, int>, 2> runs = {{{wraps ? n_runs_ - 1 : m - 1, 1}, {wraps ? 0 : m, 0}}};
      for (const auto& [run, end] : runs) {
        if (run >= n_runs_) continue;
        const size_t a = d_.multiplier_nodes[run], b = d_.multiplier_nodes[run + 1];
        support += 0.5 * (arc(b) - arc(a));
        if (!basis_[run]) continue;
        const double Dk = basis_[run]->D[end];
        covered += Dk;
        const size_t k = end == 0 ? a : b - 1;  // the slave segment next to node i
        nu += Dk * segments_.slave_normal[k];
      }
      if (!(covered > 0)) {
        d_.status[i] = NodeStatus::uncovered;
      } else if (covered < kDropCoverage * support) {
        d_.status[i] = NodeStatus::barely_covered;
      } else if (auto p = prescribed.find(poly_[i]);
                 p != prescribed.end() && normal_is_prescribed(p->second, nu.normalized())) {
        d_.status[i] = NodeStatus::crosspoint;
      } else if (auto c = friction_corner(corners, i, nu); c && c->third_body) {
        d_.status[i] = NodeStatus::crosspoint;
      } else {
        d_.status[i] = NodeStatus::contact;
        if (friction_corner(corners, i, nu)) tangential_dropped_.insert(i);
      }
    }
  }

  // The corner (slave_corners) at slave node i with the multiplier's normal nu, if friction is involved there and
  // the other edge turns away.
  const Corner* friction_corner(const std::map<int, Corner>& corners, size_t i, const Eigen::Vector2d& nu) const {
    const auto c = corners.find(poly_[i]);
    if (c == corners.end() || !c->second.friction || !(nu.norm() > 0)) return nullptr;
    return turns(Eigen::Vector2d(-nu.y(), nu.x()).normalized(), c->second.tangent) ? &c->second : nullptr;
  }

  // Which pair of the group carries each contact node's multiplier: of the pairs whose pieces touch the node (else
  // whose pieces lie on its two segments), the first in the job's order. The others mark it carried elsewhere. On a
  // closed chain the last position is the start again and takes the start's answer.
  void assign_owners() {
    if (group_.pairs.size() < 2) return;
    const size_t n_segments = on_segment_.size();
    for (size_t m = 0; m <= n_runs_ && n_runs_ > 0; ++m) {
      const size_t i = d_.multiplier_nodes[m];
      if (d_.status[i] != NodeStatus::contact || (closed_ && i + 1 == n_)) continue;
      int touching = -1, near = -1;
      auto consider = [](int& best, int pair) { best = best < 0 ? pair : std::min(best, pair); };
      // The segments before and after node i (on a closed chain position 0 follows the closing segment).
      const size_t before = i > 0 ? i - 1 : (closed_ ? n_segments - 1 : n_segments);
      for (const auto& [k, end] : {std::pair{before, 1.0}, std::pair{i, 0.0}}) {
        if (k >= n_segments) continue;
        for (const auto* s : on_segment_[k]) {
          consider(near, pair_of(*s));
          if (std::abs((end == 0.0 ? s->xi0 : s->xi1) - end) < 1e-9) consider(touching, pair_of(*s));
        }
      }
      const int owner = touching >= 0 ? touching : near;
      if (owner != pair_index_) d_.status[i] = NodeStatus::other_pair;
    }
    if (closed_ && n_ > 0) d_.status[n_ - 1] = d_.status[0];
  }

  // One row per contact node; every slave node's value from the rows: a multiplier node's own; inside a run the
  // linear interpolation in s of its two ends, where a dropped end takes the other end's value (its function was
  // added to the other's).
  void number_rows() {
    d_.row_of_node.assign(n_, -1);
    for (size_t i = 0; i < d_.slave_nodes.size(); ++i)
      if (d_.status[i] == NodeStatus::contact) {
        d_.row_of_node[i] = static_cast<int>(d_.node_of_row.size());
        d_.node_of_row.push_back(static_cast<int>(i));
        d_.tangential_dropped.push_back(tangential_dropped_.count(i) ? 1 : 0);
      }
    if (closed_ && n_ > 0) d_.row_of_node[n_ - 1] = d_.row_of_node[0];  // the start again: its row
    // A run between two nodes this pair does not carry, one of them carried by another pair of its group, lies in
    // that pair's part of the surface: its inner nodes are that pair's too (their values are its), not this
    // pair's coarse-grained interior with no value.
    for (size_t m = 0; m < n_runs_; ++m) {
      const size_t a = d_.multiplier_nodes[m], b = d_.multiplier_nodes[m + 1];
      const bool elsewhere = d_.status[a] == NodeStatus::other_pair || d_.status[b] == NodeStatus::other_pair;
      if (!elsewhere || d_.row_of_node[a] >= 0 || d_.row_of_node[b] >= 0) continue;
      for (size_t i = a + 1; i < b; ++i)
        if (d_.status[i] == NodeStatus::inner) d_.status[i] = NodeStatus::other_pair;
    }
    d_.node_from_rows.assign(n_, {});
    for (size_t m = 0; m < n_runs_; ++m) {
      const size_t a = d_.multiplier_nodes[m], b = d_.multiplier_nodes[m + 1];
      const int ra = d_.row_of_node[a], rb = d_.row_of_node[b];
      for (size_t i = a; i <= b; ++i) {
        if ((i == a && ra >= 0) || (i == b && rb >= 0)) {
          d_.node_from_rows[i] = {{i == a ? ra : rb, 1.0}};
          continue;
        }
        if ((i == a || i == b) && d_.status[i] != NodeStatus::inner) continue;  // a multiplier node without a row
        const double t = (arc(i) - arc(a)) / (arc(b) - arc(a));
        if (ra >= 0 && rb >= 0)
          d_.node_from_rows[i] = {{ra, 1 - t}, {rb, t}};
        else if (ra >= 0 || rb >= 0)
          d_.node_from_rows[i] = {{ra >= 0 ? ra : rb, 1.0}};
      }
    }
    const Eigen::Index rows = static_cast<Eigen::Index>(d_.node_of_row.size());
    d_.D = Eigen::VectorXd::Zero(rows);
    d_.area = Eigen::VectorXd::Zero(rows);
    d_.gap0 = Eigen::VectorXd::Zero(rows);
    nu_.assign(static_cast<size_t>(rows), Eigen::Vector2d::Zero());
  }

  static void add(VectorEntries& to, std::pair<int, int> key, const Eigen::Vector2d& v) {
    auto it = to.emplace(key, Eigen::Vector2d::Zero()).first;  // Eigen's default constructor leaves it unset
    it->second += v;
  }

  // A quadrature point of a mortar segment: the slave point x, the normal n the gap is measured along (and the
  // pressure acts along), and the gap t to the master along n. Where neither side's segment has a curve, the
  // chords' (x on the chord, n the chord's normal, t affine along the mortar segment: the arithmetic of the
  // segment mesh, unchanged); else the curves' (edge_curves.hpp), the master's curve hit on the segment whose
  // stretch the hit lies on (the mortar segment's, or a neighbour's where the normal leans across its end).
  struct GapPoint {
    Eigen::Vector2d x, normal;
    double gap = 0.0;
  };
  GapPoint gap_point(const MortarSegment& s, size_t k, double u, double xi) const {
    GapPoint p;
    p.gap = s.gap0 + u * (s.gap1 - s.gap0);
    const size_t j = static_cast<size_t>(s.master);
    if (!slave_curves_.curved(k) && !master_curves_.curved(j)) {
      p.x = S_[k] + xi * (S_[k + 1] - S_[k]);
      p.normal = segments_.slave_normal[k];
      return p;
    }
    const EdgeCurves::Frame f = slave_curves_.at(k, xi);
    p.x = f.point;
    p.normal = f.normal;
    const size_t nm = master_curves_.segments();
    const auto t = master_curves_.hit(j, p.x, p.normal);
    if (!t) return p;  // the line misses the master's curve (grazing): the chords' gap
    p.gap = *t;
    const double eta = master_curves_.chord_parameter(j, p.x + *t * p.normal);
    const bool before = eta < 0 && (j > 0 || master_closed_), after = eta > 1 && (j + 1 < nm || master_closed_);
    if (!before && !after) return p;
    const size_t other = before ? (j + nm - 1) % nm : (j + 1) % nm;
    const auto t_other = master_curves_.hit(other, p.x, p.normal);
    if (!t_other) return p;
    const double eta_other = master_curves_.chord_parameter(other, p.x + *t_other * p.normal);
    if (eta_other >= 0 && eta_other <= 1) p.gap = *t_other;
    return p;
  }

  // Integrals over every mortar segment of one run (three-point Gauss: the integrands are at most cubic in xi).
  void integrate_run(size_t m) {
    const size_t a = d_.multiplier_nodes[m], b_node = d_.multiplier_nodes[m + 1];
    const int r0 = d_.row_of_node[a], r1 = d_.row_of_node[b_node];
    if (r0 < 0 && r1 < 0) return;
    // A node without a row drops its function into the other's, unless another pair of the group carries it.
    DualBasis b = *basis_[m];
    if (r0 < 0 && d_.status[a] != NodeStatus::other_pair) b = drop_node(b, 0);
    if (r1 < 0 && d_.status[b_node] != NodeStatus::other_pair) b = drop_node(b, 1);
    const double Lrun = arc(b_node) - arc(a);
    for (size_t k = a; k < b_node; ++k) {
      const double L = segments_.slave_length[k];
      for (const auto* s : on_segment_[k]) {
        const int m0 = master_poly_[static_cast<size_t>(s->master)],
                  m1 = master_poly_[static_cast<size_t>(s->master) + 1];
        const int n_master = static_cast<int>(d_.master_nodes.size());  // a closed master's last position is its first
        for (size_t q = 0; q < kGaussX.size(); ++q) {
          const double u = kGaussX[q];
          const double xi = s->xi0 + u * (s->xi1 - s->xi0);
          const double w = kGaussW[q] * (s->xi1 - s->xi0) * L * thickness_;
          const double eta = s->eta0 + u * (s->eta1 - s->eta0);
          const double sr = (arc(k) + xi * L - arc(a)) / Lrun;  // parameter along the run
          const GapPoint p = gap_point(*s, k, u, xi);
          const Eigen::Vector2d& n = p.normal;
          const double gap = (pair_.gap.geometric ? p.gap : 0.0) + analytic_gap(pair_.gap, p.x);
          const double Ns[2] = {1 - xi, xi}, Nm[2] = {1 - eta, eta}, Nrun[2] = {1 - sr, sr};
          for (int i = 0; i < 2; ++i) {
            const int r = i == 0 ? r0 : r1;
            if (r < 0) continue;
            const double phi = b.phi(i, sr);
            d_.gap0[r] += w * phi * gap;
            d_.D[r] += w * phi * Nrun[i];
            d_.area[r] += w * phi;
            nu_[static_cast<size_t>(r)] += w * phi * n;
            for (int l = 0; l < 2; ++l) {
              add(gs_, {r, poly_[k + static_cast<size_t>(l)]}, w * phi * Ns[l] * n);
              ss_[{r, poly_[k + static_cast<size_t>(l)]}] += w * phi * Ns[l];
              add(gm_, {r, l == 0 ? m0 : m1}, w * phi * Nm[l] * n);
              mm_[{r, (s->master + l) % n_master}] += w * phi * Nm[l];
            }
          }
        }
      }
    }
  }

  void integrate() {
    for (size_t m = 0; m < n_runs_; ++m)
      if (basis_[m]) integrate_run(m);
    for (const auto& v : nu_) d_.normal.push_back(v.normalized());
    for (const auto& n : d_.normal) d_.tangent.emplace_back(-n.y(), n.x());
  }

  // The initial gap at every slave polyline position: at the node's end of a mortar segment that covers it (the
  // segment after it first, then the one before), as the quadrature points measure it (gap_point).
  void node_gaps() {
    d_.initial_gap.assign(n_, std::numeric_limits<double>::quiet_NaN());
    constexpr double kAtEnd = 1e-12;  // a mortar segment's end within this of the node's parameter covers it
    for (size_t i = 0; i < n_; ++i) {
      for (const auto& [k, xi] : {std::pair<size_t, double>{i, 0.0}, std::pair<size_t, double>{i - 1, 1.0}}) {
        if (k >= on_segment_.size()) continue;  // i - 1 wrapped past 0, or the last position has no segment after
        const MortarSegment* on = nullptr;
        for (const auto* s : on_segment_[k])
          if (s->xi0 <= xi + kAtEnd && s->xi1 >= xi - kAtEnd) on = s;
        if (!on || !(on->xi1 > on->xi0)) continue;
        const double u = std::clamp((xi - on->xi0) / (on->xi1 - on->xi0), 0.0, 1.0);
        const GapPoint p = gap_point(*on, k, u, xi);
        d_.initial_gap[i] = (pair_.gap.geometric ? p.gap : 0.0) + analytic_gap(pair_.gap, p.x);
        break;
      }
    }
  }

  // Sparse operators. Exact zeros (an axis-aligned normal touches one component only) are left out, which keeps
  // each body's interface unknowns minimal; tiny off-diagonal remainders of biorthogonality are dropped too.
  SparseRows sparse_rows(const VectorEntries& entries, int n_dofs) const {
    std::vector<Eigen::Triplet<double>> t;
    for (const auto& [key, v] : entries) {
      const double scale = d_.D[key.first];
      for (int c = 0; c < 2; ++c)
        if (std::abs(v[c]) > 1e-14 * scale) t.emplace_back(key.first, 2 * key.second + c, v[c]);
    }
    SparseRows out(d_.D.size(), n_dofs);
    out.setFromTriplets(t.begin(), t.end());
    return out;
  }

  void assemble_operators() {
    d_.Gs = sparse_rows(gs_, 2 * slave_.mesh.num_nodes());
    d_.Gm = sparse_rows(gm_, 2 * master_.mesh.num_nodes());
    std::vector<Eigen::Triplet<double>> tm;
    for (const auto& [key, v] : mm_)
      if (v != 0.0) tm.emplace_back(key.first, key.second, v);
    d_.M.resize(d_.D.size(), static_cast<Eigen::Index>(d_.master_nodes.size()));
    d_.M.setFromTriplets(tm.begin(), tm.end());
    if (pair_.friction.active()) tangential_operators();
  }

  // The per-node results on the slave nodes, each once: on a closed slave edge the last position (the start
  // again) is dropped, its row being the start's; node_arc runs along the loop from the start.
  void close_loop() {
    const size_t n = d_.slave_nodes.size();
    d_.node_arc = arc_.head(static_cast<Eigen::Index>(n));
    if (!closed_) return;
    d_.closed = true;
    d_.loop_length = n_ > 0 ? arc(n_ - 1) : 0.0;
    d_.status.resize(n);
    d_.row_of_node.resize(n);
    d_.node_from_rows.resize(n);
    // The start again: covered from the loop's last segment where its first does not cover it.
    if (std::isnan(d_.initial_gap.front()) && n_ > n) d_.initial_gap.front() = d_.initial_gap[n_ - 1];
    d_.initial_gap.resize(n);
  }

  // A pair whose group chains several slave edges: its own edge's stretch of the per-node results (positions
  // first .. last of the chain), its arc lengths from its own first node.
  void keep_own_edge() {
    if (group_.slave.edges.size() < 2) return;
    const size_t own = group_.slave.index(pair_.slave_edge);
    const size_t first = group_.slave.start[own];
    const size_t last = first + slave_.mesh.edge_set_nodes(pair_.slave_edge).size() - 1;  // on poly_
    const auto from = static_cast<std::ptrdiff_t>(first), to = static_cast<std::ptrdiff_t>(last) + 1;
    d_.slave_nodes.assign(poly_.begin() + from, poly_.begin() + to);
    auto slice = [&](auto& v) { v = std::decay_t<decltype(v)>(v.begin() + from, v.begin() + to); };
    if (d_.status.size() < n_) {  // close_loop() folded the start back: unfold for the slicing
      d_.status.push_back(d_.status.front());
      d_.row_of_node.push_back(d_.row_of_node.front());
      d_.node_from_rows.push_back(d_.node_from_rows.front());
      d_.initial_gap.push_back(d_.initial_gap.front());
    }
    slice(d_.status);
    slice(d_.row_of_node);
    slice(d_.node_from_rows);
    slice(d_.initial_gap);
    d_.node_arc = arc_.segment(from, to - from).array() - arc(first);
    std::vector<size_t> multipliers;
    for (size_t i : d_.multiplier_nodes)
      if (i >= first && i <= last) multipliers.push_back(i - first);
    d_.multiplier_nodes = multipliers;
    d_.closed = false;
    d_.loop_length = 0.0;
    // A row at the chain's start belongs to an edge ending there when the chain closes (position n_ - 1 again).
    for (int& i : d_.node_of_row) {
      if (i < static_cast<int>(first)) i = static_cast<int>(n_) - 1;
      i -= static_cast<int>(first);
    }
  }

  // Ts and Tm: the scalar mortar integrals of the slave and the master times the row's tangent.
  void tangential_operators() {
    VectorEntries ts, tm;
    for (const auto& [key, v] : ss_) ts[key] = v * d_.tangent[static_cast<size_t>(key.first)];
    for (const auto& [key, v] : mm_)
      tm[{key.first, d_.master_nodes[static_cast<size_t>(key.second)]}] =
          v * d_.tangent[static_cast<size_t>(key.first)];
    d_.Ts = sparse_rows(ts, 2 * slave_.mesh.num_nodes());
    d_.Tm = sparse_rows(tm, 2 * master_.mesh.num_nodes());
  }

  const Problem& problem_;
  const ContactIndex& index_;  // the problem's pairs by body
  const ContactPair& pair_;
  const Body& slave_;
  const Body& master_;
  const double thickness_;
  const int pair_index_;
  const PairGroup group_;  // the pairs sharing this pair's contact surface (itself alone, mostly)
  PairDiscretization d_;
  std::vector<int> poly_, master_poly_;  // the slave's and the master's nodes as polylines (polyline())
  bool closed_ = false;                  // the slave edge is a closed loop
  Eigen::VectorXd arc_;                  // arc length at every slave polyline position
  std::vector<Eigen::Vector2d> S_;
  std::set<size_t> tangential_dropped_;  // slave nodes whose friction row is dropped (slave_corners)
  size_t n_ = 0, n_runs_ = 0;
  SegmentMesh segments_;
  EdgeCurves slave_curves_, master_curves_;  // the sides' true curves where the mesh knows them
  bool master_closed_ = false;               // the master edge is a closed loop
  std::vector<double> master_length_;
  std::vector<std::vector<const MortarSegment*>> on_segment_;
  std::vector<std::optional<DualBasis>> basis_;
  std::vector<Eigen::Vector2d> nu_;
  VectorEntries gs_, gm_;
  std::map<std::pair<int, int>, double> mm_;  // (row, master edge position) -> scalar M
  std::map<std::pair<int, int>, double> ss_;  // (row, slave node) -> integral Phi_r N_i
};

}  // namespace

PairDiscretization discretize_pair(const Problem& problem, int pair_index, double theta, const ContactIndex* index) {
  if (index) return PairBuilder(problem, *index, pair_index, theta).build();
  const ContactIndex own(problem);
  return PairBuilder(problem, own, pair_index, theta).build();
}

}  // namespace contact::mortar
