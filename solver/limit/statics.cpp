#include "statics.hpp"

#include "../common/background.hpp"

#include <glpk.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>

namespace contact::limit {

namespace {

// The generalised force conjugate to (vx, vy, size x omega): (Fx, Fy, M / size).
Eigen::Vector3d conjugate(const Resultant& f, double size) { return {f[0], f[1], f[2] / size}; }

struct LpDeleter {
  void operator()(glp_prob* lp) const { glp_delete_prob(lp); }
};

// The sparse matrix of the program, 1-based as GLPK takes it.
struct Triplets {
  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0.0};
  void add(int i, int j, double v) {
    if (v == 0.0) return;
    ia.push_back(i);
    ja.push_back(j);
    ar.push_back(v);
  }
};

// The linear program itself (on the caller's thread, or on its own when a cancel may leave it: largest_multiplier).
StaticsAnswer solve_statics(const RigidBlocks& blocks, const std::vector<Resultant>& fixed,
                            const std::vector<Resultant>& scaled) {
  StaticsAnswer out;
  const size_t nb = blocks.bodies.size();
  // GLPK keeps its environment (the terminal output switch, its memory accounting) per thread at best: one program
  // at a time, quiet (glp_scale_prob and glp_adv_basis write to stdout whatever the simplex's msg_lev says).
  static std::mutex glpk;
  const std::lock_guard<std::mutex> one_at_a_time(glpk);
  glp_term_out(GLP_OFF);
  std::unique_ptr<glp_prob, LpDeleter> lp(glp_create_prob());
  glp_set_obj_dir(lp.get(), GLP_MAX);

  // Columns: lambda, then per joint row its pressure z and (with friction) its tangential multiplier q.
  const int lambda = glp_add_cols(lp.get(), 1);
  glp_set_col_bnds(lp.get(), lambda, GLP_LO, 0.0, 0.0);
  glp_set_obj_coef(lp.get(), lambda, 1.0);
  std::vector<int> z_col(blocks.rows.size()), q_col(blocks.rows.size(), 0);
  for (size_t i = 0; i < blocks.rows.size(); ++i) {
    const FrictionSpec& law = blocks.friction_of_pair[blocks.rows[i].pair];
    z_col[i] = glp_add_cols(lp.get(), 1);
    glp_set_col_bnds(lp.get(), z_col[i], GLP_LO, 0.0, 0.0);
    if (law.law == FrictionSpec::Law::none) continue;
    q_col[i] = glp_add_cols(lp.get(), 1);
    if (law.law == FrictionSpec::Law::tresca)
      glp_set_col_bnds(lp.get(), q_col[i], law.bound > 0 ? GLP_DB : GLP_FX, -law.bound, law.bound);
    else
      glp_set_col_bnds(lp.get(), q_col[i], GLP_FR, 0.0, 0.0);
  }

  // Rows: per body, its equilibrium along each rigid motion its supports leave it.
  Triplets m;
  std::vector<std::vector<int>> eq_row(nb);
  for (size_t a = 0; a < nb; ++a) {
    const RigidBody& body = blocks.bodies[a];
    for (Eigen::Index j = 0; j < body.motions.cols(); ++j) {
      const Eigen::Vector3d motion = body.motions.col(j);
      const int row = glp_add_rows(lp.get(), 1);
      eq_row[a].push_back(row);
      const double rhs = -motion.dot(conjugate(fixed[a], body.size));
      glp_set_row_bnds(lp.get(), row, GLP_FX, rhs, rhs);
      m.add(row, lambda, motion.dot(conjugate(scaled[a], body.size)));
    }
  }
  for (size_t i = 0; i < blocks.rows.size(); ++i) {
    const JointRow& r = blocks.rows[i];
    const size_t s = static_cast<size_t>(blocks.slave_of_pair[r.pair]);
    const size_t t = static_cast<size_t>(blocks.master_of_pair[r.pair]);
    // (A pair whose slave and master are one body adds both shares to that body's rows.)
    for (size_t j = 0; j < eq_row[s].size(); ++j) {
      const Eigen::Vector3d motion = blocks.bodies[s].motions.col(static_cast<Eigen::Index>(j));
      m.add(eq_row[s][j], z_col[i], motion.dot(conjugate(r.slave_normal, blocks.bodies[s].size)));
      if (q_col[i]) m.add(eq_row[s][j], q_col[i], motion.dot(conjugate(r.slave_tangential, blocks.bodies[s].size)));
    }
    for (size_t j = 0; j < eq_row[t].size(); ++j) {
      const Eigen::Vector3d motion = blocks.bodies[t].motions.col(static_cast<Eigen::Index>(j));
      m.add(eq_row[t][j], z_col[i], motion.dot(conjugate(r.master_normal, blocks.bodies[t].size)));
      if (q_col[i]) m.add(eq_row[t][j], q_col[i], motion.dot(conjugate(r.master_tangential, blocks.bodies[t].size)));
    }
    // Coulomb: q - mu z <= 0 and -q - mu z <= 0.
    const FrictionSpec& law = blocks.friction_of_pair[r.pair];
    if (law.law == FrictionSpec::Law::coulomb) {
      const int row = glp_add_rows(lp.get(), 2);
      glp_set_row_bnds(lp.get(), row, GLP_UP, 0.0, 0.0);
      glp_set_row_bnds(lp.get(), row + 1, GLP_UP, 0.0, 0.0);
      m.add(row, q_col[i], 1.0);
      m.add(row, z_col[i], -law.coefficient);
      m.add(row + 1, q_col[i], -1.0);
      m.add(row + 1, z_col[i], -law.coefficient);
    }
  }
  // Round-off (a moment arm of 1e-17 where a row's point is at the reference) is no coefficient: an entry 1e-16 of
  // its row's largest, or a right-hand side 1e-12 of the loads, is dropped (GLPK's simplex loses feasibility on them).
  std::vector<double> row_max(static_cast<size_t>(glp_get_num_rows(lp.get())) + 1, 0.0);
  for (size_t e = 1; e < m.ar.size(); ++e)
    row_max[static_cast<size_t>(m.ia[e])] = std::max(row_max[static_cast<size_t>(m.ia[e])], std::abs(m.ar[e]));
  {
    Triplets kept;
    for (size_t e = 1; e < m.ar.size(); ++e)
      if (std::abs(m.ar[e]) > 1e-12 * row_max[static_cast<size_t>(m.ia[e])]) kept.add(m.ia[e], m.ja[e], m.ar[e]);
    m = std::move(kept);
  }
  double load_scale = 0.0;
  for (size_t a = 0; a < nb; ++a)
    load_scale =
        std::max({load_scale, fixed[a].head<2>().norm(), scaled[a].head<2>().norm(),
                  std::abs(fixed[a][2]) / blocks.bodies[a].size, std::abs(scaled[a][2]) / blocks.bodies[a].size});
  for (size_t a = 0; a < nb; ++a)
    for (int row : eq_row[a])
      if (std::abs(glp_get_row_lb(lp.get(), row)) <= 1e-12 * load_scale) glp_set_row_bnds(lp.get(), row, GLP_FX, 0, 0);
  if (glp_get_num_rows(lp.get()) == 0) {  // every body clamped: nothing can move
    out.status = StaticsAnswer::Status::unbounded;
    out.velocity.assign(nb, Eigen::Vector3d::Zero());
    return out;
  }
  glp_load_matrix(lp.get(), static_cast<int>(m.ia.size()) - 1, m.ia.data(), m.ja.data(), m.ar.data());

  glp_scale_prob(lp.get(), GLP_SF_AUTO);
  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.presolve = GLP_OFF;  // the duals (the mechanism) are wanted
  glp_adv_basis(lp.get(), 0);
  const int code = glp_simplex(lp.get(), &parm);
  if (code != 0) {
    out.message = "the linear program of the statics failed (GLPK glp_simplex returned " + std::to_string(code) + ")";
    return out;
  }
  const int status = glp_get_status(lp.get());
  if (status == GLP_UNBND) {
    out.status = StaticsAnswer::Status::unbounded;
    out.velocity.assign(nb, Eigen::Vector3d::Zero());
    return out;
  }
  if (status == GLP_NOFEAS || status == GLP_INFEAS) {
    out.status = StaticsAnswer::Status::infeasible;
    return out;
  }
  if (status != GLP_OPT) {
    out.message = "the linear program of the statics ended undecided (GLPK status " + std::to_string(status) + ")";
    return out;
  }
  out.status = StaticsAnswer::Status::bounded;
  out.multiplier = glp_get_obj_val(lp.get());

  // The mechanism: per body, the row duals along its motions, as (vx, vy, omega).
  out.velocity.assign(nb, Eigen::Vector3d::Zero());
  double power = 0.0, largest = 0.0;
  for (size_t a = 0; a < nb; ++a) {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (size_t j = 0; j < eq_row[a].size(); ++j)
      v += glp_get_row_dual(lp.get(), eq_row[a][j]) * blocks.bodies[a].motions.col(static_cast<Eigen::Index>(j));
    v[2] /= blocks.bodies[a].size;
    out.velocity[a] = v;
    power += v.dot(scaled[a]);
    largest = std::max(largest, v.head<2>().norm() + blocks.bodies[a].size * std::abs(v[2]));
  }
  const double unit = (power < 0 ? -1.0 : 1.0) / (largest > 0 ? largest : 1.0);
  for (auto& v : out.velocity) {
    v *= unit;
    for (Eigen::Index i = 0; i < 3; ++i)
      if (std::abs(v[i]) < 1e-12) v[i] = 0.0;
  }
  return out;
}

}  // namespace

StaticsAnswer largest_multiplier(const RigidBlocks& blocks, const std::vector<Resultant>& fixed,
                                 const std::vector<Resultant>& scaled, const std::function<bool()>& cancelled) {
  // GLPK's simplex has no interrupt: on its own thread (common/background.hpp) a cancel returns at once and leaves
  // it to finish alone, so the work owns copies of its inputs.
  std::unique_ptr<StaticsAnswer> answer = run_unless_cancelled<StaticsAnswer>(
      [blocks, fixed, scaled] { return std::make_unique<StaticsAnswer>(solve_statics(blocks, fixed, scaled)); },
      cancelled);
  if (answer) return std::move(*answer);
  StaticsAnswer out;
  out.message = "cancelled";
  return out;
}

}  // namespace contact::limit
