// The pairs that share a contact surface: where contact edges meet (docs/algorithm.md, "Where contact edges meet").
//
// A job often cuts one contact surface into several pairs: a bore against the two arc edges of a shaft's quarter
// block (one slave edge, two master edges meeting at a point), or the two arcs against the bore (two slave edges
// meeting at a point). Discretised pair by pair, the slave segment across such a point gets two consistent dual
// bases on its two partly covered parts (one per pair), or the shared slave node two half multipliers: more rows
// than the gap has freedom there, and a uniform pressure comes out as spikes of both signs.
//
// So the pairs between the same two bodies whose slave edges chain end to end (or are the same edge) and whose
// master edges do likewise form one group, discretised as one pair: the slave edges chained into one polyline,
// the master edges into another, one segment mesh and one dual basis on it, each slave node one multiplier. Each
// pair keeps the rows of its own slave edge's nodes opposite its own master edge (where two pairs could hold a
// node, the first in the job's order does); a piece of a slave edge opposite a master edge it is not paired with
// carries nothing. A pair alone is a group of one, discretised exactly as before.
#pragma once

#include "contact/problem.hpp"
#include "contact_index.hpp"

#include <string>
#include <vector>

namespace contact::mortar {

// One side of a group: its edges chained into one polyline of mesh nodes.
struct Chain {
  std::vector<std::string> edges;  // the side's edges in chain order
  std::vector<size_t> start;       // per edge: the chain position of its first node
  std::vector<int> nodes;          // the chain's nodes, each once (a closed chain: from its start, not repeated)
  bool closed = false;             // the chain is a closed loop (one closed edge, or edges that close one)

  // The edge (index into edges) of the chain's segment k (from position k to k + 1).
  size_t edge_of_segment(size_t k) const;
  // The index of an edge in edges (edges.size() when absent).
  size_t index(const std::string& edge) const;
};

struct PairGroup {
  std::vector<int> pairs;  // the group's pairs (indices into Problem::contacts) in the job's order
  Chain slave, master;
  // Whether pairs has a pair of slave edge s and master edge m (indices into slave.edges, master.edges), and
  // which: the first in the job's order (-1 if none).
  int pair_of(size_t s, size_t m) const;
  std::vector<std::vector<int>> by_edges;  // [s][m] -> pair index or -1
};

// The group of pair `pair_index`. Edges that do not chain into one polyline per side (they meet at no end, or
// fork) leave the pair alone in its group.
// `index`: the problem's pairs by body (made here when null).
PairGroup pair_group(const Problem& problem, int pair_index, const ContactIndex* index = nullptr);

}  // namespace contact::mortar
