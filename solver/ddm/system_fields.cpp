// ContactSystem's reports and results: the per-iteration report (pressures, gaps, active sets, friction) and
// the final fields of a step (each body's displacements, stresses, reactions and rigid motion; each pair's
// pressures, gaps, normals and friction results). The system's set-up and solves are contact_system.cpp.
#include "contact_system.hpp"

#include "../contact_extent.hpp"
#include "../mortar/pair_group.hpp"
#include "../mortar/segments.hpp"

#include <Eigen/QR>

#include <cmath>
#include <limits>
#include <map>

namespace contact::ddm {

IterationReport ContactSystem::report_gaps(int iteration, const Pressures& z, const Pressures& nodal_gaps,
                                           std::vector<std::vector<char>>& previous_active) const {
  IterationReport r;
  r.iteration = iteration;
  for (size_t a = 0; a < bodies_.size(); ++a)
    r.bodies.push_back({problem_.bodies[a].name, problem_.bodies[a].mesh.num_cells(), bodies_[a]->n_free(), 0});
  previous_active.resize(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const auto& pair = pairs_[k];
    const Eigen::VectorXd& p = z[k];
    const Eigen::VectorXd& g = nodal_gaps[k];
    PairReport pr;
    pr.name = pair.name;
    pr.theta = problem_.solver.enforcement == Enforcement::exact ? 0.0 : pair.theta;
    pr.force = pair.total_force(p);
    pr.resultant = pair.resultant(p);
    auto& prev = previous_active[k];
    const bool had_previous = prev.size() == static_cast<size_t>(p.size());
    prev.resize(static_cast<size_t>(p.size()), 0);
    for (Eigen::Index row = 0; row < p.size(); ++row) {
      pr.max_penetration = std::max(pr.max_penetration, -g[row]);
      const char active = p[row] > 0 ? 1 : 0;
      if (had_previous && active != prev[static_cast<size_t>(row)]) ++pr.changed_nodes;
      prev[static_cast<size_t>(row)] = active;
      if (!active) continue;
      ++pr.active_nodes;
      pr.max_pressure = std::max(pr.max_pressure, p[row]);
    }
    const Eigen::VectorXd pn = pair.to_nodes(p, 0.0);
    const ContactExtent extent = contact_extent(pair.node_arc, pn, pair.loop_length);
    pr.extent_begin = extent.begin;
    pr.extent_end = extent.end;
    pr.positions.assign(pair.node_arc.data(), pair.node_arc.data() + pair.node_arc.size());
    pr.pressures.assign(pn.data(), pn.data() + pn.size());
    r.active_nodes += pr.active_nodes;
    r.active_set_changes += pr.changed_nodes;
    r.pairs.push_back(std::move(pr));
  }
  return r;
}

namespace {

// Stick flags of the rows at every slave node: a node inside a multiplier segment (no row of its own) sticks where
// every row its value comes from sticks.
Eigen::VectorXi stick_at_nodes(const mortar::PairDiscretization& pair, const Eigen::VectorXi& rows) {
  Eigen::VectorXi out = Eigen::VectorXi::Zero(static_cast<Eigen::Index>(pair.slave_nodes.size()));
  for (size_t j = 0; j < pair.slave_nodes.size(); ++j) {
    const auto& from = pair.node_from_rows[j];
    bool all = !from.empty();
    for (const auto& [row, weight] : from) all = all && rows[row] != 0;
    out[static_cast<Eigen::Index>(j)] = all ? 1 : 0;
  }
  return out;
}

}  // namespace

void ContactSystem::report_friction(const Pressures& z, const Pressures& q, IterationReport& report) const {
  for (size_t k = 0; k < pairs_.size() && k < report.pairs.size() && k < q.size(); ++k) {
    const auto& pair = pairs_[k];
    if (!pair.has_friction() || q[k].size() != pair.n_rows()) continue;
    PairReport& pr = report.pairs[k];
    const Eigen::VectorXd t = pair.to_nodes(-q[k], 0.0);
    pr.tangential_tractions.assign(t.data(), t.data() + t.size());
    const Eigen::VectorXi stick = stick_at_nodes(pair, pair.sticking(z[k], q[k]));
    pr.stick.assign(stick.data(), stick.data() + stick.size());
    pr.tangential_force = -pair.area.dot(q[k]);
    pr.friction = pair.friction.law == FrictionSpec::Law::coulomb ? "coulomb" : "tresca";
    pr.friction_coefficient = pair.friction.coefficient;
    pr.friction_bound = pair.friction.bound;
    pr.resultant += pair.tangential_resultant(q[k]);
  }
}

namespace {

// The friction results of a pair (PairField): tangents, the tangential traction t = -q on the slave, the
// accumulated slip (the slave's tangential displacement relative to the master's, -w / area), stick flags.
void friction_fields(const mortar::PairDiscretization& pair, const Eigen::VectorXd& us, const Eigen::VectorXd& um,
                     const Eigen::VectorXd& z, const Eigen::VectorXd& q, PairField& f) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Index n = static_cast<Eigen::Index>(pair.slave_nodes.size());
  f.friction = pair.friction.law == FrictionSpec::Law::coulomb ? "coulomb" : "tresca";
  f.friction_coefficient = pair.friction.coefficient;
  f.friction_bound = pair.friction.bound;
  f.tangent.resize(n, 2);
  for (Eigen::Index j = 0; j < n; ++j) f.tangent.row(j) << -f.normal(j, 1), f.normal(j, 0);
  f.tangential_traction = pair.to_nodes(-q, 0.0);
  f.slip = pair.to_nodes((-pair.weighted_jump(us, um)).cwiseQuotient(pair.area), nan);
  f.stick = stick_at_nodes(pair, pair.sticking(z, q));
  f.tangential_force = -pair.area.dot(q);
  f.resultant += pair.tangential_resultant(q);
}

}  // namespace

namespace {

// The support reactions per displacement condition: only the components it prescribes (a corner node's other
// component is another support's).
std::vector<BodyField::SupportReaction> support_reactions(const Body& body, const Eigen::MatrixX2d& reaction) {
  std::vector<BodyField::SupportReaction> out;
  for (const auto& bc : body.boundary) {
    if (!prescribes_displacement(bc)) continue;
    BodyField::SupportReaction s{bc.vertex.empty() ? bc.edge : bc.vertex, Eigen::Vector2d::Zero()};
    for (int node : condition_nodes(body.mesh, bc)) {
      if (bc.ux) s.force.x() += reaction(node, 0);
      if (bc.uy) s.force.y() += reaction(node, 1);
    }
    out.push_back(std::move(s));
  }
  return out;
}

// A floating body's rigid part R alpha as a translation of the nodes' centroid and a rotation about it (exact fit).
Eigen::Vector3d rigid_motion(const mesh::Mesh& mesh, const Eigen::Vector2d& center, const Eigen::VectorXd& v) {
  const int n = mesh.num_nodes();
  Eigen::MatrixXd A(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d d = mesh.nodes[static_cast<size_t>(i)] - center;
    A.row(2 * i) << 1.0, 0.0, -d.y();
    A.row(2 * i + 1) << 0.0, 1.0, d.x();
  }
  return A.colPivHouseholderQr().solve(v);
}

// A pair's normals at every slave node: a row's contact normal, elsewhere the mean of the adjacent slave segments'
// outward normals (on a closed slave edge the segment from the last node to the first is one of them).
Eigen::MatrixX2d node_normals(const mortar::PairDiscretization& pair, const Eigen::MatrixX2d& position) {
  const Eigen::Index n = position.rows();
  Eigen::MatrixX2d normal = Eigen::MatrixX2d::Zero(n, 2);
  for (Eigen::Index j = 0; j < n; ++j) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (Eigen::Index s : {j - 1, j}) {
      if (pair.closed && n > 1) s = (s + n) % n;
      if (s >= 0 && s < n && (s + 1 < n || pair.closed))
        sum += mortar::outward_normal(position.row(s).transpose(), position.row((s + 1) % n).transpose());
    }
    if (sum.norm() > 0) normal.row(j) = sum.normalized().transpose();
  }
  for (size_t r = 0; r < pair.node_of_row.size(); ++r) normal.row(pair.node_of_row[r]) = pair.normal[r].transpose();
  return normal;
}

}  // namespace

void ContactSystem::stresses_and_reactions(const Displacements& u, const Displacements& loads, const fem::LoadPoint& at,
                                           std::vector<fem::StressFields>& stress,
                                           std::vector<Eigen::VectorXd>& reaction) const {
  stress.assign(bodies_.size(), {});
  reaction.assign(bodies_.size(), {});
  const parallel::BodyShare share{[&](size_t a, parallel::Packer& out) {
                                    out.put(stress[a].cell);
                                    out.put(stress[a].node);
                                    out.put(stress[a].von_mises_cell);
                                    out.put(reaction[a]);
                                  },
                                  [&](size_t a, parallel::Unpacker& in) {
                                    stress[a].cell = in.get_matrix();
                                    stress[a].node = in.get_matrix();
                                    stress[a].von_mises_cell = in.get_vector();
                                    reaction[a] = in.get_vector();
                                  }};
  // On each body's owner (the reactions need its assembled loads).
  runner_.run_bodies(
      bodies_.size(),
      [&](size_t a) {
        stress[a] = bodies_[a]->stresses(u[a]);
        reaction[a] = bodies_[a]->reactions(u[a], loads[a], at);
      },
      share);
}

BodyField ContactSystem::body_field(size_t a, const Eigen::VectorXd& u, fem::StressFields stress,
                                    const Eigen::VectorXd& reaction, const Eigen::VectorXd* rigid_amplitudes) const {
  const Body& body = problem_.bodies[a];
  BodyField f;
  f.name = body.name;
  f.mesh = body.mesh;
  const int n = body.mesh.num_nodes();
  f.displacement = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(u.data(), n, 2);
  f.stress_cell = std::move(stress.cell);
  f.stress_node = std::move(stress.node);
  f.von_mises_cell = std::move(stress.von_mises_cell);
  f.reaction = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(reaction.data(), n, 2);
  f.reaction_total = f.reaction.colwise().sum().transpose();
  f.support_reactions = support_reactions(body, f.reaction);
  if (bodies_[a]->floating()) {
    f.free_motions = bodies_[a]->rigid_mode_names();
    f.rigid_center = Eigen::Vector2d::Zero();
    for (const auto& p : body.mesh.nodes) f.rigid_center += p / n;
    if (rigid_amplitudes && rigid_amplitudes->size() == bodies_[a]->rigid_modes().cols())
      f.rigid_motion = rigid_motion(body.mesh, f.rigid_center, bodies_[a]->rigid_modes() * *rigid_amplitudes);
  }
  return f;
}

PairField ContactSystem::pair_field(size_t k, const Displacements& u, const Eigen::VectorXd& z,
                                    const Eigen::VectorXd* q) const {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto& pair = pairs_[k];
  const ContactPair& spec = problem_.contacts[k];
  const auto& us = u[static_cast<size_t>(pair.slave_body)];
  const auto& um = u[static_cast<size_t>(pair.master_body)];
  PairField f;
  f.name = pair.name;
  f.slave_body = problem_.bodies[static_cast<size_t>(spec.slave_body)].name;
  f.master_body = problem_.bodies[static_cast<size_t>(spec.master_body)].name;
  f.slave_edge = spec.slave_edge;
  f.master_edge = spec.master_edge;
  f.enforcement = to_string(problem_.solver.enforcement);
  f.theta = problem_.solver.enforcement == Enforcement::exact ? 0.0 : pair.theta;
  const auto& mesh = problem_.bodies[static_cast<size_t>(spec.slave_body)].mesh;
  const Eigen::Index n = static_cast<Eigen::Index>(pair.slave_nodes.size());
  f.position.resize(n, 2);
  f.node.resize(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    f.node[j] = pair.slave_nodes[static_cast<size_t>(j)];
    f.position.row(j) = mesh.nodes[static_cast<size_t>(f.node[j])].transpose();
  }
  f.normal = node_normals(pair, f.position);
  f.arc_length = pair.node_arc;
  f.weight = pair.rows_at_nodes(pair.area, 0.0);
  f.gap = pair.to_nodes(pair.gap0.cwiseQuotient(pair.area), nan);
  const Eigen::VectorXd g = pair.nodal_gap(us, um);
  f.normal_gap = pair.to_nodes(g, nan);
  f.pressure = pair.to_nodes(z, 0.0);
  f.penetration = pair.to_nodes((-g).cwiseMax(0.0), 0.0);
  f.active.resize(n);
  f.status.resize(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    f.active[j] = f.pressure[j] > 0 ? 1 : 0;
    f.status[j] = static_cast<int>(pair.status[static_cast<size_t>(j)]);
  }
  f.force = pair.total_force(z);
  f.resultant = pair.resultant(z);
  if (pair.has_friction() && q && q->size() == pair.n_rows()) friction_fields(pair, us, um, z, *q, f);
  return f;
}

Step ContactSystem::fields(const Displacements& u, const Pressures& z, int iteration, const RunState& state,
                           const std::vector<Eigen::VectorXd>* rigid_amplitudes, const Pressures* q) const {
  Step step;
  step.iteration = iteration;
  std::vector<fem::StressFields> stress;
  std::vector<Eigen::VectorXd> reaction;
  stresses_and_reactions(u, loads_from_pressures(z, q), state.load, stress, reaction);
  for (size_t a = 0; a < bodies_.size(); ++a) {
    const Eigen::VectorXd* alpha = rigid_amplitudes && a < rigid_amplitudes->size() ? &(*rigid_amplitudes)[a] : nullptr;
    step.bodies.push_back(body_field(a, u[a], std::move(stress[a]), reaction[a], alpha));
  }
  for (size_t k = 0; k < pairs_.size(); ++k)
    step.pairs.push_back(pair_field(k, u, z[k], q && k < q->size() ? &(*q)[k] : nullptr));
  share_carried_values(step.pairs);
  for (auto& pair : step.pairs) pair.joint = joint_results(pair);
  return step;
}

// In a group of pairs that share one contact surface (mortar/pair_group.hpp) each slave node is carried by one pair;
// the others list it with status 5 (other_pair). Its values there are the carrying pair's: the one that lists the
// same slave node carrying a multiplier (status 0) or inside one of its multiplier segments (4). Without this a
// reader of one pair saw half its nodes at pressure 0 where the contact is closed.
void ContactSystem::share_carried_values(std::vector<PairField>& pairs) const {
  for (size_t k = 0; k < pairs.size(); ++k) {
    PairField& f = pairs[k];
    if ((f.status.array() != static_cast<int>(mortar::NodeStatus::other_pair)).all()) continue;
    // The carrying entries of the group's other pairs, by slave node.
    std::map<int, std::pair<size_t, Eigen::Index>> carried;
    for (const int other : mortar::pair_group(problem_, static_cast<int>(k)).pairs) {
      const auto o = static_cast<size_t>(other);
      if (o == k || o >= pairs.size()) continue;
      const PairField& g = pairs[o];
      for (Eigen::Index j = 0; j < g.status.size(); ++j)
        if (g.status[j] == static_cast<int>(mortar::NodeStatus::contact) ||
            g.status[j] == static_cast<int>(mortar::NodeStatus::inner))
          carried.emplace(g.node[j], std::make_pair(o, j));
    }
    for (Eigen::Index j = 0; j < f.status.size(); ++j) {
      if (f.status[j] != static_cast<int>(mortar::NodeStatus::other_pair)) continue;
      const auto it = carried.find(f.node[j]);
      if (it == carried.end()) continue;
      const PairField& g = pairs[it->second.first];
      const Eigen::Index i = it->second.second;
      f.gap[j] = g.gap[i];
      f.normal_gap[j] = g.normal_gap[i];
      f.pressure[j] = g.pressure[i];
      f.penetration[j] = g.penetration[i];
      f.active[j] = g.active[i];
      if (f.tangential_traction.size() == f.status.size() && g.tangential_traction.size() == g.status.size()) {
        f.tangential_traction[j] = g.tangential_traction[i];
        f.slip[j] = g.slip[i];
        f.stick[j] = g.stick[i];
      }
    }
  }
}

}  // namespace contact::ddm
