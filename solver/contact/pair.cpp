#include "pair.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace contact::interface {

namespace {

Eigen::Vector2d outward_normal(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = (b - a).normalized();
  return {e.y(), -e.x()};
}

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

// Appends n . (interpolated displacement) to a row: weights w0, w1 at nodes n0, n1. Exact zeros are left out
// (an axis-aligned normal touches one component only), which keeps each body's contact-zone dof set minimal.
void add_row(std::vector<Eigen::Triplet<double>>& t, int row, const Eigen::Vector2d& n, int n0, double w0, int n1, double w1) {
  auto add = [&](int dof, double value) {
    if (value != 0.0) t.emplace_back(row, dof, value);
  };
  add(2 * n0, w0 * n.x());
  add(2 * n0 + 1, w0 * n.y());
  add(2 * n1, w1 * n.x());
  add(2 * n1 + 1, w1 * n.y());
}

}  // namespace

std::optional<Projection> project(const std::vector<Eigen::Vector2d>& polyline, const Eigen::Vector2d& x) {
  std::optional<Projection> best;
  double best_distance = std::numeric_limits<double>::infinity();
  const double tol = 1e-9;
  for (size_t i = 0; i + 1 < polyline.size(); ++i) {
    const Eigen::Vector2d a = polyline[i], e = polyline[i + 1] - a;
    const double L2 = e.squaredNorm();
    if (!(L2 > 0)) continue;
    double t = (x - a).dot(e) / L2;
    if (t < -tol || t > 1 + tol) continue;
    t = std::clamp(t, 0.0, 1.0);
    const Eigen::Vector2d foot = a + t * e;
    const double dist = (x - foot).norm();
    if (dist < best_distance) {
      best_distance = dist;
      best = Projection{static_cast<int>(i), t, foot, outward_normal(a, polyline[i + 1])};
    }
  }
  // Interior vertices: x in the wedge outside a convex corner (beyond the end of the segment before it and
  // before the start of the segment after it) projects onto the vertex itself.
  for (size_t k = 1; k + 1 < polyline.size(); ++k) {
    const Eigen::Vector2d before = polyline[k] - polyline[k - 1], after = polyline[k + 1] - polyline[k];
    const bool past_before = (x - polyline[k - 1]).dot(before) >= (1 - tol) * before.squaredNorm();
    const bool ahead_of_after = (x - polyline[k]).dot(after) <= tol * after.squaredNorm();
    if (!past_before || !ahead_of_after) continue;
    const double dist = (x - polyline[k]).norm();
    if (dist < best_distance * (1 - 1e-12)) {
      best_distance = dist;
      const Eigen::Vector2d n =
          (outward_normal(polyline[k - 1], polyline[k]) + outward_normal(polyline[k], polyline[k + 1])).normalized();
      best = Projection{static_cast<int>(k), 0.0, polyline[k], n};
    }
  }
  return best;
}

Eigen::VectorXd PairDiscretization::pressure(const Eigen::VectorXd& g) const {
  Eigen::VectorXd p(g.size());
  const bool shifted = multiplier.size() == g.size();
  for (Eigen::Index q = 0; q < g.size(); ++q) {
    const double lambda = shifted ? multiplier[q] : 0.0;
    p[q] = weight[q] > 0 ? std::max(0.0, lambda - g[q] / theta) : 0.0;
  }
  return p;
}

Eigen::VectorXd PairDiscretization::node_pressure(const Eigen::VectorXd& g, const Eigen::VectorXd& gauss_pressure) const {
  Eigen::VectorXd p(g.size());
  for (Eigen::Index j = 0; j < g.size(); ++j) {
    double v = 0.0;
    for (const auto& [q, w] : node_from_gauss[static_cast<size_t>(j)]) v += w * gauss_pressure[q];
    p[j] = node_has_master[j] ? std::max(0.0, v) : 0.0;
  }
  return p;
}

void PairDiscretization::add_forces(const Eigen::VectorXd& p, Eigen::VectorXd& fs, Eigen::VectorXd& fm) const {
  const Eigen::VectorXd wp = weight.cwiseProduct(p);
  fs.noalias() += Gs.transpose() * wp;
  fm.noalias() -= Gm.transpose() * wp;
}

PenaltyChoice choose_penalty(const Problem& problem, int pair_index) {
  const ContactPair& pair = problem.contacts[static_cast<size_t>(pair_index)];
  const Body& slave = problem.bodies[static_cast<size_t>(pair.slave_body)];
  const Body& master = problem.bodies[static_cast<size_t>(pair.master_body)];
  // Mean outward normal of the master edge, weighted by segment length.
  const auto mpts = coordinates(master.mesh, master.mesh.edge_set_nodes(pair.master_edge));
  Eigen::Vector2d n = Eigen::Vector2d::Zero();
  for (size_t i = 0; i + 1 < mpts.size(); ++i) n += (mpts[i + 1] - mpts[i]).norm() * outward_normal(mpts[i], mpts[i + 1]);
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
  const std::vector<int> master_nodes = master.mesh.edge_set_nodes(pair.master_edge);
  const auto S = coordinates(slave.mesh, d.slave_nodes);
  const auto M = coordinates(master.mesh, master_nodes);

  std::vector<Eigen::Triplet<double>> ts, tm;
  std::vector<double> weights, gaps, arcs;
  auto add_point = [&](const Eigen::Vector2d& x, double w, double arc, int s0, double ws0, int s1, double ws1,
                       std::vector<Eigen::Triplet<double>>& trip_s, std::vector<Eigen::Triplet<double>>& trip_m,
                       std::vector<Eigen::Vector2d>& normals, std::vector<double>& gap_out, std::vector<double>& w_out,
                       std::vector<double>& arc_out) {
    const int row = static_cast<int>(w_out.size());
    const auto proj = project(M, x);
    if (!proj) {
      normals.emplace_back(Eigen::Vector2d::Zero());
      gap_out.push_back(0.0);
      w_out.push_back(0.0);
      arc_out.push_back(arc);
      return false;
    }
    const Eigen::Vector2d n = proj->normal;
    normals.push_back(n);
    const double geometric = pair.gap.geometric ? (x - proj->point).dot(n) : 0.0;
    gap_out.push_back(geometric + analytic_gap(pair.gap, x));
    w_out.push_back(w);
    arc_out.push_back(arc);
    add_row(trip_s, row, n, s0, ws0, s1, ws1);
    const int j = proj->segment;
    const int m0 = master_nodes[static_cast<size_t>(j)];
    const int m1 = static_cast<size_t>(j) + 1 < master_nodes.size() ? master_nodes[static_cast<size_t>(j) + 1] : m0;
    add_row(trip_m, row, n, m0, 1 - proj->t, m1, proj->t);
    return true;
  };

  // Gauss points: each slave segment split at the projections of the master nodes onto it.
  const double gauss = 0.5 / std::sqrt(3.0);
  double arc0 = 0.0;
  d.node_from_gauss.assign(S.size(), {});
  for (size_t k = 0; k + 1 < S.size(); ++k) {
    const Eigen::Vector2d a = S[k], e = S[k + 1] - a;
    const double L = e.norm();
    std::vector<double> cuts = {0.0, 1.0};
    for (const auto& m : M) {
      const double t = (m - a).dot(e) / (L * L);
      if (t > 1e-10 && t < 1 - 1e-10) cuts.push_back(t);
    }
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end(), [](double u, double v) { return v - u < 1e-10; }), cuts.end());
    for (size_t c = 0; c + 1 < cuts.size(); ++c) {
      const double t0 = cuts[c], t1 = cuts[c + 1], mid = 0.5 * (t0 + t1), half = t1 - t0;
      // Linear extrapolation of the piece's two Gauss values to the segment's end nodes it touches.
      const int qa = static_cast<int>(weights.size()), qb = qa + 1;
      const double ta = mid - gauss * half, tb = mid + gauss * half;
      auto extrapolate_to = [&](size_t node, double t_node) {
        const double s_node = (t_node - ta) / (tb - ta);
        d.node_from_gauss[node].emplace_back(qa, 1 - s_node);
        d.node_from_gauss[node].emplace_back(qb, s_node);
      };
      if (c == 0) extrapolate_to(k, 0.0);
      if (c + 2 == cuts.size()) extrapolate_to(k + 1, 1.0);
      for (double t : {mid - gauss * half, mid + gauss * half}) {
        const Eigen::Vector2d x = a + t * e;
        add_point(x, 0.5 * half * L * thickness, arc0 + t * L, d.slave_nodes[k], 1 - t, d.slave_nodes[k + 1], t, ts, tm,
                  d.normal, gaps, weights, arcs);
        d.point.push_back(x);
      }
    }
    arc0 += L;
  }
  for (auto& entries : d.node_from_gauss)  // average over the (one or two) adjacent pieces
    for (auto& e : entries) e.second *= entries.size() > 2 ? 0.5 : 1.0;
  const int Q = static_cast<int>(weights.size());
  d.weight = Eigen::Map<Eigen::VectorXd>(weights.data(), Q);
  d.gap = Eigen::Map<Eigen::VectorXd>(gaps.data(), Q);
  d.arc = Eigen::Map<Eigen::VectorXd>(arcs.data(), Q);
  d.Gs.resize(Q, 2 * slave.mesh.num_nodes());
  d.Gs.setFromTriplets(ts.begin(), ts.end());
  d.Gm.resize(Q, 2 * master.mesh.num_nodes());
  d.Gm.setFromTriplets(tm.begin(), tm.end());

  // The same at the slave nodes.
  std::vector<Eigen::Triplet<double>> hs, hm;
  std::vector<Eigen::Vector2d> node_normals;
  std::vector<double> ngap, nweight, narc;
  double arc = 0.0;
  for (size_t k = 0; k < S.size(); ++k) {
    if (k > 0) arc += (S[k] - S[k - 1]).norm();
    add_point(S[k], 1.0, arc, d.slave_nodes[k], 1.0, d.slave_nodes[k], 0.0, hs, hm, node_normals, ngap, nweight, narc);
  }
  const int n = static_cast<int>(S.size());
  d.node_arc = Eigen::Map<Eigen::VectorXd>(narc.data(), n);
  d.node_gap = Eigen::Map<Eigen::VectorXd>(ngap.data(), n);
  d.node_has_master.resize(n);
  for (int k = 0; k < n; ++k) d.node_has_master[k] = nweight[static_cast<size_t>(k)] > 0 ? 1 : 0;
  d.Hs.resize(n, 2 * slave.mesh.num_nodes());
  d.Hs.setFromTriplets(hs.begin(), hs.end());
  d.Hm.resize(n, 2 * master.mesh.num_nodes());
  d.Hm.setFromTriplets(hm.begin(), hm.end());
  return d;
}

}  // namespace contact::interface
