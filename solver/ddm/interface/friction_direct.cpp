#include "friction_direct.hpp"

#include "../../linalg/friction_nested.hpp"

#include <cmath>
#include <limits>
#include <sstream>

namespace contact::ddm {

namespace {

using linalg::Contact;
using linalg::FrictionRow;
using linalg::FrictionSets;

// The first sets: the frictionless normal problem's (with the equilibrium normal pressures can meet; from nested
// coarse solves, which keeps the number of steps independent of the mesh, also at a new load step, where the
// previous step's sets would move the zone's edge by a few nodes per step); where that fails, the warm start's
// prediction, or every normal row active (floating bodies) or those that overlap. Every node in contact sticks:
// the tied problem under the loads is well posed (friction holds the floating bodies). The solver then predicts
// better sets from coarse friction solves (first_sets_from_coarse) and comes back here if those fail.
FrictionSets first_sets(const SparseMatrix& F, const InterfaceQp& qp, const Eigen::VectorXd* z0,
                        const Eigen::VectorXd& alpha0, const Eigen::VectorXd& c, const std::vector<FrictionRow>& rows,
                        const std::vector<char>& mask, std::string& note) {
  const Eigen::Index n = qp.g.size(), m = qp.problem.normal_size();
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(n);
  const SparseMatrix Fnn = F.topLeftCorner(m, m);
  const Eigen::VectorXd gn = qp.g.head(m);
  const linalg::Equalities held = linalg::normal_equalities(qp.equilibrium, m);
  const std::vector<int> line(qp.line.begin(), qp.line.begin() + m);
  const Eigen::VectorXd guess = linalg::nested_initial_guess(Fnn, gn, line, qp.position.head(m), held);
  const linalg::StepCallback quiet = [](const Eigen::VectorXd&, const Eigen::VectorXd&, const linalg::ActiveSetStep&) { return true; };
  const linalg::ActiveSetResult normal = linalg::solve_active_set(Fnn, gn, 100, quiet, &guess, held);
  if (normal.converged) {
    lambda.head(m) = normal.z;
    note = "first sets from the frictionless solution (" + std::to_string(normal.steps) + " active-set steps)";
  }
  const bool solved = lambda.cwiseAbs().maxCoeff() > 0;
  if (!solved && z0 && z0->size() == n && z0->cwiseAbs().maxCoeff() > 0) {
    // The normal sets predicted from the previous answer (with its rigid amplitudes); every node in contact
    // sticking.
    Eigen::VectorXd h = qp.g + F * *z0;
    if (alpha0.size() == qp.equilibrium.G.rows() && alpha0.size() > 0) h += qp.equilibrium.G.transpose() * alpha0;
    FrictionSets s = linalg::predict_friction_sets(*z0, h, c, rows, mask);
    for (size_t t = 0; t < rows.size(); ++t)
      s.state[t] = s.active[static_cast<size_t>(rows[t].normal)] || !rows[t].coulomb ? Contact::stick : Contact::open;
    return s;
  }
  // Its pressing nodes are the first normal set (its own gaps, with its rigid amplitudes, confirm them).
  FrictionSets s;
  s.active.assign(static_cast<size_t>(n), 0);
  for (Eigen::Index j = 0; j < m; ++j)
    s.active[static_cast<size_t>(j)] = solved ? lambda[j] > 0 : !qp.equilibrium.empty() || qp.g[j] < 0;
  s.state.assign(rows.size(), Contact::open);
  s.sign.assign(rows.size(), 0);
  for (size_t t = 0; t < rows.size(); ++t)
    if (s.active[static_cast<size_t>(rows[t].normal)] || !rows[t].coulomb) s.state[t] = Contact::stick;
  return s;
}

// Why the sets' system is singular, for the message: some floating body's load along a free translation exceeds
// what its friction contacts carried at the last iterate (lambda), or, if none does, that nothing holds it.
std::string friction_shortfall(const InterfaceQp& qp, const Eigen::VectorXd& lambda) {
  const ContactSystem& system = qp.problem.system();
  const auto& pairs = system.pairs();
  for (const auto& f : qp.problem.floating()) {
    const auto& body = system.body(f.body);
    const auto& names = body.rigid_mode_names();
    const Eigen::VectorXd load = body.external_load();
    for (size_t mode = 0; mode < names.size(); ++mode) {
      if (names[mode].rfind("translation in ", 0) != 0) continue;
      const int c = names[mode].back() == 'x' ? 0 : 1;
      double required = 0, capacity = 0;
      for (Eigen::Index d = c; d < load.size(); d += 2) required += load[d];
      std::string names_of_pairs;
      for (size_t k = 0; k < pairs.size(); ++k) {
        const auto& pair = pairs[k];
        if (static_cast<size_t>(pair.slave_body) != f.body && static_cast<size_t>(pair.master_body) != f.body) continue;
        if (!pair.has_friction()) continue;
        names_of_pairs += (names_of_pairs.empty() ? "'" : ", '") + pair.name + "'";
        for (Eigen::Index r = 0; r < pair.n_rows(); ++r) {
          const double z = lambda.size() > qp.problem.offset(k) + r ? std::max(0.0, lambda[qp.problem.offset(k) + r]) : 0.0;
          const double bound = pair.friction.law == FrictionSpec::Law::coulomb ? pair.friction.coefficient * z : pair.friction.bound;
          capacity += bound * pair.area[r] * std::abs(pair.tangent[static_cast<size_t>(r)][c]);
        }
      }
      if (names_of_pairs.empty() || !(std::abs(required) > capacity)) continue;
      std::ostringstream os;
      os.precision(4);
      os << "friction cannot hold body '" << system.problem().bodies[f.body].name << "' against its load along "
         << (c == 0 ? "x" : "y") << ": its contact" << (names_of_pairs.find(',') != std::string::npos ? "s " : " ")
         << names_of_pairs << (names_of_pairs.find(',') != std::string::npos ? " carry" : " carries") << " at most "
         << capacity << " by friction at the last iterate, the load is " << std::abs(required);
      if (capacity > 0) os << " (" << std::abs(required) / capacity << " times)";
      os << "; under force control it would slide without end: lower the load, raise the friction, or "
            "prescribe the body's displacement";
      return os.str();
    }
  }
  return "the system of the stick and slip sets is singular: a floating body is held neither by normal contact nor "
         "by friction";
}

}  // namespace

std::vector<FrictionRow> friction_rows(const InterfaceProblem& problem) {
  std::vector<FrictionRow> rows;
  const auto& pairs = problem.system().pairs();
  for (size_t k = 0; k < pairs.size(); ++k) {
    const Eigen::Index t0 = problem.tangential_offset(k);
    if (t0 < 0) continue;
    const auto& f = pairs[k].friction;
    for (Eigen::Index r = 0; r < pairs[k].n_rows(); ++r)
      rows.push_back({problem.offset(k) + r, t0 + r, f.law == FrictionSpec::Law::coulomb, f.coefficient, f.bound});
  }
  return rows;
}

namespace {

// The first sets from coarse friction solves (linalg/friction_nested.hpp) over the sticking start: false (and the
// sets unchanged) when there is no coarser level or a coarse problem could not be solved.
bool first_sets_from_coarse(const SparseMatrix& F, const InterfaceQp& qp, const std::vector<FrictionRow>& rows,
                            FrictionSets& sets, std::string& note) {
  const Eigen::Index m = qp.problem.normal_size();
  if (static_cast<Eigen::Index>(qp.line.size()) < m || qp.position.size() < m) return false;
  const std::vector<int> line(qp.line.begin(), qp.line.begin() + m);  // the normal rows' (tangential: on none)
  const Eigen::VectorXd position = qp.position.head(m);
  const linalg::FrictionLevel level{F, qp.g, qp.equilibrium, rows, m, line, position};
  std::vector<int> coarse_steps;
  FrictionSets nested;
  if (!linalg::nested_friction_sets(level, nested, &coarse_steps)) return false;
  sets = std::move(nested);
  std::string steps;
  for (int k : coarse_steps) steps += (steps.empty() ? "" : ", ") + std::to_string(k);
  note += std::string(note.empty() ? "" : "; ") + "stick and slip sets from coarse friction solves (" + steps +
          " steps, finest first)";
  return true;
}

}  // namespace

linalg::ActiveSetResult FrictionDirectSolver::solve(const InterfaceQp& qp, const Eigen::VectorXd* z0,
                                                    InterfaceSolveContext& context) {
  linalg::ActiveSetResult result;
  const Eigen::Index n = qp.problem.size();
  const SparseMatrix& F = compliance_.of(qp.problem);
  const Eigen::VectorXd diagonal = F.diagonal();
  const double dmax = diagonal.cwiseAbs().maxCoeff();
  // A node whose tangential motion both sides prescribe (on a symmetry line) cannot slip: its row of F is zero and
  // its tangential traction goes into the supports; it is left out (q = 0 there).
  std::vector<FrictionRow> rows;

  for (const auto& r : friction_rows(qp.problem))
    if (diagonal[r.tangential] > 1e-12 * dmax) rows.push_back(r);
  const std::vector<char> mask = linalg::tangential_mask(n, rows);
  // c_j: the inverse of the unknown's own compliance (the pressure or traction that would close its gap or slip
  // alone); a row no body can move gets the largest scale.
  const Eigen::VectorXd c = linalg::friction_scaling(F);
  if (last_alpha_.size() != qp.equilibrium.G.rows()) last_alpha_.resize(0);
  const FrictionSets sticking = first_sets(F, qp, z0, last_alpha_, c, rows, mask, context.note);
  FrictionSets sets = sticking;
  bool from_coarse = first_sets_from_coarse(F, qp, rows, sets, context.note);
  result.z = Eigen::VectorXd::Zero(n);
  bool restarted = false;
  for (int step = 1; step <= context.max_steps; ++step) {
    const linalg::FrictionParametrization p = linalg::parametrize(sets, rows, mask);
    const linalg::FrictionStepSolve s = linalg::solve_on_friction_sets(F, qp.g, qp.equilibrium, p);
    if (!s.ok && from_coarse && step == 1) {  // the coarse guess leaves a floating body unheld: start as without it
      from_coarse = false;
      sets = sticking;
      --step;
      continue;
    }
    if (!s.ok && !restarted && step > 1) {
      // A floating body held by nothing on these sets, which may be a bad guess: once, every node in contact sticks.
      restarted = true;
      for (size_t t = 0; t < rows.size(); ++t)
        if (sets.active[static_cast<size_t>(rows[t].normal)] || !rows[t].coulomb) sets.state[t] = Contact::stick;
      continue;
    }
    if (!s.ok) {
      result.message = friction_shortfall(qp, result.z);
      result.steps = step;
      return result;
    }
    result.z = s.lambda;
    result.alpha = s.alpha;
    last_alpha_ = s.alpha;
    result.h = qp.g + F * s.lambda;
    if (s.alpha.size() > 0) result.h += qp.equilibrium.G.transpose() * s.alpha;
    const FrictionSets next = linalg::predict_friction_sets(result.z, result.h, c, rows, mask);
    linalg::ActiveSetStep info;
    info.step = step;
    info.changes = next.changes(sets);
    for (char a : next.active) info.active += a;
    info.complementarity = linalg::friction_complementarity(result.z, result.h, c, rows, mask);
    result.steps = step;
    if (!context.on_step(result.z, result.h, info)) {
      result.cancelled = true;
      return result;
    }
    if (next == sets || info.complementarity <= 1e-13) {
      int stick = 0, slip = 0;
      for (auto st : sets.state) {
        stick += st == Contact::stick;
        slip += st == Contact::slip;
      }
      std::ostringstream os;
      os << "stick and slip sets settled in " << step << " steps (" << info.active << " nodes in contact: " << stick
         << " sticking, " << slip << " slipping)";
      result.converged = true;
      result.message = os.str();
      return result;
    }
    sets = next;
  }
  result.message = "the stick and slip sets did not settle within " + std::to_string(context.max_steps) + " steps";
  return result;
}

std::string friction_overload(const ContactSystem& system) {
  const Problem& problem = system.problem();
  const auto& pairs = system.pairs();
  for (size_t a = 0; a < system.n_bodies(); ++a) {
    if (system.body(a).rigid_modes().cols() < 3) continue;  // held in some direction by its own supports
    std::vector<size_t> touching;
    for (size_t k = 0; k < pairs.size(); ++k)
      if (static_cast<size_t>(pairs[k].slave_body) == a || static_cast<size_t>(pairs[k].master_body) == a) touching.push_back(k);
    if (touching.size() != 1 || !pairs[touching[0]].has_friction()) continue;
    const auto& pair = pairs[touching[0]];
    Eigen::Vector2d n = Eigen::Vector2d::Zero();
    for (Eigen::Index r = 0; r < pair.n_rows(); ++r) n += pair.area[r] * pair.normal[static_cast<size_t>(r)];
    if (!(n.norm() > 0)) continue;
    n.normalize();
    const Eigen::VectorXd f = system.body(a).external_load();
    Eigen::Vector2d load = Eigen::Vector2d::Zero();
    for (Eigen::Index d = 0; d < f.size(); ++d) load[d % 2] += f[d];
    const double normal = std::abs(load.dot(n)), tangential = std::abs(load.x() * n.y() - load.y() * n.x());
    const bool coulomb = pair.friction.law == FrictionSpec::Law::coulomb;
    const double capacity = coulomb ? pair.friction.coefficient * normal : pair.friction.bound * pair.area.sum();
    if (!(tangential > capacity * (1 + 1e-6))) continue;
    std::ostringstream os;
    os.precision(4);
    os << "contact '" << pair.name << "': friction cannot hold body '" << problem.bodies[a].name
       << "': its loads push it along the contact with " << tangential << ", "
       << (capacity > 0 ? tangential / capacity : std::numeric_limits<double>::infinity()) << " times what friction can carry ("
       << (coulomb ? "mu x normal load = " : "bound x contact length = ") << capacity
       << "); under force control it would slide without end: lower the tangential load, raise the friction, or "
          "prescribe the body's displacement";
    return os.str();
  }
  return {};
}

}  // namespace contact::ddm
