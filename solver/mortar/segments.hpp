// The mortar segment mesh of one contact pair (geometry only; no basis functions, no algebra).
//
// Both sides are polylines of boundary nodes in order along the edge with the body on the left (edge sets are
// counter-clockwise), so a segment from a to b has the outward unit normal (e_y, -e_x), e = (b - a) / |b - a|.
// Curved edges enter as their chords between nodes.
//
// Matching: a slave point x on slave segment k is paired with the master point x' hit by the line through x
// along the slave segment's normal n_k (x' = x + t n_k; t is the normal gap, positive when open). Along one
// slave segment the line's direction is fixed, so x' and t are affine in the slave parameter on every piece
// between the orthogonal projections of the master nodes: slave segments are cut at those projections, and each
// piece (a mortar segment) lies opposite one master segment. Products of linear functions of the two sides are
// then quadratic on every mortar segment, and two-point Gauss rules integrate them exactly.
//
// Only master segments that face the slave segment (n_master . n_k < 0) are candidates; where several are hit
// (a folded master edge), the nearest (smallest |t|) is taken. A piece whose line hits no facing master segment
// is uncovered: it carries no contact.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace contact::mortar {

using Polyline = std::vector<Eigen::Vector2d>;

struct MortarSegment {
  int slave = -1;             // slave segment (between slave nodes slave and slave + 1)
  int master = -1;            // master segment (between master nodes master and master + 1)
  double xi0 = 0, xi1 = 0;    // slave parameter range, 0 <= xi0 < xi1 <= 1 (0 at node slave)
  double eta0 = 0, eta1 = 0;  // master parameter at xi0 and xi1 (affine in between; 0 at node master)
  double gap0 = 0, gap1 = 0;  // t at xi0 and xi1: the normal gap along n_k (affine in between)
};

struct SegmentMesh {
  std::vector<MortarSegment> segments;        // ordered by slave segment, then by xi
  std::vector<Eigen::Vector2d> slave_normal;  // outward unit normal of each slave segment
  std::vector<double> slave_length;           // length of each slave segment
};

// Outward unit normal of the boundary segment a -> b of a counter-clockwise boundary.
Eigen::Vector2d outward_normal(const Eigen::Vector2d& a, const Eigen::Vector2d& b);

// Cuts every slave segment against the master polyline. Degenerate (zero-length) segments on either side carry
// nothing.
SegmentMesh build_segment_mesh(const Polyline& slave, const Polyline& master);

}  // namespace contact::mortar
