// Every tunable of the input graph, in one struct that is saved inside model files.
#pragma once

namespace fignet {

// How objects interact across the collision radius.
enum class CollisionEdges {
  kFaceFace,  // FIGNet: face–face hyper-edges between triangles (seed C.1.1)
  kNodeNode,  // FIGNet-NoFaceCollision: MeshGraphNets "world edges" between mesh nodes (seed D.2)
};

// How the floor enters the graph.
enum class FloorModel {
  kMesh,      // a static object of 2·floor_segments² large triangles (seed C.1.1)
  kImplicit,  // no floor object; mesh nodes carry [within d_c of the floor, height] (seed D.2)
  kNone,      // no floor at all (the scene brings its own static geometry)
};

struct GraphConfig {
  double collision_radius = 0.1;  // d_c in metres: faces of different objects closer than this
  int history = 2;                // h: velocities per node feature (h + 1 positions are needed)
  bool object_nodes = true;       // false gives FIGNet-NoObjectNode
  CollisionEdges collisions = CollisionEdges::kFaceFace;
  FloorModel floor = FloorModel::kMesh;
  double floor_half_extent = 40.0;  // the floor spans [-e, e]² (Kubric's dome bounds)
  int floor_segments = 1;           // > 1 subdivides the floor mesh (MGN's "subdivided floor")
  // Mesh–mesh edges inside objects; false gives FIGNet* (object nodes carry the rigid coupling,
  // about 40 % fewer FLOPs). Needs object_nodes.
  bool mesh_edges = true;
  // Mesh and object–mesh edges inside kinematic objects (the floor's 80 m edges among them);
  // their latents cannot move anything, only set the normalisers' scales.
  bool static_internal_edges = true;
  // The mass feature as log(kg) instead of kg (MOVi masses span 1.4–59 kg).
  bool log_mass = false;
  // > 0: face–face edges' spans (closest point to each face vertex) are shortened to at most this
  // many metres. The floor's 20–56 m spans otherwise set the features' scale, and objects' faces
  // (0.4 m median in MOVi-A) read as ~0.01σ; 0 keeps them whole (seed C.1.1).
  double face_span_limit = 0.0;
  // > 0: node features also carry sign(v)·ln(1 + |v|/s) of each velocity component, s in metres
  // per frame, so that sub-millimetre motion (a body sliding to a stop) is not ~0.01σ.
  double velocity_log_scale = 0.0;
  // > 0: face–face edges also carry ln(1 + |d_rs|/s) of the closest-point distance, s in metres.
  // |d_rs| is normalised by a σ set by the collision radius (3.2 cm in a MOVi-A model), where a
  // body resting 5 mm above the floor and one held 4 mm higher differ by 0.13σ.
  double distance_log_scale = 0.0;
  // Face–face edges also carry the motion of the receiver's closest point relative to the
  // sender's over the last frame, u = Δp_r − Δp_s (each interpolated from its face's vertex
  // displacements, exact for rigid motion), as [u, |u|, u·n_s]: u·n_s < 0 is the approach speed
  // along the sender's normal. With |d_rs| it tells when within the next frame two faces meet,
  // which node velocities give only through six vertices' latents; the one-step error of
  // impacts (4× moving contact's, and too soft) comes from that instant.
  bool contact_motion = false;
  // > 0: u is shrunk toward zero by this many metres per frame before it is written, u·(1 −
  // δ/|u|) where |u| > δ and 0 below. Resting contacts then read u = 0 in training as in a
  // rollout, instead of the training noise's few tenths of a millimetre (a rollout from rest
  // starts at exactly 0, where the network had never been taught); 0 keeps u whole.
  double contact_motion_dead_zone = 0.0;
  // Dynamic objects without a collision edge are left out of the graph, in training and in
  // prediction, and move by gravity alone (rollout/free_flight.h), as FIGNetDynamicsWorld's free
  // flight moves them: the network is spent on bodies in contact only. Without it the network
  // also learns, and is asked, the free flight of bodies that touch nothing.
  bool omit_free_flight = false;

  // Throws ConfigError naming the first invalid field and its value.
  void validate() const;
};

// Feature widths of each node and edge type under `config` (seed C.1.1 with C.2's norms).
struct FeatureSizes {
  int mesh_node;    // h·(3+1) velocities (+ h·3 logarithms), 3 static properties, kinematic
                    // flag, 3+1 next-step move
  int object_node;  // as mesh nodes, at the centre of mass (no implicit-floor features)
  int mesh_edge;    // [d, |d|, d_rest, |d_rest|] = 8; also object->mesh and mesh->object
  int world_edge;   // [d, |d|] = 4 (node–node collision edges)
  int face_edge;    // [d_rs, 3 sender spans, 3 receiver spans] with norms, n_r, n_s = 34
                    // (+ 1 logarithm of |d_rs|, + 5 contact motion)
};
FeatureSizes feature_sizes(const GraphConfig& config);

}  // namespace fignet
