#include "fignet/bullet/shape_mesh.h"

#include <BulletCollision/CollisionShapes/btShapeHull.h>
#include <LinearMath/btConvexHullComputer.h>
#include <btBulletCollisionCommon.h>
#include <fmt/format.h>

#include <array>

#include "fignet/bullet/conversions.h"
#include "fignet/error.h"
#include "fignet/geometry/shapes.h"

namespace fignet::bullet {

namespace {

// Welds points by exact position into a vertex list and collects triangles.
class MeshAssembler {
 public:
  int vertex(const Vec3& p) {
    const auto [it, inserted] = index_.emplace(std::array<double, 3>{p.x(), p.y(), p.z()},
                                               static_cast<int>(points_.size()));
    if (inserted) points_.push_back(p);
    return it->second;
  }
  void triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
    const int i = vertex(a), j = vertex(b), k = vertex(c);
    if (i != j && j != k && i != k) faces_.push_back({i, j, k});
  }
  // Appends `mesh` moved by `transform` (kept as separate vertices: compound children may touch
  // without sharing a surface).
  void append(const TriangleMesh& mesh, const btTransform& transform) {
    const int base = static_cast<int>(points_.size());
    for (int v = 0; v < mesh.num_vertices(); ++v)
      points_.push_back(from_bt(transform * to_bt(Vec3(mesh.vertices().row(v).transpose()))));
    for (int f = 0; f < mesh.num_faces(); ++f)
      faces_.push_back(
          {base + mesh.faces()(f, 0), base + mesh.faces()(f, 1), base + mesh.faces()(f, 2)});
  }
  bool empty() const { return faces_.empty(); }
  TriangleMesh finish(std::string name) {
    Points vertices(static_cast<Eigen::Index>(points_.size()), 3);
    for (size_t v = 0; v < points_.size(); ++v)
      vertices.row(static_cast<Eigen::Index>(v)) = points_[v].transpose();
    Triangles faces(static_cast<Eigen::Index>(faces_.size()), 3);
    for (size_t f = 0; f < faces_.size(); ++f)
      faces.row(static_cast<Eigen::Index>(f)) << faces_[f][0], faces_[f][1], faces_[f][2];
    MeshOptions options;
    options.degenerate_faces = DegenerateFaces::kDrop;
    return TriangleMesh(std::move(name), std::move(vertices), std::move(faces), options);
  }

 private:
  std::map<std::array<double, 3>, int> index_;
  std::vector<Vec3> points_;
  std::vector<std::array<int, 3>> faces_;
};

// A mesh built along z turned to Bullet's up axis (0 = x, 1 = y, 2 = z).
TriangleMesh along_axis(const TriangleMesh& mesh, int axis) {
  if (axis == 2) return mesh;
  const Eigen::Matrix3d turn =
      axis == 0 ? Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix()    // z -> x
                : Eigen::AngleAxisd(-M_PI / 2, Vec3::UnitX()).toRotationMatrix();  // z -> y
  return TriangleMesh(mesh.name(), mesh.vertices() * turn.transpose(), mesh.faces());
}

// The convex hull of `points` as a triangle mesh (faces fanned from their first vertex).
TriangleMesh hull_mesh(const std::vector<btVector3>& points, const std::string& name) {
  btConvexHullComputer hull;
  hull.compute(&points[0].x(), sizeof(btVector3), static_cast<int>(points.size()), 0, 0);
  MeshAssembler assembler;
  for (int f = 0; f < hull.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
    const Vec3 a = from_bt(hull.vertices[first->getSourceVertex()]);
    for (const btConvexHullComputer::Edge* e = first->getNextEdgeOfFace();
         e->getTargetVertex() != first->getSourceVertex(); e = e->getNextEdgeOfFace()) {
      assembler.triangle(a, from_bt(hull.vertices[e->getSourceVertex()]),
                         from_bt(hull.vertices[e->getTargetVertex()]));
    }
  }
  if (assembler.empty()) {
    throw MeshError(
        fmt::format("{}: the convex hull of its {} points is flat", name, points.size()));
  }
  return assembler.finish(name);
}

}  // namespace

TriangleMesh shape_to_mesh(const btCollisionShape& shape) {
  switch (shape.getShapeType()) {
    case BOX_SHAPE_PROXYTYPE: {
      const auto& box = static_cast<const btBoxShape&>(shape);
      return make_box(from_bt(box.getHalfExtentsWithMargin()));
    }
    case SPHERE_SHAPE_PROXYTYPE:
      return make_sphere(static_cast<const btSphereShape&>(shape).getRadius());
    case CYLINDER_SHAPE_PROXYTYPE: {
      const auto& cylinder = static_cast<const btCylinderShape&>(shape);
      const int axis = cylinder.getUpAxis();
      const btVector3 half = cylinder.getHalfExtentsWithMargin();
      return along_axis(make_cylinder(cylinder.getRadius(), half[axis]), axis);
    }
    case CONE_SHAPE_PROXYTYPE: {
      const auto& cone = static_cast<const btConeShape&>(shape);
      return along_axis(make_cone(cone.getRadius(), cone.getHeight()), cone.getConeUpIndex());
    }
    case CAPSULE_SHAPE_PROXYTYPE: {
      const auto& capsule = static_cast<const btCapsuleShape&>(shape);
      return along_axis(make_capsule(capsule.getRadius(), capsule.getHalfHeight()),
                        capsule.getUpAxis());
    }
    case CONVEX_HULL_SHAPE_PROXYTYPE: {
      const auto& hull = static_cast<const btConvexHullShape&>(shape);
      std::vector<btVector3> points;
      for (int i = 0; i < hull.getNumPoints(); ++i) points.push_back(hull.getScaledPoint(i));
      return hull_mesh(points, "convex hull");
    }
    case COMPOUND_SHAPE_PROXYTYPE: {
      const auto& compound = static_cast<const btCompoundShape&>(shape);
      MeshAssembler assembler;
      for (int i = 0; i < compound.getNumChildShapes(); ++i) {
        assembler.append(shape_to_mesh(*compound.getChildShape(i)), compound.getChildTransform(i));
      }
      if (assembler.empty()) throw MeshError("compound shape without children");
      return assembler.finish("compound");
    }
    default:
      break;
  }
  if (shape.isConvex()) {
    // Any other convex shape: the hull of its support points in 42 directions (btShapeHull).
    btShapeHull sampler(static_cast<const btConvexShape*>(&shape));
    sampler.buildHull(shape.getMargin());
    std::vector<btVector3> points(sampler.getVertexPointer(),
                                  sampler.getVertexPointer() + sampler.numVertices());
    return hull_mesh(points, shape.getName());
  }
  throw ConfigError(fmt::format(
      "collision shape '{}' (type {}) cannot be converted to a mesh for a moving body: use "
      "box, sphere, cylinder, cone, capsule, convex hull or a compound of these; triangle "
      "meshes and planes are supported for static bodies",
      shape.getName(), shape.getShapeType()));
}

std::unique_ptr<TriangleMesh> concave_triangles_in_box(const btConcaveShape& shape,
                                                       const btVector3& lower,
                                                       const btVector3& upper) {
  struct Collector : btTriangleCallback {
    MeshAssembler assembler;
    void processTriangle(btVector3* t, int, int) override {
      assembler.triangle(from_bt(t[0]), from_bt(t[1]), from_bt(t[2]));
    }
  } collector;
  shape.processAllTriangles(&collector, lower, upper);
  if (collector.assembler.empty()) return nullptr;
  return std::make_unique<TriangleMesh>(collector.assembler.finish(shape.getName()));
}

std::shared_ptr<const TriangleMesh> ShapeMeshCache::mesh_of(const btCollisionShape& shape) {
  const btVector3& s = shape.getLocalScaling();
  auto key = std::pair(&shape, std::vector<float>{float(s.x()), float(s.y()), float(s.z())});
  auto it = meshes_.find(key);
  if (it == meshes_.end()) {
    it = meshes_.emplace(key, std::make_shared<const TriangleMesh>(shape_to_mesh(shape))).first;
  }
  return it->second;
}

}  // namespace fignet::bullet
