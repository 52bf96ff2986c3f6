// Quality figures of a built tree, comparable across builders and with other
// tools' trees: sah_cost is normalised as docs/ARCHITECTURE.md says (inner nodes cost 1,
// leaves cost their triangle count, each weighted by SA(node)/SA(root)).
#pragma once

#include <cstddef>
#include <cstdint>

namespace hprt {

struct TreeStats {
  size_t triangles = 0;          // valid triangles in the tree
  size_t invalid_triangles = 0;  // degenerate or non-finite, left out
  size_t nodes = 0;              // inner + leaves
  size_t leaves = 0;
  int depth = 0;
  double avg_leaf_size = 0.0;
  int max_leaf_size = 0;
  double sah_cost = 0.0;
  uint64_t tree_hash = 0;
};

}  // namespace hprt
