#include "fignet/geometry/bvh.h"

#include <algorithm>
#include <numeric>

namespace fignet {

void Bvh::build(std::span<const Aabb> primitive_boxes) {
  boxes_.assign(primitive_boxes.begin(), primitive_boxes.end());
  order_.resize(boxes_.size());
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.clear();
  if (boxes_.empty()) return;
  nodes_.reserve(boxes_.size() + 1);  // a median-split tree with leaves of 1..4 has <= n nodes
  build_node(boxes_, 0, static_cast<std::int32_t>(boxes_.size()));
}

std::int32_t Bvh::build_node(std::span<const Aabb> boxes, std::int32_t begin, std::int32_t end) {
  const auto index = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  Aabb box, centers;
  for (std::int32_t i = begin; i < end; ++i) {
    box.extend(boxes[order_[i]]);
    centers.extend(boxes[order_[i]].center());
  }
  nodes_[index].box = box;
  if (end - begin <= kLeafSize) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  // Median split along the longest axis of the primitive centres: depth stays log2(n).
  int axis = 0;
  centers.extent().maxCoeff(&axis);
  const std::int32_t middle = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](std::int32_t a, std::int32_t b) {
                     return boxes[a].center()[axis] < boxes[b].center()[axis];
                   });
  const std::int32_t left = build_node(boxes, begin, middle);
  const std::int32_t right = build_node(boxes, middle, end);
  nodes_[index].first = left;
  nodes_[index].right = right;
  return index;
}

void Bvh::refit(std::span<const Aabb> primitive_boxes) {
  std::copy(primitive_boxes.begin(), primitive_boxes.end(), boxes_.begin());
  if (!nodes_.empty()) refit_node(0, boxes_);
}

void Bvh::refit_node(std::int32_t index, std::span<const Aabb> boxes) {
  Node& node = nodes_[index];
  Aabb box;
  if (node.is_leaf()) {
    for (std::int32_t i = node.first; i < node.first + node.count; ++i)
      box.extend(boxes[order_[i]]);
  } else {
    refit_node(node.first, boxes);
    refit_node(node.right, boxes);
    box.extend(nodes_[node.first].box);
    box.extend(nodes_[node.right].box);
  }
  nodes_[index].box = box;
}

}  // namespace fignet
