// A bounding-volume hierarchy over primitive boxes (mesh faces or points), and the query that
// finds every pair of primitives of two hierarchies whose boxes lie within a distance.
//
// The tree's topology is built once from the rest mesh; each step only refits the boxes to the
// moved vertices (O(n), no allocation). Rigid motion keeps a rest-shape topology efficient.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "fignet/geometry/aabb.h"

namespace fignet {

class Bvh {
 public:
  // Builds the topology by median splits along the longest axis, and the node boxes.
  void build(std::span<const Aabb> primitive_boxes);
  // Recomputes every node box from new primitive boxes (same count and order as build()).
  void refit(std::span<const Aabb> primitive_boxes);

  bool empty() const { return nodes_.empty(); }
  const Aabb& bounds() const { return nodes_.front().box; }
  int num_primitives() const { return static_cast<int>(order_.size()); }

  // Calls visit(i, j) for each primitive i of *this and j of other whose boxes are within
  // `margin` of each other. Every pair within the margin is visited exactly once.
  template <class Visit>
  void for_each_pair_within(const Bvh& other, double margin, Visit&& visit) const;

 private:
  static constexpr int kLeafSize = 4;
  static constexpr int kMaxStack = 256;

  struct Node {
    Aabb box;
    std::int32_t first = 0;   // leaf: first index into order_; inner: the left child
    std::int32_t count = 0;   // leaf: number of primitives; inner: 0
    std::int32_t right = -1;  // inner: the right child
    bool is_leaf() const { return count > 0; }
  };

  std::int32_t build_node(std::span<const Aabb> boxes, std::int32_t begin, std::int32_t end);
  void refit_node(std::int32_t node, std::span<const Aabb> boxes);

  const Aabb& primitive_box_of(std::int32_t primitive) const { return boxes_[primitive]; }

  std::vector<Node> nodes_;
  std::vector<std::int32_t> order_;  // primitive indices, grouped by leaf
  std::vector<Aabb> boxes_;          // primitive boxes, by primitive index
};

template <class Visit>
void Bvh::for_each_pair_within(const Bvh& other, double margin, Visit&& visit) const {
  if (empty() || other.empty()) return;
  const double margin2 = margin * margin;
  // Depth-first dual traversal; the stack holds node pairs still to test. Each pop pushes at
  // most two pairs and descends one tree by a level, so its depth is bounded by the sum of the
  // tree depths (median splits keep those logarithmic).
  std::int32_t stack[kMaxStack][2];
  int top = 0;
  stack[top][0] = 0, stack[top][1] = 0, ++top;
  while (top > 0) {
    --top;
    const Node& a = nodes_[stack[top][0]];
    const Node& b = other.nodes_[stack[top][1]];
    if (squared_distance(a.box, b.box) > margin2) continue;
    if (a.is_leaf() && b.is_leaf()) {
      for (std::int32_t i = a.first; i < a.first + a.count; ++i) {
        for (std::int32_t j = b.first; j < b.first + b.count; ++j) {
          const std::int32_t pi = order_[i], pj = other.order_[j];
          if (squared_distance(primitive_box_of(pi), other.primitive_box_of(pj)) <= margin2) {
            visit(pi, pj);
          }
        }
      }
      continue;
    }
    // Descend the larger box (or the only inner node) so both trees shrink together.
    const bool descend_a = !a.is_leaf() && (b.is_leaf() || a.box.extent().squaredNorm() >=
                                                               b.box.extent().squaredNorm());
    const std::int32_t a_index = stack[top][0], b_index = stack[top][1];
    if (descend_a) {
      stack[top][0] = a.first, stack[top][1] = b_index, ++top;
      stack[top][0] = a.right, stack[top][1] = b_index, ++top;
    } else {
      stack[top][0] = a_index, stack[top][1] = b.first, ++top;
      stack[top][0] = a_index, stack[top][1] = b.right, ++top;
    }
  }
}

}  // namespace fignet
