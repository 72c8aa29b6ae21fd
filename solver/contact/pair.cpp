#include "pair.hpp"

#include "dual_basis.hpp"
#include "segments.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

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

// Prescribed displacement components (x, y) of every node of a body.
std::map<int, std::array<bool, 2>> prescribed_components(const Body& body) {
  std::map<int, std::array<bool, 2>> out;
  for (const auto& bc : body.boundary) {
    if (!prescribes_displacement(bc)) continue;
    for (int node : condition_nodes(body.mesh, bc)) {
      auto& p = out[node];
      p[0] = p[0] || bc.ux.has_value();
      p[1] = p[1] || bc.uy.has_value();
    }
  }
  return out;
}

// A crosspoint: the node's displacement along its normal is prescribed (both components, or the one component
// within 10 degrees of the normal), so the slave side cannot move to open or close the contact there.
bool normal_is_prescribed(const std::array<bool, 2>& p, const Eigen::Vector2d& n) {
  if (p[0] && p[1]) return true;
  const double cos10 = 0.984807753;
  return (p[0] && std::abs(n.x()) >= cos10) || (p[1] && std::abs(n.y()) >= cos10);
}

// Three-point Gauss-Legendre on [0, 1]: exact to degree 5 (the products here are at most cubic).
constexpr std::array<double, 3> kGaussX = {0.1127016653792583, 0.5, 0.8872983346207417};
constexpr std::array<double, 3> kGaussW = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};

}  // namespace

Eigen::VectorXd PairDiscretization::penalty_pressure(const Eigen::VectorXd& g) const {
  Eigen::VectorXd z(g.size());
  const bool shifted = multiplier.size() == g.size();
  for (Eigen::Index r = 0; r < g.size(); ++r) z[r] = std::max(0.0, (shifted ? multiplier[r] : 0.0) - g[r] / theta);
  return z;
}

void PairDiscretization::add_forces(const Eigen::VectorXd& z, Eigen::VectorXd& fs, Eigen::VectorXd& fm) const {
  fs.noalias() -= Gs.transpose() * z;
  fm.noalias() += Gm.transpose() * z;
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
  // Mean outward normal of the master edge, weighted by segment length.
  const auto mpts = coordinates(master.mesh, master.mesh.edge_set_nodes(pair.master_edge));
  Eigen::Vector2d n = Eigen::Vector2d::Zero();
  for (size_t i = 0; i + 1 < mpts.size(); ++i)
    if ((mpts[i + 1] - mpts[i]).norm() > 0) n += (mpts[i + 1] - mpts[i]).norm() * outward_normal(mpts[i], mpts[i + 1]);
  if (n.norm() > 0) n.normalize();
  auto extent = [&](const mesh::Mesh& m) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& p : m.nodes) {
      lo = std::min(lo, p.dot(n));
      hi = std::max(hi, p.dot(n));
    }
    return hi - lo;
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
// first and the last always among them. Where the master is coarser than the slave, consecutive slave segments are
// grouped until the group is as long as the longest master segment opposite, to the nearest slave segment;
// elsewhere every slave node is a multiplier node (the plain dual mortar method).
std::vector<size_t> multiplier_partition(const SegmentMesh& segments, const std::vector<double>& master_length) {
  const size_t n_segments = segments.slave_length.size();
  std::vector<double> opposite(n_segments, 0.0);  // the longest master segment opposite each slave segment
  for (const auto& s : segments.segments)
    opposite[static_cast<size_t>(s.slave)] = std::max(opposite[static_cast<size_t>(s.slave)], master_length[static_cast<size_t>(s.master)]);
  std::vector<size_t> nodes = {0};
  double run = 0, longest = 0;
  for (size_t k = 0; k < n_segments; ++k) {
    run += segments.slave_length[k];
    longest = std::max(longest, opposite[k]);
    // Close the run when one more slave segment would take it further from the master length than it is now.
    if (k + 1 == n_segments || run >= longest - 0.5 * segments.slave_length[k]) {
      nodes.push_back(k + 1);
      run = longest = 0;
    }
  }
  return nodes;
}

}  // namespace

PairDiscretization discretize_pair(const Problem& problem, int pair_index, double theta) {
  const ContactPair& pair = problem.contacts[static_cast<size_t>(pair_index)];
  const Body& slave = problem.bodies[static_cast<size_t>(pair.slave_body)];
  const Body& master = problem.bodies[static_cast<size_t>(pair.master_body)];
  const double thickness = problem.model.plane == Plane::stress ? problem.model.thickness : 1.0;

  PairDiscretization d;
  d.name = pair.name;
  d.slave_body = pair.slave_body;
  d.master_body = pair.master_body;
  d.theta = theta;
  d.slave_nodes = slave.mesh.edge_set_nodes(pair.slave_edge);
  d.master_nodes = master.mesh.edge_set_nodes(pair.master_edge);
  const auto S = coordinates(slave.mesh, d.slave_nodes);
  const auto Mx = coordinates(master.mesh, d.master_nodes);
  const size_t n = S.size();
  const SegmentMesh segments = build_segment_mesh(S, Mx);
  const size_t n_segments = n < 2 ? 0 : n - 1;
  std::vector<double> master_length;
  for (size_t j = 0; j + 1 < Mx.size(); ++j) master_length.push_back((Mx[j + 1] - Mx[j]).norm());

  d.node_arc = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  for (size_t k = 1; k < n; ++k) d.node_arc[static_cast<Eigen::Index>(k)] = d.node_arc[static_cast<Eigen::Index>(k) - 1] + (S[k] - S[k - 1]).norm();
  auto arc = [&](size_t i) { return d.node_arc[static_cast<Eigen::Index>(i)]; };

  std::vector<std::vector<const MortarSegment*>> on_segment(n_segments);
  for (const auto& s : segments.segments) {
    on_segment[static_cast<size_t>(s.slave)].push_back(&s);
    d.covered_length += (s.xi1 - s.xi0) * segments.slave_length[static_cast<size_t>(s.slave)];
  }

  // Multiplier segments (runs of slave segments between consecutive multiplier nodes), each with its dual basis
  // on its covered part, in the arc-length parameter s of the run.
  d.multiplier_nodes = n_segments ? multiplier_partition(segments, master_length) : std::vector<size_t>{};
  const size_t n_runs = d.multiplier_nodes.empty() ? 0 : d.multiplier_nodes.size() - 1;
  std::vector<std::optional<DualBasis>> basis(n_runs);
  for (size_t m = 0; m < n_runs; ++m) {
    const size_t a = d.multiplier_nodes[m], b = d.multiplier_nodes[m + 1];
    const double L = arc(b) - arc(a);
    std::vector<std::pair<double, double>> covered;
    for (size_t k = a; k < b; ++k)
      for (const auto* s : on_segment[k])
        covered.emplace_back((arc(k) + s->xi0 * segments.slave_length[k] - arc(a)) / L,
                             (arc(k) + s->xi1 * segments.slave_length[k] - arc(a)) / L);
    if (L > 0) basis[m] = dual_basis(covered, L);
  }

  // Which multiplier nodes carry a multiplier: covered enough, and not a crosspoint. The other slave nodes lie
  // inside a multiplier segment.
  d.status.assign(n, NodeStatus::inner);
  const auto prescribed = prescribed_components(slave);
  for (size_t m = 0; m <= n_runs && n_runs > 0; ++m) {
    const size_t i = d.multiplier_nodes[m];
    double support = 0, covered = 0;
    Eigen::Vector2d nu = Eigen::Vector2d::Zero();
    for (size_t run : {m - 1, m}) {  // the runs before and after node i (m - 1 wraps for m = 0: skipped)
      if (run >= n_runs) continue;
      const size_t a = d.multiplier_nodes[run], b = d.multiplier_nodes[run + 1];
      support += 0.5 * (arc(b) - arc(a));
      if (!basis[run]) continue;
      const double Dk = basis[run]->D[run == m ? 0 : 1];
      covered += Dk;
      const size_t k = run == m ? a : b - 1;  // the slave segment next to node i
      nu += Dk * segments.slave_normal[k];
    }
    if (!(covered > 0)) {
      d.status[i] = NodeStatus::uncovered;
    } else if (covered < kDropCoverage * support) {
      d.status[i] = NodeStatus::barely_covered;
    } else if (auto p = prescribed.find(d.slave_nodes[i]); p != prescribed.end() && normal_is_prescribed(p->second, nu.normalized())) {
      d.status[i] = NodeStatus::crosspoint;
    } else {
      d.status[i] = NodeStatus::contact;
    }
  }
  d.row_of_node.assign(n, -1);
  for (size_t i = 0; i < n; ++i)
    if (d.status[i] == NodeStatus::contact) {
      d.row_of_node[i] = static_cast<int>(d.node_of_row.size());
      d.node_of_row.push_back(static_cast<int>(i));
    }
  // Every slave node's value from the rows: a multiplier node's own; inside a run the linear interpolation in s of
  // its two ends, where a dropped end takes the other end's value (its function was added to the other's).
  d.node_from_rows.assign(n, {});
  for (size_t m = 0; m < n_runs; ++m) {
    const size_t a = d.multiplier_nodes[m], b = d.multiplier_nodes[m + 1];
    const int ra = d.row_of_node[a], rb = d.row_of_node[b];
    for (size_t i = a; i <= b; ++i) {
      if ((i == a && ra >= 0) || (i == b && rb >= 0)) {
        d.node_from_rows[i] = {{i == a ? ra : rb, 1.0}};
        continue;
      }
      if ((i == a || i == b) && d.status[i] != NodeStatus::inner) continue;  // a multiplier node without a row
      const double t = (arc(i) - arc(a)) / (arc(b) - arc(a));
      if (ra >= 0 && rb >= 0)
        d.node_from_rows[i] = {{ra, 1 - t}, {rb, t}};
      else if (ra >= 0 || rb >= 0)
        d.node_from_rows[i] = {{ra >= 0 ? ra : rb, 1.0}};
    }
  }
  const Eigen::Index rows = static_cast<Eigen::Index>(d.node_of_row.size());
  d.D = Eigen::VectorXd::Zero(rows);
  d.area = Eigen::VectorXd::Zero(rows);
  d.gap0 = Eigen::VectorXd::Zero(rows);
  std::vector<Eigen::Vector2d> nu(static_cast<size_t>(rows), Eigen::Vector2d::Zero());

  // Integrals over every mortar segment (three-point Gauss: the integrands are at most cubic in xi).
  std::map<std::pair<int, int>, Eigen::Vector2d> gs, gm;  // (row, node) -> vector coefficient
  std::map<std::pair<int, int>, double> mm;              // (row, master edge position) -> scalar M
  auto add = [](std::map<std::pair<int, int>, Eigen::Vector2d>& to, std::pair<int, int> key, const Eigen::Vector2d& v) {
    auto it = to.emplace(key, Eigen::Vector2d::Zero()).first;  // Eigen's default constructor leaves it unset
    it->second += v;
  };
  for (size_t m = 0; m < n_runs; ++m) {
    if (!basis[m]) continue;
    const size_t a = d.multiplier_nodes[m], b_node = d.multiplier_nodes[m + 1];
    const int r0 = d.row_of_node[a], r1 = d.row_of_node[b_node];
    if (r0 < 0 && r1 < 0) continue;
    DualBasis b = *basis[m];
    if (r0 < 0) b = drop_node(b, 0);
    if (r1 < 0) b = drop_node(b, 1);
    const double Lrun = arc(b_node) - arc(a);
    for (size_t k = a; k < b_node; ++k) {
      const Eigen::Vector2d nk = segments.slave_normal[k];
      const double L = segments.slave_length[k];
      for (const auto* s : on_segment[k]) {
        const int m0 = d.master_nodes[static_cast<size_t>(s->master)], m1 = d.master_nodes[static_cast<size_t>(s->master) + 1];
        for (size_t q = 0; q < kGaussX.size(); ++q) {
          const double u = kGaussX[q];
          const double xi = s->xi0 + u * (s->xi1 - s->xi0);
          const double w = kGaussW[q] * (s->xi1 - s->xi0) * L * thickness;
          const double eta = s->eta0 + u * (s->eta1 - s->eta0);
          const double t = s->gap0 + u * (s->gap1 - s->gap0);
          const double sr = (arc(k) + xi * L - arc(a)) / Lrun;  // parameter along the run
          const Eigen::Vector2d x = S[k] + xi * (S[k + 1] - S[k]);
          const double gap = (pair.gap.geometric ? t : 0.0) + analytic_gap(pair.gap, x);
          const double Ns[2] = {1 - xi, xi}, Nm[2] = {1 - eta, eta}, Nrun[2] = {1 - sr, sr};
          for (int i = 0; i < 2; ++i) {
            const int r = i == 0 ? r0 : r1;
            if (r < 0) continue;
            const double phi = b.phi(i, sr);
            d.gap0[r] += w * phi * gap;
            d.D[r] += w * phi * Nrun[i];
            d.area[r] += w * phi;
            nu[static_cast<size_t>(r)] += w * phi * nk;
            for (int l = 0; l < 2; ++l) {
              add(gs, {r, d.slave_nodes[k + static_cast<size_t>(l)]}, w * phi * Ns[l] * nk);
              add(gm, {r, l == 0 ? m0 : m1}, w * phi * Nm[l] * nk);
              mm[{r, s->master + l}] += w * phi * Nm[l];
            }
          }
        }
      }
    }
  }
  for (Eigen::Index r = 0; r < rows; ++r) d.normal.push_back(nu[static_cast<size_t>(r)].normalized());

  // Sparse operators. Exact zeros (an axis-aligned normal touches one component only) are left out, which keeps
  // each body's interface unknowns minimal; tiny off-diagonal remainders of biorthogonality are dropped too.
  auto build = [&](const std::map<std::pair<int, int>, Eigen::Vector2d>& entries, int n_dofs) {
    std::vector<Eigen::Triplet<double>> t;
    for (const auto& [key, v] : entries) {
      const double scale = d.D[key.first];
      for (int c = 0; c < 2; ++c)
        if (std::abs(v[c]) > 1e-14 * scale) t.emplace_back(key.first, 2 * key.second + c, v[c]);
    }
    SparseRows out(rows, n_dofs);
    out.setFromTriplets(t.begin(), t.end());
    return out;
  };
  d.Gs = build(gs, 2 * slave.mesh.num_nodes());
  d.Gm = build(gm, 2 * master.mesh.num_nodes());
  std::vector<Eigen::Triplet<double>> tm;
  for (const auto& [key, v] : mm)
    if (v != 0.0) tm.emplace_back(key.first, key.second, v);
  d.M.resize(rows, static_cast<Eigen::Index>(d.master_nodes.size()));
  d.M.setFromTriplets(tm.begin(), tm.end());
  return d;
}

}  // namespace contact::mortar
