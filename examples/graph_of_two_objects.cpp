// Builds the FIGNet input graph of a cube falling onto a resting sphere, using fignet's core
// alone (no Bullet): rest meshes, a short pose history, then one GraphBuilder call.
#include <cstdio>
#include <vector>

#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"
#include "fignet/graph/graph_builder.h"

int main() {
  using namespace fignet;
  // Rest meshes live in their body's centre-of-mass frame.
  const TriangleMesh cube = centered_on_center_of_mass(make_box(Vec3::Constant(0.5)));
  const TriangleMesh sphere = centered_on_center_of_mass(make_sphere(0.5));

  // History h = 2 needs three poses per object, oldest first. The cube falls at 1 m/s (48 Hz).
  const double dt = 1.0 / 48.0;
  SceneObject falling;
  falling.mesh = &cube;
  falling.properties = {.mass = 2.7 * 1.0, .friction = 0.4, .restitution = 0.3};  // metal
  set_pose_history(
      falling,
      std::vector<Pose>{{Vec3(0, 0, 1.55 + 2 * dt)}, {Vec3(0, 0, 1.55 + dt)}, {Vec3(0, 0, 1.55)}});
  SceneObject resting;
  resting.mesh = &sphere;
  resting.properties = {.mass = 1.1 * 0.52, .friction = 0.8, .restitution = 0.7};  // rubber
  set_pose_history(resting, std::vector<Pose>(3, Pose{Vec3(0, 0, 0.5)}));

  Scene scene;
  scene.objects = {falling, resting};
  scene.floor = Floor{};  // z = 0, Kubric's floor material

  GraphBuilder builder(GraphConfig{});  // d_c = 0.1 m, h = 2, face-face collisions, mesh floor
  Graph graph;
  builder.build(scene, graph);
  std::printf("mesh nodes %d, objects %d (the floor included)\n", graph.num_mesh_nodes(),
              graph.num_objects());
  std::printf("mesh edges %d, object<->mesh edges %d + %d, face-face edges %d\n",
              graph.mesh_edges.size(), graph.object_to_mesh.size(), graph.mesh_to_object.size(),
              graph.face_edges.size());
  return 0;
}
