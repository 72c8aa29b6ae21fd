#include "friction_sets.hpp"

#include <algorithm>
#include <cmath>

#include "../common/assert.hpp"

namespace contact::linalg {

int FrictionSets::changes(const FrictionSets& o) const {
  int n = 0;
  for (size_t j = 0; j < active.size() && j < o.active.size(); ++j) n += active[j] != o.active[j];
  for (size_t t = 0; t < state.size() && t < o.state.size(); ++t)
    n += state[t] != o.state[t] || (state[t] == FrictionState::slip && sign[t] != o.sign[t]);
  return n;
}

std::vector<char> tangential_mask(Eigen::Index size, const std::vector<FrictionRow>& rows) {
  std::vector<char> mask(static_cast<size_t>(size), 0);
  for (const auto& r : rows) mask[static_cast<size_t>(r.tangential)] = 1;
  return mask;
}

void stick_where_in_contact(FrictionSets& sets, const std::vector<FrictionRow>& rows) {
  sets.state.assign(rows.size(), FrictionState::open);
  sets.sign.assign(rows.size(), 0);
  for (size_t t = 0; t < rows.size(); ++t)
    if (sets.active[static_cast<size_t>(rows[t].normal)] || !rows[t].coulomb) sets.state[t] = FrictionState::stick;
}

namespace {
double bound_of(const FrictionRow& r, double normal_trial) {
  return r.coulomb ? r.mu * std::max(0.0, normal_trial) : r.bound;
}
}  // namespace

FrictionSets predict_friction_sets(const Eigen::VectorXd& lambda, const Eigen::VectorXd& h, const Eigen::VectorXd& c,
                                   const std::vector<FrictionRow>& rows, const std::vector<char>& is_tangential) {
  CONTACT_ASSERT_SIZE(h.size(), lambda.size(), "the gaps and slips");
  CONTACT_ASSERT_SIZE(c.size(), lambda.size(), "the scaling");
  CONTACT_ASSERT_SIZE(is_tangential.size(), lambda.size(), "the tangential mask");
  FrictionSets s;
  const Eigen::Index n = lambda.size();
  s.active.assign(static_cast<size_t>(n), 0);
  for (Eigen::Index j = 0; j < n; ++j)
    if (!is_tangential[static_cast<size_t>(j)]) s.active[static_cast<size_t>(j)] = lambda[j] - c[j] * h[j] > 0;
  s.state.assign(rows.size(), FrictionState::open);
  s.sign.assign(rows.size(), 0);
  for (size_t t = 0; t < rows.size(); ++t) {
    const auto& r = rows[t];
    if (r.coulomb && !s.active[static_cast<size_t>(r.normal)]) continue;  // open: no bound, q = 0
    const double trial = lambda[r.tangential] - c[r.tangential] * h[r.tangential];
    const double b = bound_of(r, lambda[r.normal] - c[r.normal] * h[r.normal]);
    if (std::abs(trial) <= b) {
      s.state[t] = FrictionState::stick;
    } else {
      s.state[t] = FrictionState::slip;
      s.sign[t] = trial > 0 ? 1 : -1;
    }
  }
  return s;
}

FrictionParametrization parametrize(const FrictionSets& sets, const std::vector<FrictionRow>& rows,
                                    const std::vector<char>& is_tangential) {
  FrictionParametrization out;
  const Eigen::Index n = static_cast<Eigen::Index>(sets.active.size());
  out.lambda0 = Eigen::VectorXd::Zero(n);
  std::vector<Eigen::Index> column(static_cast<size_t>(n), -1);
  for (Eigen::Index j = 0; j < n; ++j)
    if (!is_tangential[static_cast<size_t>(j)] && sets.active[static_cast<size_t>(j)]) {
      column[static_cast<size_t>(j)] = static_cast<Eigen::Index>(out.rows.size());
      out.rows.push_back(j);
    }
  for (size_t t = 0; t < rows.size(); ++t)
    if (sets.state[t] == FrictionState::stick) {
      column[static_cast<size_t>(rows[t].tangential)] = static_cast<Eigen::Index>(out.rows.size());
      out.rows.push_back(rows[t].tangential);
    }
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index j : out.rows) entries.emplace_back(j, column[static_cast<size_t>(j)], 1.0);
  for (size_t t = 0; t < rows.size(); ++t) {
    if (sets.state[t] != FrictionState::slip) continue;
    const auto& r = rows[t];
    if (r.coulomb)  // q_t = s mu z_i: a share of z_i's column
      entries.emplace_back(r.tangential, column[static_cast<size_t>(r.normal)], sets.sign[t] * r.mu);
    else
      out.lambda0[r.tangential] = sets.sign[t] * r.bound;
  }
  out.P.resize(n, static_cast<Eigen::Index>(out.rows.size()));
  out.P.setFromTriplets(entries.begin(), entries.end());
  return out;
}

double complementarity_squared(const Eigen::VectorXd& lambda, const Eigen::VectorXd& h, const Eigen::VectorXd& c,
                               const std::vector<FrictionRow>& rows, const std::vector<char>& is_tangential,
                               CoulombBound bound) {
  double sum = 0.0;
  for (Eigen::Index j = 0; j < lambda.size(); ++j)
    if (!is_tangential[static_cast<size_t>(j)]) {
      const double C = lambda[j] - std::max(0.0, lambda[j] - c[j] * h[j]);
      sum += C * C;
    }
  for (const auto& r : rows) {
    const double z = bound == CoulombBound::trial ? lambda[r.normal] - c[r.normal] * h[r.normal] : lambda[r.normal];
    const double b = !r.coulomb || z > 0 ? bound_of(r, z) : 0.0;
    const double trial = lambda[r.tangential] - c[r.tangential] * h[r.tangential];
    const double C = lambda[r.tangential] - std::clamp(trial, -b, b);
    sum += C * C;
  }
  return sum;
}

double friction_complementarity(const Eigen::VectorXd& lambda, const Eigen::VectorXd& h, const Eigen::VectorXd& c,
                                const std::vector<FrictionRow>& rows, const std::vector<char>& is_tangential) {
  return std::sqrt(complementarity_squared(lambda, h, c, rows, is_tangential, CoulombBound::current)) /
         std::max(lambda.norm(), 1e-300);
}

}  // namespace contact::linalg
