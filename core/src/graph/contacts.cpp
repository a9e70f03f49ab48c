#include "fignet/graph/contacts.h"

#include <algorithm>

#include "fignet/geometry/triangle_distance.h"

namespace fignet {

namespace {

Triangle face_triangle(const PosedMesh& posed, std::int32_t face) {
  const auto& f = posed.mesh->faces().row(face);
  const auto v = posed.vertices();
  return {{v.row(f(0)).transpose(), v.row(f(1)).transpose(), v.row(f(2)).transpose()}};
}

}  // namespace

void ContactFinder::update(std::span<const PosedMesh> objects, bool with_node_hierarchies) {
  slots_.resize(objects.size());
  for (size_t o = 0; o < objects.size(); ++o) {
    const PosedMesh& posed = objects[o];
    Slot& slot = slots_[o];
    const auto vertices = posed.vertices();
    // Face boxes at the current pose.
    boxes_.resize(posed.mesh->num_faces());
    for (int f = 0; f < posed.mesh->num_faces(); ++f) {
      Aabb box;
      for (int k = 0; k < 3; ++k) box.extend(vertices.row(posed.mesh->faces()(f, k)).transpose());
      boxes_[f] = box;
    }
    const bool same_mesh = slot.mesh == posed.mesh;
    same_mesh ? slot.faces.refit(boxes_) : slot.faces.build(boxes_);
    if (with_node_hierarchies) {
      boxes_.resize(posed.mesh->num_vertices());
      for (int i = 0; i < posed.mesh->num_vertices(); ++i) {
        boxes_[i] = Aabb{vertices.row(i).transpose(), vertices.row(i).transpose()};
      }
      (same_mesh && slot.has_node_hierarchy) ? slot.nodes.refit(boxes_) : slot.nodes.build(boxes_);
    }
    slot.has_node_hierarchy = with_node_hierarchies;
    slot.mesh = posed.mesh;
    slot.positions = posed.positions;
    slot.kinematic = posed.kinematic;
  }
}

void ContactFinder::find_candidate_pairs(double radius, std::vector<ObjectPair>& out) {
  out.clear();
  const auto n = static_cast<std::int32_t>(slots_.size());
  sweep_.resize(n);
  for (std::int32_t i = 0; i < n; ++i) sweep_[i] = i;
  std::sort(sweep_.begin(), sweep_.end(),
            [&](std::int32_t a, std::int32_t b) { return bounds(a).min.x() < bounds(b).min.x(); });
  const double radius2 = radius * radius;
  for (std::int32_t i = 0; i < n; ++i) {
    const Aabb& a = bounds(sweep_[i]);
    for (std::int32_t j = i + 1; j < n && bounds(sweep_[j]).min.x() <= a.max.x() + radius; ++j) {
      const std::int32_t oa = sweep_[i], ob = sweep_[j];
      if (slots_[oa].kinematic && slots_[ob].kinematic) continue;
      if (squared_distance(a, bounds(ob)) > radius2) continue;
      out.push_back({std::min(oa, ob), std::max(oa, ob)});
    }
  }
  // A deterministic order, independent of the sort's tie-breaking.
  std::sort(out.begin(), out.end(), [](const ObjectPair& x, const ObjectPair& y) {
    return std::tie(x.a, x.b) < std::tie(y.a, y.b);
  });
}

void ContactFinder::find_face_pairs(std::span<const ObjectPair> candidates, double radius,
                                    std::vector<FacePair>& out) const {
  out.clear();
  for (const ObjectPair& pair : candidates) {
    const size_t first = out.size();
    const Slot& a = slots_[pair.a];
    const Slot& b = slots_[pair.b];
    const PosedMesh posed_a{a.mesh, a.positions, a.kinematic};
    const PosedMesh posed_b{b.mesh, b.positions, b.kinematic};
    a.faces.for_each_pair_within(b.faces, radius, [&](std::int32_t fa, std::int32_t fb) {
      const ClosestPoints cp =
          closest_points_triangles(face_triangle(posed_a, fa), face_triangle(posed_b, fb));
      if (cp.distance <= radius) {
        out.push_back({pair.a, fa, pair.b, fb, cp.on_first, cp.on_second, cp.distance});
      }
    });
    // Traversal order depends on whether the hierarchies were rebuilt or refitted; a fixed
    // order keeps the network's sums, and so whole rollouts, independent of that history.
    std::sort(out.begin() + first, out.end(), [](const FacePair& x, const FacePair& y) {
      return std::tie(x.face_a, x.face_b) < std::tie(y.face_a, y.face_b);
    });
  }
}

void ContactFinder::find_node_pairs(std::span<const ObjectPair> candidates, double radius,
                                    std::vector<NodePair>& out) const {
  out.clear();
  for (const ObjectPair& pair : candidates) {
    const size_t first = out.size();
    const Slot& a = slots_[pair.a];
    const Slot& b = slots_[pair.b];
    const Eigen::Map<const Points> va(a.positions, a.mesh->num_vertices(), 3);
    const Eigen::Map<const Points> vb(b.positions, b.mesh->num_vertices(), 3);
    a.nodes.for_each_pair_within(b.nodes, radius, [&](std::int32_t i, std::int32_t j) {
      const double distance = (va.row(i) - vb.row(j)).norm();
      if (distance <= radius) out.push_back({pair.a, i, pair.b, j, distance});
    });
    std::sort(out.begin() + first, out.end(), [](const NodePair& x, const NodePair& y) {
      return std::tie(x.node_a, x.node_b) < std::tie(y.node_a, y.node_b);
    });
  }
}

}  // namespace fignet
