#include "segments.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace contact::mortar {

namespace {

// Where the line x + t n meets the master segment a -> b: (t, eta) with x + t n = a + eta (b - a). nullopt
// when the line is parallel to the segment.
std::optional<std::pair<double, double>> intersect(const Eigen::Vector2d& x, const Eigen::Vector2d& n,
                                                   const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d f = b - a;
  // [n, -f] (t, eta)^T = a - x
  const double det = -n.x() * f.y() + n.y() * f.x();
  const double scale = f.norm();
  if (!(std::abs(det) > 1e-12 * scale)) return std::nullopt;
  const Eigen::Vector2d r = a - x;
  const double t = (-r.x() * f.y() + r.y() * f.x()) / det;
  const double eta = (n.x() * r.y() - n.y() * r.x()) / det;
  return std::make_pair(t, eta);
}

}  // namespace

Eigen::Vector2d outward_normal(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = (b - a).normalized();
  return {e.y(), -e.x()};
}

SegmentMesh build_segment_mesh(const Polyline& slave, const Polyline& master) {
  SegmentMesh mesh;
  const size_t ns = slave.size() < 2 ? 0 : slave.size() - 1;
  const size_t nm = master.size() < 2 ? 0 : master.size() - 1;
  mesh.slave_normal.assign(ns, Eigen::Vector2d::Zero());
  mesh.slave_length.assign(ns, 0.0);
  std::vector<Eigen::Vector2d> master_normal(nm, Eigen::Vector2d::Zero());
  std::vector<char> master_ok(nm, 0);
  for (size_t j = 0; j < nm; ++j) {
    master_ok[j] = (master[j + 1] - master[j]).norm() > 0;
    if (master_ok[j]) master_normal[j] = outward_normal(master[j], master[j + 1]);
  }
  const double tol = 1e-10;
  for (size_t k = 0; k < ns; ++k) {
    const Eigen::Vector2d a = slave[k], e = slave[k + 1] - a;
    const double L = e.norm();
    if (!(L > 0)) continue;
    const Eigen::Vector2d n = outward_normal(a, slave[k + 1]);
    mesh.slave_normal[k] = n;
    mesh.slave_length[k] = L;
    std::vector<double> cuts = {0.0, 1.0};
    for (const auto& m : master) {
      const double xi = (m - a).dot(e) / (L * L);
      if (xi > tol && xi < 1 - tol) cuts.push_back(xi);
    }
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end(), [&](double u, double v) { return v - u < tol; }), cuts.end());
    for (size_t c = 0; c + 1 < cuts.size(); ++c) {
      const double xi0 = cuts[c], xi1 = cuts[c + 1];
      const Eigen::Vector2d mid = a + 0.5 * (xi0 + xi1) * e;
      int best = -1;
      double best_gap = std::numeric_limits<double>::infinity();
      for (size_t j = 0; j < nm; ++j) {
        if (!master_ok[j] || !(master_normal[j].dot(n) < 0)) continue;
        const auto hit = intersect(mid, n, master[j], master[j + 1]);
        if (!hit || hit->second < -tol || hit->second > 1 + tol) continue;
        if (std::abs(hit->first) < std::abs(best_gap)) {
          best_gap = hit->first;
          best = static_cast<int>(j);
        }
      }
      if (best < 0) continue;
      const auto& ma = master[static_cast<size_t>(best)];
      const auto& mb = master[static_cast<size_t>(best) + 1];
      const auto h0 = intersect(a + xi0 * e, n, ma, mb);
      const auto h1 = intersect(a + xi1 * e, n, ma, mb);
      MortarSegment s;
      s.slave = static_cast<int>(k);
      s.master = best;
      s.xi0 = xi0;
      s.xi1 = xi1;
      s.gap0 = h0->first;
      s.gap1 = h1->first;
      s.eta0 = std::clamp(h0->second, 0.0, 1.0);
      s.eta1 = std::clamp(h1->second, 0.0, 1.0);
      mesh.segments.push_back(s);
    }
  }
  return mesh;
}

}  // namespace contact::mortar
