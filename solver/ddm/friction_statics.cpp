#include "friction_statics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <sstream>

namespace contact::ddm {

namespace {

using Vec = Eigen::Vector2d;

// A flat joint: pairs on one line, n.x = offset, n with its first non-zero component positive.
struct Joint {
  Vec n = Vec::Zero();
  double offset = 0.0;
  std::vector<size_t> pairs;
};

Vec point_of(const ContactSystem& system, int body, int node) {
  return system.problem().bodies[static_cast<size_t>(body)].mesh.nodes[static_cast<size_t>(node)];
}

Vec centroid(const ContactSystem& system, size_t body) {
  const auto& nodes = system.problem().bodies[body].mesh.nodes;
  Vec c = Vec::Zero();
  for (const auto& p : nodes) c += p;
  return nodes.empty() ? c : Vec(c / static_cast<double>(nodes.size()));
}

// The pair's common unit normal if all its rows share it (a straight contact), else zero.
Vec flat_normal(const mortar::PairDiscretization& pair) {
  Vec n = Vec::Zero();
  for (Eigen::Index r = 0; r < pair.n_rows(); ++r) n += pair.area[r] * pair.normal[static_cast<size_t>(r)];
  if (!(n.norm() > 0)) return Vec::Zero();
  n.normalize();
  for (Eigen::Index r = 0; r < pair.n_rows(); ++r)
    if (pair.area[r] > 0 && pair.normal[static_cast<size_t>(r)].dot(n) < 1 - 1e-9) return Vec::Zero();
  if (n.x() < -1e-12 || (std::abs(n.x()) <= 1e-12 && n.y() < 0)) n = -n;
  return n;
}

std::vector<Joint> flat_joints(const ContactSystem& system, double length_scale) {
  std::vector<Joint> joints;
  const auto& pairs = system.pairs();
  for (size_t k = 0; k < pairs.size(); ++k) {
    const Vec n = flat_normal(pairs[k]);
    if (n.isZero() || pairs[k].slave_nodes.empty()) continue;
    const double offset = n.dot(point_of(system, pairs[k].slave_body, pairs[k].slave_nodes.front()));
    auto same = [&](const Joint& j) {
      return j.n.dot(n) > 1 - 1e-10 && std::abs(j.offset - offset) <= 1e-9 * length_scale;
    };
    auto it = std::find_if(joints.begin(), joints.end(), same);
    if (it == joints.end()) it = joints.insert(joints.end(), Joint{n, offset, {}});
    it->pairs.push_back(k);
  }
  return joints;
}

// Connected components of the bodies linked by every pair except the joint's: a component label per body.
std::vector<size_t> components_without(const ContactSystem& system, const Joint& joint) {
  std::vector<size_t> parent(system.n_bodies());
  std::iota(parent.begin(), parent.end(), size_t{0});
  auto find = [&](size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  std::vector<char> in_joint(system.pairs().size(), 0);
  for (size_t k : joint.pairs) in_joint[k] = 1;
  for (size_t k = 0; k < system.pairs().size(); ++k)
    if (!in_joint[k])
      parent[find(static_cast<size_t>(system.pairs()[k].slave_body))] =
          find(static_cast<size_t>(system.pairs()[k].master_body));
  for (size_t a = 0; a < parent.size(); ++a) parent[a] = find(a);
  return parent;
}

// A set of bodies that friction cannot hold along a joint.
struct Sliding {
  std::vector<size_t> bodies;
  std::vector<size_t> pairs;  // the joint's pairs that hold it
  Vec direction = Vec::Zero();
  double load = 0.0, capacity = 0.0, ratio = 0.0;
  bool coulomb_only = true;
};

// The component `label` against `joint`, if friction cannot hold it (ratio > 0), else ratio 0.
Sliding check_component(const ContactSystem& system, const fem::LoadPoint& at, const Joint& joint,
                        const std::vector<size_t>& label, size_t component) {
  Sliding s;
  for (size_t a = 0; a < system.n_bodies(); ++a)
    if (label[a] == component) {
      if (system.body(a).rigid_modes().cols() < 3) return {};  // a support of its own
      s.bodies.push_back(a);
    }
  // The joint's pairs that cross the component's boundary, and the side they press it from.
  double side = 0.0, mu = 0.0, tresca = 0.0;
  bool any_friction = false;
  for (size_t k : joint.pairs) {
    const auto& pair = system.pairs()[k];
    const bool slave_in = label[static_cast<size_t>(pair.slave_body)] == component;
    const bool master_in = label[static_cast<size_t>(pair.master_body)] == component;
    if (slave_in == master_in) continue;
    const size_t inside = static_cast<size_t>(slave_in ? pair.slave_body : pair.master_body);
    const double this_side = joint.n.dot(centroid(system, inside)) - joint.offset > 0 ? 1.0 : -1.0;
    if (side != 0.0 && this_side != side) return {};  // pressed from both sides: not decided here
    side = this_side;
    s.pairs.push_back(k);
    if (!pair.has_friction()) continue;
    any_friction = true;
    if (pair.friction.law == FrictionSpec::Law::coulomb) {
      mu = std::max(mu, pair.friction.coefficient);
    } else {
      tresca += pair.friction.bound * pair.area.sum();
      s.coulomb_only = false;
    }
  }
  if (s.pairs.empty() || !any_friction) return {};
  Vec load = Vec::Zero();
  for (size_t a : s.bodies) {
    const Eigen::VectorXd f = system.body(a).external_load(at);
    for (Eigen::Index d = 0; d < f.size(); ++d) load[d % 2] += f[d];
  }
  const Vec m = side * joint.n;  // from the joint into the component: the direction the contact pushes it
  const double normal = -load.dot(m);
  if (!(normal > 0)) return {};  // pulled off the joint: the solve says what holds it
  s.direction = Vec(-m.y(), m.x());
  s.load = std::abs(load.dot(s.direction));
  s.capacity = mu * normal + tresca;
  if (!(s.load > s.capacity * (1 + 1e-6)) || !(s.load > 1e-12 * load.norm())) return {};
  s.ratio = s.capacity > 0 ? s.load / s.capacity : std::numeric_limits<double>::infinity();
  if (s.direction.dot(load) < 0) s.direction = -s.direction;  // the way it would slide
  return s;
}

std::string direction_words(const Vec& t) {
  if (std::abs(t.y()) < 1e-9) return t.x() > 0 ? "+x" : "-x";
  if (std::abs(t.x()) < 1e-9) return t.y() > 0 ? "+y" : "-y";
  std::ostringstream os;
  os.precision(4);
  os << "(" << t.x() << ", " << t.y() << ")";
  return os.str();
}

std::string quoted_list(const std::vector<std::string>& names, size_t shown) {
  std::string text;
  for (size_t i = 0; i < names.size() && i < shown; ++i) text += (i ? ", '" : "'") + names[i] + "'";
  if (names.size() > shown) text += " and " + std::to_string(names.size() - shown) + " more";
  return text;
}

std::string describe(const ContactSystem& system, const Sliding& s) {
  const Problem& problem = system.problem();
  std::vector<std::string> bodies, pairs;
  for (size_t a : s.bodies) bodies.push_back(problem.bodies[a].name);
  for (size_t k : s.pairs) pairs.push_back(system.pairs()[k].name);
  const std::string law = s.coulomb_only ? "mu x normal load = " : "mu x normal load + bound x contact length = ";
  std::ostringstream os;
  os.precision(4);
  if (bodies.size() == 1 && pairs.size() == 1) {
    os << "contact '" << pairs[0] << "': friction cannot hold body '" << bodies[0]
       << "': its loads push it along the contact (" << direction_words(s.direction) << ") with " << s.load << ", "
       << four_digits(s.ratio) << " times what friction can carry (" << law << s.capacity
       << "); under force control it would slide without end: lower the tangential load, raise the "
       << "friction, or prescribe the body's displacement";
    return os.str();
  }
  os << "friction cannot hold " << (bodies.size() == 1 ? "body " : std::to_string(bodies.size()) + " bodies ")
     << quoted_list(bodies, 6) << " on the joint of "
     << (pairs.size() == 1 ? "contact " : std::to_string(pairs.size()) + " contacts ") << quoted_list(pairs, 3)
     << ": their loads push them along the joint (" << direction_words(s.direction) << ") with " << s.load << ", "
     << four_digits(s.ratio) << " times what friction can carry (" << law << s.capacity
     << "); under force control they would slide without end: lower the tangential load, raise the friction, or "
     << "prescribe a displacement that holds them";
  return os.str();
}

double length_scale(const ContactSystem& system) {
  double lo_x = 0, hi_x = 0, lo_y = 0, hi_y = 0;
  bool first = true;
  for (const auto& body : system.problem().bodies)
    for (const auto& p : body.mesh.nodes) {
      if (first) lo_x = hi_x = p.x(), lo_y = hi_y = p.y(), first = false;
      lo_x = std::min(lo_x, p.x()), hi_x = std::max(hi_x, p.x()), lo_y = std::min(lo_y, p.y()),
      hi_y = std::max(hi_y, p.y());
    }
  return std::max({hi_x - lo_x, hi_y - lo_y, 1e-300});
}

}  // namespace

std::string four_digits(double value) {
  if (!std::isfinite(value)) return "infinitely many";
  char text[32];
  const int digits = value == 0 ? 0 : static_cast<int>(std::floor(std::log10(std::abs(value))));
  std::snprintf(text, sizeof text, "%.*f", std::max(0, 3 - digits), value);
  return text;
}

std::string friction_cannot_hold(const ContactSystem& system, const fem::LoadPoint& at) {
  if (!system.has_friction()) return {};
  Sliding worst;
  for (const Joint& joint : flat_joints(system, length_scale(system))) {
    const std::vector<size_t> label = components_without(system, joint);
    std::vector<size_t> checked;
    for (size_t k : joint.pairs)
      for (int body : {system.pairs()[k].slave_body, system.pairs()[k].master_body}) {
        const size_t c = label[static_cast<size_t>(body)];
        if (std::find(checked.begin(), checked.end(), c) != checked.end()) continue;
        checked.push_back(c);
        Sliding s = check_component(system, at, joint, label, c);
        // The worst ratio; among equal ones (every course of a wall under a top load) the smallest set.
        const bool tie = std::abs(s.ratio - worst.ratio) <= 1e-9 * s.ratio;
        if ((s.ratio > worst.ratio && !tie) || (tie && s.ratio > 0 && s.bodies.size() < worst.bodies.size()))
          worst = std::move(s);
      }
  }
  return worst.ratio > 0 ? describe(system, worst) : std::string();
}

}  // namespace contact::ddm
