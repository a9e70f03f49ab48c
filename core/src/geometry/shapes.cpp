#include "fignet/geometry/shapes.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <tuple>

#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"

namespace fignet {

namespace {

constexpr double kPi = std::numbers::pi;

// Collects vertices and faces; build() orients the closed result outward by its signed volume.
class MeshBuilder {
 public:
  int add_vertex(const Vec3& p) {
    vertices_.push_back(p);
    return static_cast<int>(vertices_.size()) - 1;
  }
  void add_triangle(int a, int b, int c) { faces_.push_back({a, b, c}); }
  void add_quad(int a, int b, int c, int d) {
    add_triangle(a, b, c);
    add_triangle(a, c, d);
  }

  TriangleMesh build(std::string name) const {
    Points vertices(static_cast<Eigen::Index>(vertices_.size()), 3);
    for (size_t i = 0; i < vertices_.size(); ++i) vertices.row(i) = vertices_[i];
    Triangles faces(static_cast<Eigen::Index>(faces_.size()), 3);
    for (size_t i = 0; i < faces_.size(); ++i) {
      faces.row(i) << faces_[i][0], faces_[i][1], faces_[i][2];
    }
    // Construction keeps a consistent winding; flip all faces if it points inward (a clockwise
    // polygon, a left-handed tube frame).
    double signed_volume = 0.0;
    for (Eigen::Index f = 0; f < faces.rows(); ++f) {
      const Vec3 a = vertices.row(faces(f, 0)), b = vertices.row(faces(f, 1)),
                 c = vertices.row(faces(f, 2));
      signed_volume += a.dot(b.cross(c));
    }
    if (signed_volume < 0.0) faces.col(1).swap(faces.col(2));
    return TriangleMesh(std::move(name), std::move(vertices), std::move(faces));
  }

 private:
  std::vector<Vec3> vertices_;
  std::vector<std::array<int, 3>> faces_;
};

// Closes a counter-clockwise (seen from +z) ring with a fan around `center`, or without a centre
// (center < 0) with a polygon fan, facing +z or -z.
void cap_ring(MeshBuilder& b, const std::vector<int>& ring, int center, bool facing_up) {
  const int n = static_cast<int>(ring.size());
  auto fan = [&](int hub, int i, int j) {
    facing_up ? b.add_triangle(hub, ring[i], ring[j]) : b.add_triangle(hub, ring[j], ring[i]);
  };
  if (center >= 0) {
    for (int i = 0; i < n; ++i) fan(center, i, (i + 1) % n);
  } else {
    for (int i = 1; i + 1 < n; ++i) fan(ring[0], i, i + 1);
  }
}

void connect_rings(MeshBuilder& b, const std::vector<int>& lower, const std::vector<int>& upper) {
  const int n = static_cast<int>(lower.size());
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    b.add_quad(lower[i], lower[j], upper[j], upper[i]);
  }
}

// Surface of revolution about z through profile points (r, z), bottom to top. A point with r = 0
// becomes a pole; a first or last ring with r > 0 is closed by a polygon cap.
TriangleMesh revolve(std::string name, const std::vector<Eigen::Vector2d>& profile, int segments) {
  MeshBuilder b;
  std::vector<std::vector<int>> rings;
  std::vector<int> poles;
  for (const auto& point : profile) {
    if (point.x() == 0.0) {
      poles.push_back(b.add_vertex(Vec3(0, 0, point.y())));
      rings.emplace_back();
      continue;
    }
    poles.push_back(-1);
    std::vector<int> ring;
    for (int i = 0; i < segments; ++i) {
      const double angle = 2.0 * kPi * i / segments;
      ring.push_back(
          b.add_vertex(Vec3(point.x() * std::cos(angle), point.x() * std::sin(angle), point.y())));
    }
    rings.push_back(std::move(ring));
  }
  for (size_t k = 0; k + 1 < profile.size(); ++k) {
    if (poles[k] >= 0) {
      cap_ring(b, rings[k + 1], poles[k], /*facing_up=*/false);
    } else if (poles[k + 1] >= 0) {
      cap_ring(b, rings[k], poles[k + 1], /*facing_up=*/true);
    } else {
      connect_rings(b, rings[k], rings[k + 1]);
    }
  }
  if (poles.front() < 0) cap_ring(b, rings.front(), -1, /*facing_up=*/false);
  if (poles.back() < 0) cap_ring(b, rings.back(), -1, /*facing_up=*/true);
  return b.build(std::move(name));
}

// Closed tube: point(i, j) for i < n (along the tube) and j < m (around it), periodic in both.
template <class PointAt>
TriangleMesh periodic_grid(std::string name, int n, int m, PointAt point) {
  MeshBuilder b;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) b.add_vertex(point(i, j));
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      const int i1 = (i + 1) % n, j1 = (j + 1) % m;
      b.add_quad(i * m + j, i1 * m + j, i1 * m + j1, i * m + j1);
    }
  }
  return b.build(std::move(name));
}

// Boundary of a union of voxels on an n^3 grid filling [-h, h]^3, each voxel face split into
// subdivisions^2 squares; lattice points are shared, so the surface is welded.
template <class IsFilled>
TriangleMesh voxel_surface(std::string name, int n, double half_extent, int subdivisions,
                           IsFilled filled) {
  MeshBuilder b;
  const int lattice = n * subdivisions;
  std::map<std::tuple<int, int, int>, int> index;
  auto vertex = [&](int x, int y, int z) {
    const auto [it, inserted] = index.try_emplace({x, y, z}, -1);
    if (inserted) {
      const double step = 2.0 * half_extent / lattice;
      it->second = b.add_vertex(
          Vec3(-half_extent + x * step, -half_extent + y * step, -half_extent + z * step));
    }
    return it->second;
  };
  auto inside = [&](int x, int y, int z) {
    return x >= 0 && y >= 0 && z >= 0 && x < n && y < n && z < n && filled(x, y, z);
  };
  for (int x = 0; x < n; ++x) {
    for (int y = 0; y < n; ++y) {
      for (int z = 0; z < n; ++z) {
        if (!filled(x, y, z)) continue;
        for (int axis = 0; axis < 3; ++axis) {
          for (int side = 0; side < 2; ++side) {
            int neighbour[3] = {x, y, z};
            neighbour[axis] += side ? 1 : -1;
            if (inside(neighbour[0], neighbour[1], neighbour[2])) continue;
            // The face lies on the lattice plane `axis` = cell + side; u, v span it.
            const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
            const int cell[3] = {x, y, z};
            for (int i = 0; i < subdivisions; ++i) {
              for (int j = 0; j < subdivisions; ++j) {
                auto corner = [&](int du, int dv) {
                  int p[3];
                  p[axis] = (cell[axis] + side) * subdivisions;
                  p[u_axis] = cell[u_axis] * subdivisions + i + du;
                  p[v_axis] = cell[v_axis] * subdivisions + j + dv;
                  return vertex(p[0], p[1], p[2]);
                };
                // Winding: u × v points along +axis; reverse it on the negative side.
                if (side) {
                  b.add_quad(corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1));
                } else {
                  b.add_quad(corner(0, 0), corner(0, 1), corner(1, 1), corner(1, 0));
                }
              }
            }
          }
        }
      }
    }
  }
  return b.build(std::move(name));
}

void require(bool ok, std::string_view shape, std::string_view what) {
  if (!ok) throw ConfigError(fmt::format("{}: {}", shape, what));
}

}  // namespace

TriangleMesh make_box(const Vec3& half_extents, int segments) {
  require((half_extents.array() > 0).all(), "box", "half extents must be positive");
  require(segments >= 1, "box", "segments must be >= 1");
  TriangleMesh unit = voxel_surface("cube", 1, 1.0, segments, [](int, int, int) { return true; });
  Points vertices = unit.vertices() * half_extents.asDiagonal();
  return TriangleMesh("cube", std::move(vertices), unit.faces());
}

TriangleMesh make_sphere(double radius, int rings, int segments) {
  require(radius > 0, "sphere", "radius must be positive");
  require(rings >= 2 && segments >= 3, "sphere", "needs >= 2 rings and >= 3 segments");
  std::vector<Eigen::Vector2d> profile;
  for (int k = 0; k < rings; ++k) {
    const double polar = kPi * (rings - k - 0.5) / rings;  // bottom to top
    profile.emplace_back(radius * std::sin(polar), radius * std::cos(polar));
  }
  return revolve("sphere", profile, segments);
}

TriangleMesh make_cylinder(double radius, double half_height, int segments) {
  require(radius > 0 && half_height > 0, "cylinder", "radius and half height must be positive");
  require(segments >= 3, "cylinder", "needs >= 3 segments");
  return revolve(
      "cylinder",
      {{0.0, -half_height}, {radius, -half_height}, {radius, half_height}, {0.0, half_height}},
      segments);
}

TriangleMesh make_cone(double radius, double height, int segments) {
  require(radius > 0 && height > 0, "cone", "radius and height must be positive");
  require(segments >= 3, "cone", "needs >= 3 segments");
  return revolve("cone", {{0.0, -height / 2}, {radius, -height / 2}, {0.0, height / 2}}, segments);
}

TriangleMesh make_capsule(double radius, double half_height, int cap_rings, int segments) {
  require(radius > 0 && half_height > 0, "capsule", "needs radius > 0 and half height > 0");
  require(cap_rings >= 1 && segments >= 3, "capsule", "too few rings or segments");
  // Poles, then rings down the bottom hemisphere's quarter circle and up the top one.
  std::vector<Eigen::Vector2d> profile = {{0.0, -half_height - radius}};
  for (int k = 1; k <= cap_rings; ++k) {
    const double angle = 0.5 * kPi * k / cap_rings;  // from the pole to the equator
    profile.emplace_back(radius * std::sin(angle), -half_height - radius * std::cos(angle));
  }
  for (int k = cap_rings; k >= 1; --k) {
    const double angle = 0.5 * kPi * k / cap_rings;
    profile.emplace_back(radius * std::sin(angle), half_height + radius * std::cos(angle));
  }
  profile.emplace_back(0.0, half_height + radius);
  return revolve("capsule", profile, segments);
}

TriangleMesh make_torus(double major_radius, double minor_radius, int major_segments,
                        int minor_segments) {
  require(minor_radius > 0 && major_radius > minor_radius, "torus",
          "needs 0 < minor radius < major radius");
  require(major_segments >= 3 && minor_segments >= 3, "torus", "needs >= 3 segments each way");
  return periodic_grid("torus", major_segments, minor_segments, [&](int i, int j) {
    const double u = 2 * kPi * i / major_segments, v = 2 * kPi * j / minor_segments;
    const double r = major_radius + minor_radius * std::cos(v);
    return Vec3(r * std::cos(u), r * std::sin(u), minor_radius * std::sin(v));
  });
}

TriangleMesh make_torus_knot(int p, int q, double scale, double tube_radius, int segments,
                             int tube_segments) {
  require(p >= 1 && q >= 1 && scale > 0 && tube_radius > 0, "torus_knot", "bad parameters");
  require(segments >= 8 && tube_segments >= 3, "torus_knot", "too few segments");
  auto curve = [&](double t) {
    const double r = scale * (2.0 + std::cos(q * t));
    return Vec3(r * std::cos(p * t), r * std::sin(p * t), -scale * std::sin(q * t));
  };
  // Frenet frame from central differences: periodic along the closed curve, and the knot's
  // curvature never vanishes, so the frame is well defined everywhere.
  return periodic_grid("torus_knot", segments, tube_segments, [&](int i, int j) {
    const double t = 2 * kPi * i / segments, h = 1e-4;
    const Vec3 c = curve(t);
    const Vec3 tangent = (curve(t + h) - curve(t - h)).normalized();
    const Vec3 accel = curve(t + h) - 2.0 * c + curve(t - h);
    const Vec3 normal = (accel - accel.dot(tangent) * tangent).normalized();
    const Vec3 binormal = tangent.cross(normal);
    const double angle = 2 * kPi * j / tube_segments;
    return Vec3(c + tube_radius * (std::cos(angle) * normal + std::sin(angle) * binormal));
  });
}

TriangleMesh make_gear(int teeth, double root_radius, double tip_radius, double half_thickness) {
  require(teeth >= 3, "gear", "needs >= 3 teeth");
  require(root_radius > 0 && tip_radius > root_radius && half_thickness > 0, "gear",
          "needs 0 < root radius < tip radius and a positive thickness");
  // Each tooth: root, rise, tip, fall, over a quarter of its pitch each.
  std::vector<Eigen::Vector2d> polygon;
  for (int k = 0; k < teeth; ++k) {
    for (int s = 0; s < 4; ++s) {
      const double angle = 2 * kPi * (k + s / 4.0) / teeth;
      const double r = (s == 1 || s == 2) ? tip_radius : root_radius;
      polygon.emplace_back(r * std::cos(angle), r * std::sin(angle));
    }
  }
  return make_prism("gear", polygon, half_thickness);
}

TriangleMesh make_menger_sponge(double half_extent, int level) {
  require(half_extent > 0, "sponge", "half extent must be positive");
  require(level >= 0 && level <= 3, "sponge", "level must be in 0..3");
  const int n = static_cast<int>(std::lround(std::pow(3, level)));
  return voxel_surface("sponge", n, half_extent, 1, [level](int x, int y, int z) {
    // A cell is removed when, at any level, two or more of its base-3 digits are 1.
    for (int k = 0; k < level; ++k, x /= 3, y /= 3, z /= 3) {
      if ((x % 3 == 1) + (y % 3 == 1) + (z % 3 == 1) >= 2) return false;
    }
    return true;
  });
}

TriangleMesh make_prism(std::string name, std::span<const Eigen::Vector2d> polygon,
                        double half_height) {
  require(polygon.size() >= 3 && half_height > 0, name, "prism needs >= 3 points and a height");
  MeshBuilder b;
  std::vector<int> bottom, top;
  for (const auto& p : polygon) bottom.push_back(b.add_vertex(Vec3(p.x(), p.y(), -half_height)));
  for (const auto& p : polygon) top.push_back(b.add_vertex(Vec3(p.x(), p.y(), half_height)));
  cap_ring(b, bottom, b.add_vertex(Vec3(0, 0, -half_height)), /*facing_up=*/false);
  cap_ring(b, top, b.add_vertex(Vec3(0, 0, half_height)), /*facing_up=*/true);
  connect_rings(b, bottom, top);
  return b.build(std::move(name));
}

const std::vector<std::string>& movi_shape_names() {
  static const std::vector<std::string> names = {"cube",  "cylinder",   "sphere", "cone",
                                                 "torus", "torus_knot", "gear",   "sponge"};
  return names;
}

TriangleMesh make_movi_shape(std::string_view name) {
  if (name == "cube") return make_box(Vec3::Ones());
  if (name == "cylinder") return make_cylinder(1.0, 1.0);
  if (name == "sphere") return make_sphere(1.0);
  if (name == "cone") return make_cone(1.0, 2.0);
  if (name == "torus") return make_torus(0.7, 0.3);
  if (name == "torus_knot") return make_torus_knot();
  if (name == "gear") return make_gear();
  if (name == "sponge") return make_menger_sponge(1.0);
  throw ConfigError(fmt::format("unknown shape '{}'; known shapes: {}", name,
                                fmt::join(movi_shape_names(), ", ")));
}

namespace {

// Vertices of rows [a·m, (a+1)·m) and [b·m, (b+1)·m) of a periodic grid mesh.
Points ring_pair(const Points& vertices, int m, int a, int b) {
  Points part(2 * m, 3);
  part.topRows(m) = vertices.middleRows(static_cast<Eigen::Index>(a) * m, m);
  part.bottomRows(m) = vertices.middleRows(static_cast<Eigen::Index>(b) * m, m);
  return part;
}

}  // namespace

std::vector<Points> movi_convex_parts(std::string_view name) {
  const TriangleMesh mesh = make_movi_shape(name);
  const Points& v = mesh.vertices();
  std::vector<Points> parts;
  if (name == "torus" || name == "torus_knot") {
    // periodic_grid layout: vertex i·m + j; the defaults of make_torus / make_torus_knot.
    const int n = name == "torus" ? 32 : 120, m = name == "torus" ? 12 : 8;
    for (int i = 0; i < n; ++i) parts.push_back(ring_pair(v, m, i, (i + 1) % n));
  } else if (name == "gear") {
    // make_prism layout: bottom ring [0, P), top ring [P, 2P); 4 outline points per tooth:
    // root, tip, tip, root.
    const int p = (mesh.num_vertices() - 2) / 2, teeth = p / 4;
    std::vector<Eigen::Index> roots;
    for (int k = 0; k < teeth; ++k) roots.insert(roots.end(), {4 * k, 4 * k + 3});
    Points core(2 * roots.size(), 3);
    for (size_t r = 0; r < roots.size(); ++r) {
      core.row(2 * r) = v.row(roots[r]);
      core.row(2 * r + 1) = v.row(roots[r] + p);
    }
    parts.push_back(core);
    for (int k = 0; k < teeth; ++k) {
      Points tooth(8, 3);
      for (int s = 0; s < 4; ++s) {
        tooth.row(2 * s) = v.row(4 * k + s);
        tooth.row(2 * s + 1) = v.row(4 * k + s + p);
      }
      parts.push_back(tooth);
    }
  } else if (name == "sponge") {
    // make_menger_sponge(1.0, 1): the 20 kept cells of the 3×3×3 grid over [-1, 1]^3.
    for (int x = 0; x < 3; ++x) {
      for (int y = 0; y < 3; ++y) {
        for (int z = 0; z < 3; ++z) {
          if ((x == 1) + (y == 1) + (z == 1) >= 2) continue;
          Points cell(8, 3);
          for (int c = 0; c < 8; ++c) {
            cell.row(c) << -1 + 2.0 / 3 * (x + (c & 1)), -1 + 2.0 / 3 * (y + ((c >> 1) & 1)),
                -1 + 2.0 / 3 * (z + ((c >> 2) & 1));
          }
          parts.push_back(cell);
        }
      }
    }
  } else {
    parts.push_back(v);  // convex: cube, cylinder, sphere, cone
  }
  return parts;
}

}  // namespace fignet
