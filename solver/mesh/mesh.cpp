#include "contact/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

namespace contact::mesh {

namespace {
constexpr double kPi = 3.14159265358979323846;

double cross(const Point& a, const Point& b) { return a.x() * b.y() - a.y() * b.x(); }

// Node parameters in [0, 1] for n elements; grading `ratio` = largest / smallest element, smallest at t = 0
// if `small_at_start`, else at t = 1. ratio == 1 (or n == 1) gives uniform spacing.
std::vector<double> graded_parameters(int n, double ratio, bool small_at_start) {
  std::vector<double> sizes(static_cast<size_t>(n), 1.0);
  if (n > 1 && ratio != 1.0) {
    const double q = std::pow(ratio, 1.0 / (n - 1));
    for (int i = 0; i < n; ++i) sizes[static_cast<size_t>(i)] = std::pow(q, i);
    if (!small_at_start) std::reverse(sizes.begin(), sizes.end());
  }
  std::vector<double> t(static_cast<size_t>(n) + 1, 0.0);
  double total = 0.0;
  for (double s : sizes) total += s;
  for (int i = 0; i < n; ++i)
    t[static_cast<size_t>(i) + 1] = t[static_cast<size_t>(i)] + sizes[static_cast<size_t>(i)] / total;
  t.back() = 1.0;
  return t;
}
}  // namespace

Point Curve::between(const Point& p, const Point& q, double t) const {
  switch (kind) {
    case Kind::line:
      return p + t * (q - p);
    case Kind::parabola: {
      const double x = p.x() + t * (q.x() - p.x());
      return {x, a * x * x + b * x + c};
    }
    case Kind::arc: {
      const double tp = std::atan2(p.y() - center.y(), p.x() - center.x());
      const double tq = std::atan2(q.y() - center.y(), q.x() - center.x());
      double d = tq - tp;
      while (d > kPi) d -= 2 * kPi;
      while (d <= -kPi) d += 2 * kPi;
      const double th = tp + t * d;
      return center + radius * Point(std::cos(th), std::sin(th));
    }
  }
  return p;
}

std::optional<std::string> fit_curve(Curve& curve, const Point& p, const Point& q) {
  const double scale = std::max({1.0, p.norm(), q.norm()});
  if (curve.kind == Curve::Kind::parabola) {
    if (!std::isfinite(curve.a)) return "the parabola coefficient a must be finite";
    if (std::abs(q.x() - p.x()) <= 1e-12 * scale)
      return "a parabola edge y = a x^2 + b x + c needs its two end corners at different x";
    curve.b = ((q.y() - curve.a * q.x() * q.x()) - (p.y() - curve.a * p.x() * p.x())) / (q.x() - p.x());
    curve.c = p.y() - curve.a * p.x() * p.x() - curve.b * p.x();
    return std::nullopt;
  }
  if (curve.kind == Curve::Kind::arc) {
    if (!(curve.radius > 0)) return "the arc radius must be positive";
    const double dp = (p - curve.center).norm(), dq = (q - curve.center).norm();
    const double tol = 1e-6 * curve.radius;
    if (std::abs(dp - curve.radius) > tol || std::abs(dq - curve.radius) > tol) {
      std::ostringstream os;
      os << "the edge's end corners are at distances " << dp << " and " << dq
         << " from the arc centre, not at the radius " << curve.radius;
      return os.str();
    }
    const Point a = p - curve.center, b = q - curve.center;
    if (cross(a, b) == 0.0 && a.dot(b) < 0)
      return "the arc's end corners are diametrically opposite: the arc is ambiguous";
    return std::nullopt;
  }
  return std::nullopt;
}

std::vector<int> Mesh::edge_set_nodes(const std::string& name) const {
  auto it = edge_sets.find(name);
  if (it == edge_sets.end() || it->second.empty()) return {};
  std::vector<int> out;
  for (const auto& e : it->second) out.push_back(edge_nodes(e)[0]);
  if (!edge_set_closed(name)) out.push_back(edge_nodes(it->second.back())[1]);
  return out;
}

bool Mesh::edge_set_closed(const std::string& name) const {
  auto it = edge_sets.find(name);
  if (it == edge_sets.end() || it->second.empty()) return false;
  return edge_nodes(it->second.back())[1] == edge_nodes(it->second.front())[0];
}

double Mesh::cell_area(int cell) const {
  const auto& c = cells[static_cast<size_t>(cell)];
  const auto n = static_cast<size_t>(c.size());
  double a = 0.0;
  for (size_t k = 0; k < n; ++k)
    a += cross(nodes[static_cast<size_t>(c[k])], nodes[static_cast<size_t>(c[(k + 1) % n])]);
  return 0.5 * a;
}

bool Mesh::has_triangles() const {
  return std::any_of(cells.begin(), cells.end(), [](const Cell& c) { return c.is_triangle(); });
}

Eigen::Vector2d Mesh::bbox_min() const {
  Eigen::Vector2d m = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  for (const auto& p : nodes) m = m.cwiseMin(p);
  return m;
}

Eigen::Vector2d Mesh::bbox_max() const {
  Eigen::Vector2d m = Eigen::Vector2d::Constant(-std::numeric_limits<double>::infinity());
  for (const auto& p : nodes) m = m.cwiseMax(p);
  return m;
}

Mesh make_block(const BlockSpec& spec) {
  const int nx = spec.nx, ny = spec.ny;
  const auto& P = spec.corners;
  auto curve_of = [&](const char* name) {
    auto it = spec.curves.find(name);
    return it == spec.curves.end() ? Curve{} : it->second;
  };
  auto grading_of = [&](const char* name) {
    auto it = spec.grading.find(name);
    return it == spec.grading.end() ? 1.0 : it->second;
  };
  const Curve bottom = curve_of("bottom"), right = curve_of("right"), top = curve_of("top"), left = curve_of("left");

  // Parameters: a ratio towards "left" puts the small elements at xi = 0, towards "right" at xi = 1.
  std::vector<double> xi = spec.grading.count("right") ? graded_parameters(nx, grading_of("right"), false)
                                                       : graded_parameters(nx, grading_of("left"), true);
  std::vector<double> eta = spec.grading.count("top") ? graded_parameters(ny, grading_of("top"), false)
                                                      : graded_parameters(ny, grading_of("bottom"), true);

  Mesh m;
  m.nodes.resize(static_cast<size_t>((nx + 1) * (ny + 1)));
  auto node = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const double s = xi[static_cast<size_t>(i)], t = eta[static_cast<size_t>(j)];
      // Transfinite (Coons) interpolation of the four edges.
      const Point B = bottom.between(P[0], P[1], s), T = top.between(P[3], P[2], s);
      const Point L = left.between(P[0], P[3], t), R = right.between(P[1], P[2], t);
      const Point bilinear = (1 - s) * (1 - t) * P[0] + s * (1 - t) * P[1] + s * t * P[2] + (1 - s) * t * P[3];
      Point x = (1 - t) * B + t * T + (1 - s) * L + s * R - bilinear;
      // Boundary nodes exactly on their curves (the formula reproduces them up to round-off; make it exact).
      if (j == 0) x = B;
      if (j == ny) x = T;
      if (i == 0) x = L;
      if (i == nx) x = R;
      m.nodes[static_cast<size_t>(node(i, j))] = x;
    }
  }
  m.cells.reserve(static_cast<size_t>(nx * ny));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) m.cells.push_back({node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)});
  m.level.assign(m.cells.size(), 0);
  auto cell = [nx](int i, int j) { return j * nx + i; };
  auto& b = m.edge_sets["bottom"];
  for (int i = 0; i < nx; ++i) b.push_back({cell(i, 0), 0});
  auto& r = m.edge_sets["right"];
  for (int j = 0; j < ny; ++j) r.push_back({cell(nx - 1, j), 1});
  auto& tp = m.edge_sets["top"];
  for (int i = nx - 1; i >= 0; --i) tp.push_back({cell(i, ny - 1), 2});
  auto& l = m.edge_sets["left"];
  for (int j = ny - 1; j >= 0; --j) l.push_back({cell(0, j), 3});
  for (const auto& [name, c] : spec.curves)
    if (c.kind != Curve::Kind::line) m.edge_curves[name] = c;
  m.vertices = {{"bottom_left", node(0, 0)},
                {"bottom_right", node(nx, 0)},
                {"top_right", node(nx, ny)},
                {"top_left", node(0, ny)}};
  return m;
}

namespace {

std::string point_text(const Point& p) {
  std::ostringstream os;
  os << '(' << p.x() << ", " << p.y() << ')';
  return os.str();
}

// Orders boundary sides (each in its cell's counter-clockwise direction) into one open chain, from its one end,
// or into one closed loop (no side starts where none ends), from the first node of the side given first; an error
// message when they are several pieces.
std::optional<std::string> order_chain(const Mesh& m, std::vector<EdgeRef>& refs) {
  std::unordered_map<int, size_t> by_first;
  std::unordered_map<int, int> second_count;
  for (size_t k = 0; k < refs.size(); ++k) {
    const auto n = m.edge_nodes(refs[k]);
    by_first[n[0]] = k;
    second_count[n[1]]++;
  }
  std::vector<int> starts;
  for (size_t k = 0; k < refs.size(); ++k) {
    const int first = m.edge_nodes(refs[k])[0];
    if (!second_count.count(first)) starts.push_back(first);
  }
  const bool loop = starts.empty();
  std::vector<EdgeRef> chain;
  if ((loop || starts.size() == 1) && by_first.size() == refs.size()) {
    const int start = loop ? m.edge_nodes(refs.front())[0] : starts.front();
    int cur = start;
    while (chain.size() < refs.size()) {
      auto it = by_first.find(cur);
      if (it == by_first.end()) break;
      chain.push_back(refs[it->second]);
      cur = m.edge_nodes(refs[it->second])[1];
      if (loop && cur == start) break;
    }
  }
  if (loop && by_first.size() != refs.size()) {
    std::unordered_map<int, int> starting;
    int twice = m.edge_nodes(refs.front())[0];
    for (const auto& e : refs)
      if (++starting[m.edge_nodes(e)[0]] == 2) {
        twice = m.edge_nodes(e)[0];
        break;
      }
    return "its " + std::to_string(refs.size()) + " sides are not one chain along the boundary: two of them start at " +
           point_text(m.nodes[static_cast<size_t>(twice)]) +
           " (a side given twice, or the boundary touching itself there); an edge must be one connected piece";
  }
  if (chain.size() != refs.size() && loop) {
    const Point& p = m.nodes[static_cast<size_t>(m.edge_nodes(refs.front())[0])];
    return "its " + std::to_string(refs.size()) +
           " sides are not one chain along the boundary: they form several closed loops (one of " +
           std::to_string(chain.size()) + " sides through " + point_text(p) +
           "); an edge must be one connected piece (make each loop its own edge)";
  }
  if (chain.size() != refs.size()) {
    std::sort(starts.begin(), starts.end());
    std::string where;
    for (size_t k = 0; k < starts.size() && k < 4; ++k)
      where += (k ? ", " : "") + point_text(m.nodes[static_cast<size_t>(starts[k])]);
    if (starts.size() > 4) where += ", ...";
    return "its " + std::to_string(refs.size()) + " sides are not one chain along the boundary: they form " +
           std::to_string(std::max<size_t>(starts.size(), 2)) + " separate pieces (starting at " + where +
           "); an edge must be one connected piece (make each piece its own edge)";
  }
  refs = std::move(chain);
  return std::nullopt;
}

}  // namespace

std::optional<std::string> add_edge_set(Mesh& m, const std::string& name,
                                        const std::vector<std::array<int, 2>>& pairs) {
  // Sides of all cells by their unordered node pair.
  std::map<std::pair<int, int>, std::vector<EdgeRef>> sides;
  for (int c = 0; c < m.num_cells(); ++c)
    for (int s = 0; s < m.cells[static_cast<size_t>(c)].size(); ++s) {
      auto n = m.edge_nodes({c, s});
      sides[{std::min(n[0], n[1]), std::max(n[0], n[1])}].push_back({c, s});
    }
  std::vector<EdgeRef> refs;
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto [i, j] = pairs[k];
    auto it = sides.find({std::min(i, j), std::max(i, j)});
    std::ostringstream os;
    if (it == sides.end()) {
      os << "pair " << k << " [" << i << ", " << j << "] is not a side of any cell";
      return os.str();
    }
    if (it->second.size() != 1) {
      os << "pair " << k << " [" << i << ", " << j << "] is an interior side shared by two cells, not a boundary edge";
      return os.str();
    }
    refs.push_back(it->second.front());
  }
  if (refs.empty()) return "it has no sides";
  if (auto problem = order_chain(m, refs)) return problem;
  m.edge_sets[name] = std::move(refs);
  return std::nullopt;
}

std::vector<std::string> check_cells(const Mesh& m) {
  std::vector<std::string> problems;
  for (int c = 0; c < m.num_cells(); ++c) {
    const auto& q = m.cells[static_cast<size_t>(c)];
    const int n = q.size();
    std::ostringstream os;
    if (n != 3 && n != 4) {
      os << "cell " << c << " has " << n << " nodes (a cell is a triangle or a quadrilateral)";
      problems.push_back(os.str());
      continue;
    }
    bool bad_index = false;
    for (int node : q)
      if (node < 0 || node >= m.num_nodes()) bad_index = true;
    if (bad_index) {
      os << "cell " << c << " refers to a node index outside 0.." << m.num_nodes() - 1;
      problems.push_back(os.str());
      continue;
    }
    auto at = [&](int k) -> const Point& { return m.nodes[static_cast<size_t>(q[static_cast<size_t>(k % n)])]; };
    const double area = m.cell_area(c);
    double scale = 0.0;
    for (int k = 0; k < n; ++k) scale = std::max(scale, (at(k + 1) - at(k)).squaredNorm());
    if (!(scale > 0) || std::abs(area) <= 1e-12 * scale) {
      os << "cell " << c << " is degenerate (zero area)";
      problems.push_back(os.str());
      continue;
    }
    if (area < 0) {
      os << "cell " << c << " is inverted: its nodes run clockwise (they must be counter-clockwise)";
      problems.push_back(os.str());
      continue;
    }
    // A triangle of positive area is valid. The bilinear map's Jacobian is positive everywhere iff it is positive
    // at the four corners; at a triangle's corners that is its area, already checked.
    for (int k = 0; k < n; ++k) {
      if (cross(at(k + 1) - at(k), at(k + n - 1) - at(k)) <= 1e-12 * scale) {
        os << "cell " << c << " is degenerate or not convex at its local node " << k << " (node "
           << q[static_cast<size_t>(k)] << ")";
        problems.push_back(os.str());
        break;
      }
    }
  }
  return problems;
}

std::vector<int> pieces(const Mesh& m) {
  std::vector<int> parent(m.cells.size());
  for (size_t c = 0; c < parent.size(); ++c) parent[c] = static_cast<int>(c);
  auto root = [&](int c) {
    while (parent[static_cast<size_t>(c)] != c)
      c = parent[static_cast<size_t>(c)] = parent[static_cast<size_t>(parent[static_cast<size_t>(c)])];
    return c;
  };
  std::map<std::pair<int, int>, int> side_owner;
  for (int c = 0; c < m.num_cells(); ++c)
    for (int s = 0; s < m.cells[static_cast<size_t>(c)].size(); ++s) {
      const auto n = m.edge_nodes({c, s});
      auto [it, inserted] = side_owner.emplace(std::make_pair(std::min(n[0], n[1]), std::max(n[0], n[1])), c);
      if (!inserted) parent[static_cast<size_t>(root(c))] = root(it->second);
    }
  std::vector<int> piece(m.cells.size(), -1);
  std::map<int, int> number;  // root -> piece
  for (int c = 0; c < m.num_cells(); ++c)
    piece[static_cast<size_t>(c)] = number.emplace(root(c), static_cast<int>(number.size())).first->second;
  return piece;
}

}  // namespace contact::mesh
