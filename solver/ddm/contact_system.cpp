#include "contact_system.hpp"

#include "../fem/blas_threads.hpp"

#include <chrono>

namespace contact::ddm {

double relative_change(const Eigen::VectorXd& now, const Eigen::VectorXd& before) {
  const double scale = std::max(now.norm(), before.norm());
  return scale > 0 ? (now - before).norm() / scale : 0.0;
}

ContactSystem::ContactSystem(const Problem& problem, TaskRunner& runner, bool factorize)
    : problem_(problem), factorize_(factorize) {
  const auto t0 = std::chrono::steady_clock::now();
  fem::limit_blas_threads();
  bodies_.resize(problem.bodies.size());
  runner.run(bodies_.size(), [&](size_t a) {
    bodies_[a] = std::make_unique<fem::BodySolver>(problem.bodies[a], problem.model, factorize);
  });
  for (const auto& b : bodies_) {
    if (!b->ok()) error_ += (error_.empty() ? "" : "; ") + b->error();
    factorization_seconds_ += b->factorization_seconds();
  }
  if (!ok()) return;
  for (int k = 0; k < static_cast<int>(problem.contacts.size()); ++k) {
    penalties_.push_back(interface::choose_penalty(problem, k));
    pairs_.push_back(interface::discretize_pair(problem, k, penalties_.back().theta));
    if (!(penalties_.back().theta > 0))
      error_ += (error_.empty() ? "" : "; ") + ("contact '" + pairs_.back().name + "': the penalty theta is not positive");
  }
  setup_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void ContactSystem::rebuild(const std::vector<char>& changed, TaskRunner& runner) {
  std::vector<size_t> todo;
  for (size_t a = 0; a < bodies_.size(); ++a)
    if (changed[a]) todo.push_back(a);
  runner.run(todo.size(), [&](size_t i) {
    const size_t a = todo[i];
    bodies_[a] = std::make_unique<fem::BodySolver>(problem_.bodies[a], problem_.model, factorize_);
  });
  for (size_t a : todo) {
    if (!bodies_[a]->ok()) error_ += (error_.empty() ? "" : "; ") + bodies_[a]->error();
    factorization_seconds_ += bodies_[a]->factorization_seconds();
  }
  pairs_.clear();
  penalties_.clear();
  for (int k = 0; k < static_cast<int>(problem_.contacts.size()); ++k) {
    penalties_.push_back(interface::choose_penalty(problem_, k));
    pairs_.push_back(interface::discretize_pair(problem_, k, penalties_.back().theta));
  }
}

Displacements ContactSystem::loads_from_pressures(const std::vector<Eigen::VectorXd>& pressures) const {
  Displacements f(bodies_.size());
  for (size_t a = 0; a < bodies_.size(); ++a) f[a] = Eigen::VectorXd::Zero(bodies_[a]->n_dofs());
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const auto& p = pairs_[k];
    pairs_[k].add_forces(pressures[k], f[static_cast<size_t>(p.slave_body)], f[static_cast<size_t>(p.master_body)]);
  }
  return f;
}

Displacements ContactSystem::contact_loads(const Displacements& u, std::vector<Eigen::VectorXd>* pressures) const {
  std::vector<Eigen::VectorXd> p(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const auto& pair = pairs_[k];
    p[k] = pair.pressure(pair.normal_gap(u[static_cast<size_t>(pair.slave_body)], u[static_cast<size_t>(pair.master_body)]));
  }
  Displacements f = loads_from_pressures(p);
  if (pressures) *pressures = std::move(p);
  return f;
}

Eigen::VectorXd ContactSystem::zone_normals(size_t a, const Eigen::VectorXd& u_a) const {
  std::vector<Eigen::VectorXd> parts;
  Eigen::Index n = 0;
  for (const auto& pair : pairs_) {
    // u_1n = -n . u_1 (slave normal ~ -n), u_2n = n . u_2 (paper's normals)
    if (static_cast<size_t>(pair.slave_body) == a) parts.push_back(-(pair.Hs * u_a));
    if (static_cast<size_t>(pair.master_body) == a) parts.push_back(pair.Hm * u_a);
  }
  for (const auto& v : parts) n += v.size();
  Eigen::VectorXd out(n);
  Eigen::Index at = 0;
  for (const auto& v : parts) {
    out.segment(at, v.size()) = v;
    at += v.size();
  }
  return out;
}

Displacements ContactSystem::solve_bodies(const Displacements& loads, TaskRunner& runner) const {
  Displacements u(bodies_.size());
  runner.run(bodies_.size(), [&](size_t a) { u[a] = bodies_[a]->solve(loads[a]); });
  return u;
}

Displacements ContactSystem::elastic_layer_guess(TaskRunner& runner) const {
  // Each body's response to its own loads with free contact zones; where the rigid approach (the overlap of
  // these free responses) exceeds the gap, each layer of height h_a under uniaxial strain (modulus M_a)
  // carries the pressure (approach - d) / (h_1/M_1 + h_2/M_2); the initial displacements are each body's
  // response to that pressure.
  const Displacements free_u = solve_bodies(Displacements(bodies_.size()), runner);
  auto M = [&](int body) {
    const Material& m = problem_.bodies[static_cast<size_t>(body)].material;
    if (problem_.model.plane == Plane::strain) return m.E * (1 - m.nu) / ((1 + m.nu) * (1 - 2 * m.nu));
    return m.E / (1 - m.nu * m.nu);
  };
  std::vector<Eigen::VectorXd> p(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const auto& pair = pairs_[k];
    const double compliance = penalties_[k].slave_height / M(pair.slave_body) + penalties_[k].master_height / M(pair.master_body);
    const Eigen::VectorXd g = pair.normal_gap(free_u[static_cast<size_t>(pair.slave_body)], free_u[static_cast<size_t>(pair.master_body)]);
    p[k] = Eigen::VectorXd::Zero(g.size());
    for (Eigen::Index q = 0; q < g.size(); ++q)
      if (pair.weight[q] > 0) p[k][q] = std::max(0.0, -g[q]) / compliance;
  }
  return solve_bodies(loads_from_pressures(p), runner);
}

IterationReport ContactSystem::report(int iteration, const Displacements& u, std::vector<std::vector<char>>& previous_active) const {
  IterationReport r;
  r.iteration = iteration;
  for (size_t a = 0; a < bodies_.size(); ++a)
    r.bodies.push_back({problem_.bodies[a].name, problem_.bodies[a].mesh.num_cells(), bodies_[a]->n_free(), 0});
  previous_active.resize(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const auto& pair = pairs_[k];
    const auto& us = u[static_cast<size_t>(pair.slave_body)];
    const auto& um = u[static_cast<size_t>(pair.master_body)];
    const Eigen::VectorXd p = pair.pressure(pair.normal_gap(us, um));
    PairReport pr;
    pr.name = pair.name;
    pr.theta = pair.theta;
    pr.force = pair.total_force(p);
    auto& prev = previous_active[k];
    const bool had_previous = prev.size() == static_cast<size_t>(p.size());
    prev.resize(static_cast<size_t>(p.size()), 0);
    bool first = true;
    for (Eigen::Index q = 0; q < p.size(); ++q) {
      const char active = p[q] > 0 ? 1 : 0;
      if (had_previous && active != prev[static_cast<size_t>(q)]) ++pr.changed_points;
      prev[static_cast<size_t>(q)] = active;
      if (!active) continue;
      ++pr.active_points;
      if (first) pr.extent_begin = pair.arc[q];
      pr.extent_end = pair.arc[q];
      first = false;
    }
    const Eigen::VectorXd gn = pair.node_normal_gap(us, um);
    const Eigen::VectorXd pn = pair.node_pressure(gn, p);
    pr.positions.assign(pair.node_arc.data(), pair.node_arc.data() + pair.node_arc.size());
    pr.pressures.assign(pn.data(), pn.data() + pn.size());
    for (Eigen::Index j = 0; j < pn.size(); ++j) {
      pr.max_pressure = std::max(pr.max_pressure, pn[j]);
      if (pair.node_has_master[j]) pr.max_penetration = std::max(pr.max_penetration, -gn[j]);
    }
    r.pairs.push_back(std::move(pr));
  }
  return r;
}

Step ContactSystem::fields(const Displacements& u, int iteration) const {
  Step step;
  step.iteration = iteration;
  const Displacements loads = contact_loads(u);
  for (size_t a = 0; a < bodies_.size(); ++a) {
    const Body& body = problem_.bodies[a];
    BodyField f;
    f.name = body.name;
    f.mesh = body.mesh;
    const int n = body.mesh.num_nodes();
    f.displacement = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(u[a].data(), n, 2);
    const auto s = bodies_[a]->stresses(u[a]);
    f.stress_cell = s.cell;
    f.stress_node = s.node;
    f.von_mises_cell = s.von_mises_cell;
    const Eigen::VectorXd R = bodies_[a]->reactions(u[a], loads[a]);
    f.reaction = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(R.data(), n, 2);
    step.bodies.push_back(std::move(f));
  }
  for (size_t k = 0; k < pairs_.size(); ++k) {
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
    f.theta = pair.theta;
    const auto& mesh = problem_.bodies[static_cast<size_t>(spec.slave_body)].mesh;
    const Eigen::Index n = static_cast<Eigen::Index>(pair.slave_nodes.size());
    f.position.resize(n, 2);
    for (Eigen::Index j = 0; j < n; ++j) f.position.row(j) = mesh.nodes[static_cast<size_t>(pair.slave_nodes[static_cast<size_t>(j)])].transpose();
    f.arc_length = pair.node_arc;
    f.gap = pair.node_gap;
    f.normal_gap = pair.node_normal_gap(us, um);
    f.pressure = pair.node_pressure(f.normal_gap, pair.pressure(pair.normal_gap(us, um)));
    f.penetration.resize(n);
    f.active.resize(n);
    for (Eigen::Index j = 0; j < n; ++j) {
      const bool has = pair.node_has_master[j] != 0;
      f.penetration[j] = has ? std::max(0.0, -f.normal_gap[j]) : 0.0;
      f.active[j] = f.pressure[j] > 0 ? 1 : 0;
    }
    f.force = pair.total_force(pair.pressure(pair.normal_gap(us, um)));
    step.pairs.push_back(std::move(f));
  }
  return step;
}

}  // namespace contact::ddm
