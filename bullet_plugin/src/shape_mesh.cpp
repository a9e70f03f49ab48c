#include "fignet/bullet/shape_mesh.h"

#include <BulletCollision/CollisionShapes/btShapeHull.h>
#include <btBulletCollisionCommon.h>
#include <fmt/format.h>

#include "fignet/bullet/conversions.h"
#include "fignet/error.h"
#include "fignet/geometry/shapes.h"
#include "mesh_assembler.h"

namespace fignet::bullet {

namespace {

// A mesh built along z turned to Bullet's up axis (0 = x, 1 = y, 2 = z).
TriangleMesh along_axis(const TriangleMesh& mesh, int axis) {
  if (axis == 2) return mesh;
  const Eigen::Matrix3d turn =
      axis == 0 ? Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix()    // z -> x
                : Eigen::AngleAxisd(-M_PI / 2, Vec3::UnitX()).toRotationMatrix();  // z -> y
  return TriangleMesh(mesh.name(), mesh.vertices() * turn.transpose(), mesh.faces());
}

// The convex hull of `points` as a mesh named `name`; MeshError when it is flat.
template <class PointRange>
TriangleMesh hull_mesh(const PointRange& points, int count, const std::string& name) {
  Points coordinates(count, 3);
  for (int i = 0; i < count; ++i) coordinates.row(i) = from_bt(points[i]).transpose();
  const MeshAssembler assembler = convex_hull_triangles(coordinates);
  if (assembler.empty()) {
    throw MeshError(fmt::format("{}: the convex hull of its {} points is flat", name, count));
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
      return hull_mesh(points, hull.getNumPoints(), "convex hull");
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
    return hull_mesh(sampler.getVertexPointer(), sampler.numVertices(), shape.getName());
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

namespace {

auto cache_key(const btCollisionShape& shape) {
  const btVector3& s = shape.getLocalScaling();
  return std::pair(&shape, std::array<double, 3>{s.x(), s.y(), s.z()});
}

}  // namespace

std::shared_ptr<const TriangleMesh> ShapeMeshCache::within_budget(
    std::shared_ptr<const TriangleMesh> mesh) const {
  if (!budget_ || budget_->max_vertices <= 0 || mesh->num_vertices() <= budget_->max_vertices) {
    return mesh;
  }
  SimplifiedMesh simplified = simplify_mesh(*mesh, *budget_);
  // A closed mesh stays closed or stays as it is: its faces' normals must keep meaning outward.
  if (!simplified.changed || (!simplified.closed && mesh->is_closed())) return mesh;
  return std::make_shared<const TriangleMesh>(std::move(simplified.mesh));
}

void ShapeMeshCache::set_mesh(const btCollisionShape& shape,
                              std::shared_ptr<const TriangleMesh> mesh) {
  meshes_[cache_key(shape)] = within_budget(std::move(mesh));
}

std::shared_ptr<const TriangleMesh> ShapeMeshCache::mesh_of(const btCollisionShape& shape) {
  const auto key = cache_key(shape);
  auto it = meshes_.find(key);
  if (it == meshes_.end()) {
    it =
        meshes_
            .emplace(key, within_budget(std::make_shared<const TriangleMesh>(shape_to_mesh(shape))))
            .first;
  }
  return it->second;
}

}  // namespace fignet::bullet
