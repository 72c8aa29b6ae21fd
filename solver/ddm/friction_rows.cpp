#include "friction_rows.hpp"

namespace contact::ddm {

std::vector<linalg::FrictionRow> friction_rows(const ContactSystem& system,
                                               const std::function<Eigen::Index(size_t)>& normal_offset,
                                               const std::function<Eigen::Index(size_t)>& tangential_offset,
                                               const std::function<bool(Eigen::Index)>& movable) {
  std::vector<linalg::FrictionRow> rows;
  const auto& pairs = system.pairs();
  for (size_t k = 0; k < pairs.size(); ++k) {
    const Eigen::Index t0 = tangential_offset(k);
    if (t0 < 0 || !pairs[k].has_friction()) continue;
    const auto& f = pairs[k].friction;
    const auto& dropped = pairs[k].tangential_dropped;
    for (Eigen::Index r = 0; r < pairs[k].n_rows(); ++r) {
      if (static_cast<size_t>(r) < dropped.size() && dropped[static_cast<size_t>(r)]) continue;
      if (!movable(t0 + r)) continue;
      rows.push_back({normal_offset(k) + r, t0 + r, f.law == FrictionSpec::Law::coulomb, f.coefficient, f.bound});
    }
  }
  return rows;
}

std::vector<char> tangential_unknowns(const ContactSystem& system, Eigen::Index size,
                                      const std::function<Eigen::Index(size_t)>& tangential_offset) {
  std::vector<char> mask(static_cast<size_t>(size), 0);
  const auto& pairs = system.pairs();
  for (size_t k = 0; k < pairs.size(); ++k)
    if (const Eigen::Index t0 = tangential_offset(k); t0 >= 0)
      for (Eigen::Index r = 0; r < pairs[k].n_rows(); ++r) mask[static_cast<size_t>(t0 + r)] = 1;
  return mask;
}

}  // namespace contact::ddm
