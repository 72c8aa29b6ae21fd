#include "constraints.hpp"

#include <functional>
#include <sstream>

namespace contact::fem {

void Constraints::add_dirichlet(int dof, double value) { lines_[dof] = Line{{}, value}; }

void Constraints::add_line(int dof, std::vector<std::pair<int, double>> entries, double inhomogeneity) {
  lines_[dof] = Line{std::move(entries), inhomogeneity};
}

bool Constraints::is_dirichlet(int dof) const {
  auto it = lines_.find(dof);
  return it != lines_.end() && it->second.entries.empty();
}

std::string Constraints::close() {
  // Free unknowns: every dof without a line.
  std::vector<int> free_index(static_cast<size_t>(n_dofs_), -1);
  free_dofs_.clear();
  for (int d = 0; d < n_dofs_; ++d)
    if (!lines_.count(d)) {
      free_index[static_cast<size_t>(d)] = static_cast<int>(free_dofs_.size());
      free_dofs_.push_back(d);
    }
  n_free_ = static_cast<int>(free_dofs_.size());

  // Resolve each constrained dof into free unknowns (depth-first, memoised, cycle-checked).
  std::map<int, std::pair<std::map<int, double>, double>> resolved;
  std::map<int, int> state;  // 1 = in progress, 2 = done
  std::string error;
  std::function<void(int)> resolve = [&](int dof) {
    if (state[dof] == 2 || !error.empty()) return;
    if (state[dof] == 1) {
      std::ostringstream os;
      os << "constraint cycle through dof " << dof;
      error = os.str();
      return;
    }
    state[dof] = 1;
    const Line& line = lines_.at(dof);
    std::map<int, double> row;
    double b = line.inhomogeneity;
    for (const auto& [master, w] : line.entries) {
      if (master < 0 || master >= n_dofs_) {
        std::ostringstream os;
        os << "constraint of dof " << dof << " refers to dof " << master << " outside 0.." << n_dofs_ - 1;
        error = os.str();
        return;
      }
      if (!lines_.count(master)) {
        row[free_index[static_cast<size_t>(master)]] += w;
      } else {
        resolve(master);
        if (!error.empty()) return;
        const auto& [mrow, mb] = resolved.at(master);
        for (const auto& [k, v] : mrow) row[k] += w * v;
        b += w * mb;
      }
    }
    resolved[dof] = {std::move(row), b};
    state[dof] = 2;
  };
  for (const auto& [dof, line] : lines_) {
    if (dof < 0 || dof >= n_dofs_) {
      std::ostringstream os;
      os << "constrained dof " << dof << " is outside 0.." << n_dofs_ - 1;
      return os.str();
    }
    resolve(dof);
    if (!error.empty()) return error;
  }

  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<size_t>(n_dofs_));
  g_ = Eigen::VectorXd::Zero(n_dofs_);
  for (int k = 0; k < n_free_; ++k) t.emplace_back(free_dofs_[static_cast<size_t>(k)], k, 1.0);
  for (const auto& [dof, rb] : resolved) {
    for (const auto& [k, v] : rb.first) t.emplace_back(dof, k, v);
    g_[dof] = rb.second;
  }
  T_.resize(n_dofs_, n_free_);
  T_.setFromTriplets(t.begin(), t.end());
  return {};
}

Eigen::VectorXd Constraints::condense_to_masters(const Eigen::VectorXd& f) const {
  Eigen::VectorXd out = f;
  std::function<void(int, double)> push = [&](int dof, double value) {
    const auto it = lines_.find(dof);
    if (it == lines_.end() || it->second.entries.empty()) {
      out[dof] += value;
      return;
    }
    for (const auto& [master, w] : it->second.entries) push(master, w * value);
  };
  for (const auto& [dof, line] : lines_) {
    if (line.entries.empty()) continue;
    const double value = out[dof];
    out[dof] = 0.0;
    push(dof, value);
  }
  return out;
}

}  // namespace contact::fem
