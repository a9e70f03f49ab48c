#include "features.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

namespace fignet::detail {

namespace {

// Writes a relative vector and its norm (C.2 "Norm features"); returns the next free slot.
float* put_vector(float* out, const Vec3& d) {
  out[0] = static_cast<float>(d.x());
  out[1] = static_cast<float>(d.y());
  out[2] = static_cast<float>(d.z());
  out[3] = static_cast<float>(d.norm());
  return out + 4;
}

float* put_direction(float* out, const Vec3& n) {
  out[0] = static_cast<float>(n.x());
  out[1] = static_cast<float>(n.y());
  out[2] = static_cast<float>(n.z());
  return out + 3;
}

// [x^t − x^{t−1}, …, x^{t−h+1} − x^{t−h}] (newest first), their signed logarithms when
// configured, static properties, kinematic flag, next-step displacement of kinematic nodes.
template <class PositionAt>
float* put_dynamic_features(float* out, const GraphConfig& config, const SceneObject& object,
                            PositionAt position_at, const Vec3& next) {
  const int history = config.history;
  for (int k = history; k >= 1; --k) out = put_vector(out, position_at(k) - position_at(k - 1));
  // The velocities above are normalised by a spread set by falls and impacts (~5 cm per frame),
  // where a body sliding to a stop moves a fraction of a millimetre: sign(v)·ln(1 + |v|/s)
  // resolves both.
  if (const double s = config.velocity_log_scale; s > 0.0) {
    for (int k = history; k >= 1; --k) {
      const Vec3 v = position_at(k) - position_at(k - 1);
      for (int c = 0; c < 3; ++c)
        *out++ = static_cast<float>(std::copysign(std::log1p(std::abs(v[c]) / s), v[c]));
    }
  }
  // Kinematic bodies have mass 0: their log mass is taken as 0 too (the flag tells them apart).
  const double mass = object.properties.mass;
  *out++ = static_cast<float>(config.log_mass ? (mass > 0.0 ? std::log(mass) : 0.0) : mass);
  *out++ = static_cast<float>(object.properties.friction);
  *out++ = static_cast<float>(object.properties.restitution);
  *out++ = object.kinematic ? 1.0f : 0.0f;
  return put_vector(out, object.kinematic ? Vec3(next - position_at(history)) : Vec3::Zero());
}

}  // namespace

void append_mesh_nodes(const GraphConfig& config, const SceneObject& object, const Floor* floor,
                       FeatureMatrix& out) {
  const int v = object.mesh->num_vertices();
  const int h = config.history;
  float* row = out.append_rows(v);
  for (int i = 0; i < v; ++i, row += out.cols()) {
    auto position_at = [&](int k) -> Vec3 {
      return object.positions.row(static_cast<Eigen::Index>(k) * v + i).transpose();
    };
    const Vec3 next =
        object.kinematic ? Vec3(object.next_positions.row(i).transpose()) : Vec3::Zero();
    float* end = put_dynamic_features(row, config, object, position_at, next);
    if (config.floor == FloorModel::kImplicit) {
      // [within d_c of the floor, height above it when within] (seed D.2's implicit floor).
      const double height = floor ? position_at(h).z() - floor->height : INFINITY;
      const bool near = height < config.collision_radius;
      end[0] = near ? 1.0f : 0.0f;
      end[1] = near ? static_cast<float>(height) : 0.0f;
    }
  }
}

void append_object_node(const GraphConfig& config, const SceneObject& object, FeatureMatrix& out) {
  auto center_at = [&](int k) -> Vec3 { return object.centers.row(k).transpose(); };
  put_dynamic_features(out.append_rows(1), config, object, center_at, object.next_center);
}

namespace {

// [d_rs, |d_rs|, d^U_rs, |d^U_rs|]: current and rest-shape receiver-minus-sender.
void put_edge(EdgeSet& out, int sender, int receiver, const Vec3& d, const Vec3& d_rest) {
  out.senders.push_back(sender);
  out.receivers.push_back(receiver);
  put_vector(put_vector(out.features.append_rows(1), d), d_rest);
}

}  // namespace

void append_mesh_edges(const SceneObject& object, int first, EdgeSet& out) {
  const int v = object.mesh->num_vertices();
  const auto current =
      object.positions.middleRows(static_cast<Eigen::Index>(object.num_steps() - 1) * v, v);
  const Points& rest = object.mesh->vertices();
  const EdgeList& edges = object.mesh->edges();
  for (Eigen::Index e = 0; e < edges.rows(); ++e) {
    const int a = edges(e, 0), b = edges(e, 1);
    const Vec3 d = (current.row(b) - current.row(a)).transpose();
    const Vec3 d_rest = (rest.row(b) - rest.row(a)).transpose();
    put_edge(out, first + a, first + b, d, d_rest);
    put_edge(out, first + b, first + a, -d, -d_rest);
  }
}

void append_object_mesh_edges(const SceneObject& object, int object_index, int first,
                              EdgeSet& object_to_mesh, EdgeSet& mesh_to_object) {
  const int v = object.mesh->num_vertices();
  const auto current =
      object.positions.middleRows(static_cast<Eigen::Index>(object.num_steps() - 1) * v, v);
  const Vec3 center = object.centers.bottomRows(1).transpose();
  // Rest vertices are in the centre-of-mass frame, so the object node rests at the origin.
  for (int i = 0; i < v; ++i) {
    const Vec3 d = current.row(i).transpose() - center;
    const Vec3 d_rest = object.mesh->vertices().row(i).transpose();
    put_edge(object_to_mesh, object_index, first + i, d, d_rest);
    put_edge(mesh_to_object, first + i, object_index, -d, -d_rest);
  }
}

namespace {

// A face's three nodes sorted by distance to its closest point; exact ties are broken by the
// spanning vector itself, so the order depends on geometry only, never on the input order.
struct SortedFace {
  std::array<int, 3> nodes;   // local vertex indices, sorted
  std::array<Vec3, 3> spans;  // x_j − p
};

SortedFace sort_face(const PosedMesh& posed, int face, const Vec3& point, double span_limit) {
  SortedFace sorted;
  const auto vertices = posed.vertices();
  std::array<std::pair<std::tuple<double, double, double, double>, int>, 3> keyed;
  for (int k = 0; k < 3; ++k) {
    const int node = posed.mesh->faces()(face, k);
    const Vec3 span = vertices.row(node).transpose() - point;
    keyed[k] = {{span.squaredNorm(), span.x(), span.y(), span.z()}, node};
  }
  std::sort(keyed.begin(), keyed.end());
  for (int k = 0; k < 3; ++k) {
    sorted.nodes[k] = keyed[k].second;
    sorted.spans[k] = vertices.row(keyed[k].second).transpose() - point;
    // A floor triangle's spans (tens of metres) would set the features' scale and squash every
    // object face's (decimetres); beyond the limit only their direction is kept.
    const double length = sorted.spans[k].norm();
    if (span_limit > 0.0 && length > span_limit) sorted.spans[k] *= span_limit / length;
  }
  return sorted;
}

Vec3 current_normal(const PosedMesh& posed, int face) {
  const auto vertices = posed.vertices();
  const auto& f = posed.mesh->faces().row(face);
  return triangle_normal(vertices.row(f(0)).transpose(), vertices.row(f(1)).transpose(),
                         vertices.row(f(2)).transpose());
}

// How far the point p of a face moved over the last frame: its barycentric weights applied to
// the face's vertex displacements (exact for a rigid motion, which moves points affinely).
Vec3 point_motion(const PosedMesh& posed, int face, const Vec3& p) {
  if (!posed.previous) return Vec3::Zero();
  const auto now = posed.vertices();
  const auto before = posed.previous_vertices();
  const auto& f = posed.mesh->faces().row(face);
  const Vec3 a = now.row(f(0)).transpose(), b = now.row(f(1)).transpose(),
             c = now.row(f(2)).transpose();
  const Vec3 e0 = b - a, e1 = c - a, d = p - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
  const double denominator = d00 * d11 - d01 * d01;
  // A degenerate face has no unique weights: its vertices' mean motion stands for the point's.
  Eigen::Vector3d w = Eigen::Vector3d::Constant(1.0 / 3.0);
  if (denominator > 1e-12 * d00 * d11) {
    const double d20 = d.dot(e0), d21 = d.dot(e1);
    w[1] = (d11 * d20 - d01 * d21) / denominator;
    w[2] = (d00 * d21 - d01 * d20) / denominator;
    w[0] = 1.0 - w[1] - w[2];
  }
  Vec3 motion = Vec3::Zero();
  for (int k = 0; k < 3; ++k) motion += w[k] * (now.row(f(k)) - before.row(f(k))).transpose();
  return motion;
}

// [d_rs, |d_rs|, (d_sj, |d_sj|)_j, (d_rj, |d_rj|)_j, n_r, n_s] (seed C.1.1), then
// ln(1 + |d_rs|/s) when distance_log_scale s > 0, then [u, |u|, u·n_s] when contact_motion
// (u shrunk by contact_motion_dead_zone).
void put_face_edge(const GraphConfig& config, const PosedMesh& sender, int sender_face,
                   const Vec3& p_s, int sender_first, const PosedMesh& receiver, int receiver_face,
                   const Vec3& p_r, int receiver_first, FaceEdgeSet& out) {
  const SortedFace s = sort_face(sender, sender_face, p_s, config.face_span_limit);
  const SortedFace r = sort_face(receiver, receiver_face, p_r, config.face_span_limit);
  const Vec3 d = p_r - p_s;
  float* row = put_vector(out.features.append_rows(1), d);
  for (const Vec3& span : s.spans) row = put_vector(row, span);
  for (const Vec3& span : r.spans) row = put_vector(row, span);
  const Vec3 n_s = current_normal(sender, sender_face);
  row = put_direction(row, current_normal(receiver, receiver_face));
  row = put_direction(row, n_s);
  // Resting contact (|d| = 5 mm, Bullet's margin) and a body let go a few millimetres higher are
  // ~0.1σ apart in |d| above (σ ≈ 3 cm); on a logarithmic scale they are ~0.5 apart.
  if (const double scale = config.distance_log_scale; scale > 0.0)
    *row++ = static_cast<float>(std::log1p(d.norm() / scale));
  if (config.contact_motion) {
    Vec3 u = point_motion(receiver, receiver_face, p_r) - point_motion(sender, sender_face, p_s);
    // Shrinking (not clipping) keeps the columns continuous in u across the dead zone's edge.
    if (const double dead_zone = config.contact_motion_dead_zone; dead_zone > 0.0) {
      const double length = u.norm();
      u = length > dead_zone ? Vec3(u * (1.0 - dead_zone / length)) : Vec3::Zero();
    }
    row = put_vector(row, u);
    *row++ = static_cast<float>(u.dot(n_s));
  }
  for (int k = 0; k < 3; ++k) {
    out.senders.push_back(sender_first + s.nodes[k]);
    out.receivers.push_back(receiver_first + r.nodes[k]);
  }
}

}  // namespace

void append_face_edges(const GraphConfig& config, const FacePair& pair, const PosedMesh& a,
                       const PosedMesh& b, int first_a, int first_b, FaceEdgeSet& out) {
  put_face_edge(config, a, pair.face_a, pair.point_a, first_a, b, pair.face_b, pair.point_b,
                first_b, out);
  put_face_edge(config, b, pair.face_b, pair.point_b, first_b, a, pair.face_a, pair.point_a,
                first_a, out);
}

void append_world_edges(const NodePair& pair, const PosedMesh& a, const PosedMesh& b, int first_a,
                        int first_b, EdgeSet& out) {
  const Vec3 d = (b.vertices().row(pair.node_b) - a.vertices().row(pair.node_a)).transpose();
  auto put = [&](int sender, int receiver, const Vec3& delta) {
    out.senders.push_back(sender);
    out.receivers.push_back(receiver);
    put_vector(out.features.append_rows(1), delta);
  };
  put(first_a + pair.node_a, first_b + pair.node_b, d);
  put(first_b + pair.node_b, first_a + pair.node_a, -d);
}

}  // namespace fignet::detail
