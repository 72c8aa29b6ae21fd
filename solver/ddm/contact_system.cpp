#include "contact_system.hpp"

#include "../contact/extent.hpp"
#include "../contact/segments.hpp"
#include "../common/scoped_timer.hpp"
#include "../fem/blas_threads.hpp"

#include <Eigen/QR>

#include <chrono>
#include <cmath>
#include <limits>

namespace contact::ddm {

double relative_change(const Eigen::VectorXd& now, const Eigen::VectorXd& before) {
  const double scale = std::max(now.norm(), before.norm());
  return scale > 0 ? (now - before).norm() / scale : 0.0;
}

namespace {

void append_error(std::string& errors, const std::string& e) { errors += (errors.empty() ? "" : "; ") + e; }

// The errors of the bodies that failed, the first few in full and the others by name (a wall of a hundred
// bricks must not give a hundred copies of one message).
std::string body_errors(const std::vector<std::pair<std::string, std::string>>& failed) {
  constexpr size_t kInFull = 3;
  std::string out;
  for (size_t k = 0; k < failed.size() && k < kInFull; ++k) append_error(out, failed[k].second);
  if (failed.size() > kInFull) {
    constexpr size_t kNamed = 20;
    std::string names;
    for (size_t k = kInFull; k < failed.size() && k < kInFull + kNamed; ++k)
      names += (k == kInFull ? "'" : ", '") + failed[k].first + "'";
    if (failed.size() > kInFull + kNamed) names += ", ...";
    out += "; " + std::to_string(failed.size() - kInFull) + " more bodies failed too: " + names;
  }
  return out;
}

}  // namespace

ContactSystem::ContactSystem(const Problem& problem, parallel::TaskRunner& runner, Factorization factorization,
                             const CancelToken* cancel)
    : problem_(problem), factorization_(factorization), runner_(runner) {
  ScopedTimer timer(setup_seconds_);
  fem::limit_blas_threads();
  discretize_pairs();
  bodies_.resize(problem.bodies.size());
  std::vector<size_t> all(bodies_.size());
  for (size_t a = 0; a < all.size(); ++a) all[a] = a;
  build_bodies(all, runner, cancel);
}

std::unique_ptr<fem::BodySolver> ContactSystem::make_body(size_t a, bool local, const CancelToken* cancel) const {
  std::function<bool()> cancelled;
  if (cancel) cancelled = [cancel] { return cancel->cancelled(); };
  auto b = std::make_unique<fem::BodySolver>(problem_.bodies[a], problem_.model, factorization_ != Factorization::none,
                                             interface_dofs(a), may_float(a), local, std::move(cancelled));
  b->set_load_step(load_step_, load_factor_);
  return b;
}

void ContactSystem::build_bodies(const std::vector<size_t>& todo, parallel::TaskRunner& runner, const CancelToken* cancel) {
  runner.run_bodies(todo, [&](size_t a) {
    bodies_[a].reset();  // free the old factorisation first
    bodies_[a] = make_body(a, true, cancel);
  }, body_outcome_share());
  std::vector<std::pair<std::string, std::string>> failed;
  for (size_t a : todo) {
    if (bodies_[a]->was_cancelled())
      cancelled_ = true;  // not an error: the caller sees its token
    else if (!bodies_[a]->ok())
      failed.emplace_back(problem_.bodies[a].name, bodies_[a]->error());
    factorization_seconds_ += bodies_[a]->factorization_seconds();
  }
  append_error(error_, body_errors(failed));
}

parallel::BodyShare ContactSystem::body_outcome_share() {
  // The owner's outcome (an error such as a singular stiffness, the factorisation time); the other processes set
  // up the body's constraints and rigid modes themselves (the same on every process).
  return {[this](size_t a, parallel::Packer& out) {
            out.put(bodies_[a]->error());
            out.put(bodies_[a]->factorization_seconds());
          },
          [this](size_t a, parallel::Unpacker& in) {
            bodies_[a] = make_body(a, false);
            const std::string error = in.get_string();
            bodies_[a]->adopt_outcome(error, in.get_double());
          }};
}

void ContactSystem::discretize_pairs() {
  pairs_.clear();
  penalties_.clear();
  for (int k = 0; k < static_cast<int>(problem_.contacts.size()); ++k) {
    penalties_.push_back(mortar::choose_penalty(problem_, k));
    pairs_.push_back(mortar::discretize_pair(problem_, k, penalties_.back().theta));
    if (!(penalties_.back().theta > 0))
      append_error(error_, "contact '" + pairs_.back().name + "': the penalty theta is not positive");
  }
}

bool ContactSystem::may_float(size_t a) const {
  if (factorization_ == Factorization::plain) return false;  // the fixed-point schemes solve every body alone
  for (const auto& c : problem_.contacts)
    if (static_cast<size_t>(c.slave_body) == a || static_cast<size_t>(c.master_body) == a) return true;
  return false;
}

std::vector<int> ContactSystem::interface_dofs(size_t a) const {
  std::vector<int> dofs;
  if (factorization_ != Factorization::interface) return dofs;
  auto collect = [&](const mortar::SparseRows& G) {
    for (int r = 0; r < G.outerSize(); ++r)
      for (mortar::SparseRows::InnerIterator it(G, r); it; ++it) dofs.push_back(static_cast<int>(it.col()));
  };
  for (const auto& pair : pairs_) {
    if (static_cast<size_t>(pair.slave_body) == a) collect(pair.Gs);
    if (static_cast<size_t>(pair.master_body) == a) collect(pair.Gm);
    if (pair.has_friction() && static_cast<size_t>(pair.slave_body) == a) collect(pair.Ts);
    if (pair.has_friction() && static_cast<size_t>(pair.master_body) == a) collect(pair.Tm);
  }
  std::sort(dofs.begin(), dofs.end());
  dofs.erase(std::unique(dofs.begin(), dofs.end()), dofs.end());
  return dofs;
}

void ContactSystem::rebuild(const std::vector<char>& changed, parallel::TaskRunner& runner, const CancelToken* cancel) {
  discretize_pairs();
  std::vector<size_t> todo;
  for (size_t a = 0; a < bodies_.size(); ++a)
    if (changed[a] || (factorization_ == Factorization::interface && interface_dofs(a) != bodies_[a]->interface_dofs()))
      todo.push_back(a);
  build_bodies(todo, runner, cancel);
}

Pressures ContactSystem::penalty_pressures(const Displacements& u) const {
  Pressures z(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const auto& pair = pairs_[k];
    z[k] = pair.penalty_pressure(pair.nodal_gap(u[static_cast<size_t>(pair.slave_body)], u[static_cast<size_t>(pair.master_body)]));
  }
  return z;
}

Displacements ContactSystem::loads_from_pressures(const Pressures& z, const Pressures* q) const {
  Displacements f(bodies_.size());
  for (size_t a = 0; a < bodies_.size(); ++a) f[a] = Eigen::VectorXd::Zero(bodies_[a]->n_dofs());
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const auto& p = pairs_[k];
    p.add_forces(z[k], f[static_cast<size_t>(p.slave_body)], f[static_cast<size_t>(p.master_body)]);
    if (q && k < q->size())
      p.add_tangential_forces((*q)[k], f[static_cast<size_t>(p.slave_body)], f[static_cast<size_t>(p.master_body)]);
  }
  return f;
}

bool ContactSystem::has_histories() const {
  for (const auto& b : bodies_)
    if (b->has_histories()) return true;
  for (const auto& body : problem_.bodies)  // bodies of other processes are not assembled here
    for (const auto& bc : body.boundary)
      if (!bc.history.empty()) return true;
  return false;
}

void ContactSystem::accept_step(const Displacements& u) {
  for (auto& pair : pairs_)
    if (pair.has_friction())
      pair.jump_origin = pair.weighted_jump(u[static_cast<size_t>(pair.slave_body)], u[static_cast<size_t>(pair.master_body)]);
}

Displacements ContactSystem::contact_loads(const Displacements& u, Pressures* pressures) const {
  Pressures z = penalty_pressures(u);
  Displacements f = loads_from_pressures(z);
  if (pressures) *pressures = std::move(z);
  return f;
}

Eigen::VectorXd ContactSystem::zone_normals(size_t a, const Eigen::VectorXd& u_a) const {
  std::vector<Eigen::VectorXd> parts;
  for (const auto& pair : pairs_) {
    // u_1n = nu . u_1 at the slave node, u_2n = -(mortar projection of u_2) . nu (the paper's normals).
    if (static_cast<size_t>(pair.slave_body) == a) parts.push_back((pair.Gs * u_a).cwiseQuotient(pair.area));
    if (static_cast<size_t>(pair.master_body) == a) parts.push_back(-(pair.Gm * u_a).cwiseQuotient(pair.area));
  }
  Eigen::Index n = 0;
  for (const auto& v : parts) n += v.size();
  Eigen::VectorXd out(n);
  Eigen::Index at = 0;
  for (const auto& v : parts) {
    out.segment(at, v.size()) = v;
    at += v.size();
  }
  return out;
}

Displacements ContactSystem::solve_bodies(const Displacements& loads, parallel::TaskRunner& runner) const {
  Displacements u(bodies_.size());
  runner.run_bodies(bodies_.size(), [&](size_t a) { u[a] = bodies_[a]->solve(loads[a]); }, share_vectors(u));
  return u;
}

parallel::BodyShare share_vectors(std::vector<Eigen::VectorXd>& v) {
  return {[&v](size_t a, parallel::Packer& out) { out.put(v[a]); }, [&v](size_t a, parallel::Unpacker& in) { v[a] = in.get_vector(); }};
}

Displacements ContactSystem::elastic_layer_guess(parallel::TaskRunner& runner) const {
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
  Pressures z(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const auto& pair = pairs_[k];
    const double compliance = penalties_[k].slave_height / M(pair.slave_body) + penalties_[k].master_height / M(pair.master_body);
    const Eigen::VectorXd g = pair.nodal_gap(free_u[static_cast<size_t>(pair.slave_body)], free_u[static_cast<size_t>(pair.master_body)]);
    z[k] = (-g).cwiseMax(0.0) / compliance;
  }
  return solve_bodies(loads_from_pressures(z), runner);
}

Pressures ContactSystem::nodal_gaps(const Displacements& u) const {
  Pressures g(pairs_.size());
  for (size_t k = 0; k < pairs_.size(); ++k)
    g[k] = pairs_[k].nodal_gap(u[static_cast<size_t>(pairs_[k].slave_body)], u[static_cast<size_t>(pairs_[k].master_body)]);
  return g;
}

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
    const mortar::ContactExtent extent = mortar::contact_extent(pair.node_arc, pn);
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

Step ContactSystem::fields(const Displacements& u, const Pressures& z, int iteration,
                           const std::vector<Eigen::VectorXd>* rigid_amplitudes, const Pressures* q) const {
  Step step;
  step.iteration = iteration;
  const Displacements loads = loads_from_pressures(z, q);
  // Stresses and support reactions on each body's owner (the reactions need its assembled loads).
  std::vector<fem::StressFields> stress(bodies_.size());
  std::vector<Eigen::VectorXd> reaction(bodies_.size());
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
  runner_.run_bodies(bodies_.size(), [&](size_t a) {
    stress[a] = bodies_[a]->stresses(u[a]);
    reaction[a] = bodies_[a]->reactions(u[a], loads[a]);
  }, share);
  for (size_t a = 0; a < bodies_.size(); ++a) {
    const Body& body = problem_.bodies[a];
    BodyField f;
    f.name = body.name;
    f.mesh = body.mesh;
    const int n = body.mesh.num_nodes();
    f.displacement = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(u[a].data(), n, 2);
    f.stress_cell = stress[a].cell;
    f.stress_node = stress[a].node;
    f.von_mises_cell = stress[a].von_mises_cell;
    const Eigen::VectorXd& R = reaction[a];
    f.reaction = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(R.data(), n, 2);
    f.reaction_total = f.reaction.colwise().sum().transpose();
    for (const auto& bc : body.boundary) {
      if (!prescribes_displacement(bc)) continue;
      BodyField::SupportReaction s{bc.vertex.empty() ? bc.edge : bc.vertex, Eigen::Vector2d::Zero()};
      // Only the components this condition prescribes: a corner node's other component is another support's.
      for (int node : condition_nodes(body.mesh, bc)) {
        if (bc.ux) s.force.x() += f.reaction(node, 0);
        if (bc.uy) s.force.y() += f.reaction(node, 1);
      }
      f.support_reactions.push_back(std::move(s));
    }
    if (bodies_[a]->floating()) {
      f.free_motions = bodies_[a]->rigid_mode_names();
      // The rigid part R alpha as a translation of the nodes' centroid and a rotation about it (exact fit).
      f.rigid_center = Eigen::Vector2d::Zero();
      for (const auto& p : body.mesh.nodes) f.rigid_center += p / n;
      if (rigid_amplitudes && a < rigid_amplitudes->size() && (*rigid_amplitudes)[a].size() == bodies_[a]->rigid_modes().cols()) {
        const Eigen::VectorXd v = bodies_[a]->rigid_modes() * (*rigid_amplitudes)[a];
        Eigen::MatrixXd A(2 * n, 3);
        for (int i = 0; i < n; ++i) {
          const Eigen::Vector2d d = body.mesh.nodes[static_cast<size_t>(i)] - f.rigid_center;
          A.row(2 * i) << 1.0, 0.0, -d.y();
          A.row(2 * i + 1) << 0.0, 1.0, d.x();
        }
        f.rigid_motion = A.colPivHouseholderQr().solve(v);
      }
    }
    step.bodies.push_back(std::move(f));
  }
  const char* enforcement = problem_.solver.enforcement == Enforcement::exact     ? "exact"
                            : problem_.solver.enforcement == Enforcement::penalty ? "penalty"
                                                                                   : "augmented_lagrangian";
  const double nan = std::numeric_limits<double>::quiet_NaN();
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
    f.enforcement = enforcement;
    f.theta = problem_.solver.enforcement == Enforcement::exact ? 0.0 : pair.theta;
    const auto& mesh = problem_.bodies[static_cast<size_t>(spec.slave_body)].mesh;
    const Eigen::Index n = static_cast<Eigen::Index>(pair.slave_nodes.size());
    f.position.resize(n, 2);
    f.node.resize(n);
    for (Eigen::Index j = 0; j < n; ++j) {
      f.node[j] = pair.slave_nodes[static_cast<size_t>(j)];
      f.position.row(j) = mesh.nodes[static_cast<size_t>(f.node[j])].transpose();
    }
    // Normals: a row's contact normal, elsewhere the mean of the adjacent slave segments' outward normals.
    f.normal = Eigen::MatrixX2d::Zero(n, 2);
    for (Eigen::Index j = 0; j < n; ++j) {
      Eigen::Vector2d sum = Eigen::Vector2d::Zero();
      for (Eigen::Index s : {j - 1, j})
        if (s >= 0 && s + 1 < n) sum += mortar::outward_normal(f.position.row(s).transpose(), f.position.row(s + 1).transpose());
      if (sum.norm() > 0) f.normal.row(j) = sum.normalized().transpose();
    }
    for (size_t r = 0; r < pair.node_of_row.size(); ++r) f.normal.row(pair.node_of_row[r]) = pair.normal[r].transpose();
    f.arc_length = pair.node_arc;
    f.weight = pair.rows_at_nodes(pair.area, 0.0);
    f.gap = pair.to_nodes(pair.gap0.cwiseQuotient(pair.area), nan);
    const Eigen::VectorXd g = pair.nodal_gap(us, um);
    f.normal_gap = pair.to_nodes(g, nan);
    f.pressure = pair.to_nodes(z[k], 0.0);
    f.penetration = pair.to_nodes((-g).cwiseMax(0.0), 0.0);
    f.active.resize(n);
    f.status.resize(n);
    for (Eigen::Index j = 0; j < n; ++j) {
      f.active[j] = f.pressure[j] > 0 ? 1 : 0;
      f.status[j] = static_cast<int>(pair.status[static_cast<size_t>(j)]);
    }
    f.force = pair.total_force(z[k]);
    f.resultant = pair.resultant(z[k]);
    if (pair.has_friction() && q && k < q->size() && (*q)[k].size() == pair.n_rows())
      friction_fields(pair, us, um, z[k], (*q)[k], f);
    step.pairs.push_back(std::move(f));
  }
  return step;
}

}  // namespace contact::ddm
