#include "fignet/bullet/urdf.h"

#include <console_bridge/console.h>
#include <fmt/format.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>

#include "fignet/bullet/convex_decomposition.h"
#include "fignet/bullet/mesh_file.h"
#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"
#include "mesh_assembler.h"

namespace fignet::bullet {

namespace {

using Transform = Eigen::Isometry3d;

Transform to_transform(const urdf::Pose& pose) {
  Transform t = Transform::Identity();
  t.translate(Vec3(pose.position.x, pose.position.y, pose.position.z));
  t.rotate(Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
               .normalized());
  return t;
}

Transform to_transform(const Pose& pose) {
  Transform t = Transform::Identity();
  t.translate(pose.position);
  t.rotate(pose.orientation);
  return t;
}

Pose to_pose(const Transform& t) {
  Pose pose;
  pose.position = t.translation();
  pose.orientation = Eigen::Quaterniond(t.rotation()).normalized();
  return pose;
}

Points transformed(const Points& points, const Transform& t) {
  return (points * t.rotation().transpose()).rowwise() + t.translation().transpose();
}

// urdfdom reports why a file is invalid through console_bridge (to stderr by default); the
// messages are collected instead and become the exception's text.
class CollectedMessages : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level < console_bridge::CONSOLE_BRIDGE_LOG_WARN) return;
    if (!text_.empty()) text_ += "; ";
    text_ += text;
  }
  const std::string& text() const { return text_; }

 private:
  std::string text_;
};

urdf::ModelInterfaceSharedPtr parse_urdf(const std::string& xml, const std::string& where) {
  // console_bridge's handler is process-wide.
  static std::mutex mutex;
  const std::lock_guard lock(mutex);
  CollectedMessages messages;
  console_bridge::useOutputHandler(&messages);
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = urdf::parseURDF(xml);
  } catch (const std::exception& e) {
    messages.log(e.what(), console_bridge::CONSOLE_BRIDGE_LOG_ERROR, nullptr, 0);
  }
  console_bridge::restorePreviousOutputHandler();
  if (!model) {
    throw FileError(
        fmt::format("{}: not a valid URDF ({})", where,
                    messages.text().empty() ? "urdfdom gave no reason" : messages.text()));
  }
  return model;
}

struct Contact {
  std::optional<double> friction, restitution;
};

// PyBullet's <contact> element, which urdfdom does not read: link name -> coefficients.
std::map<std::string, Contact> read_contacts(const std::string& xml, const std::string& where) {
  TiXmlDocument document;
  document.Parse(xml.c_str());
  std::map<std::string, Contact> contacts;
  const TiXmlElement* robot = document.RootElement();
  if (!robot) return contacts;
  const auto value_of = [&](const TiXmlElement* contact, const char* tag, const char* link) {
    std::optional<double> value;
    const TiXmlElement* element = contact->FirstChildElement(tag);
    if (!element) return value;
    double parsed = 0.0;
    if (element->QueryDoubleAttribute("value", &parsed) != TIXML_SUCCESS || !(parsed >= 0.0)) {
      throw FileError(
          fmt::format("{}: link '{}': <contact><{}> needs a value >= 0", where, link, tag));
    }
    return value = parsed;
  };
  for (const TiXmlElement* link = robot->FirstChildElement("link"); link;
       link = link->NextSiblingElement("link")) {
    const char* name = link->Attribute("name");
    const TiXmlElement* contact = link->FirstChildElement("contact");
    if (!name || !contact) continue;
    contacts[name] = {value_of(contact, "lateral_friction", name),
                      value_of(contact, "restitution", name)};
  }
  return contacts;
}

class UrdfReader {
 public:
  UrdfReader(const std::filesystem::path& path, const UrdfOptions& options)
      : path_(path), options_(options), where_(fmt::format("URDF '{}'", path.string())) {}

  std::vector<UrdfBody> read() {
    std::ifstream file(path_, std::ios::binary);
    if (!file) throw FileError(fmt::format("{}: cannot be opened", where_));
    std::stringstream text;
    text << file.rdbuf();
    const std::string xml = text.str();
    const urdf::ModelInterfaceSharedPtr model = parse_urdf(xml, where_);
    contacts_ = read_contacts(xml, where_);
    std::vector<UrdfBody> bodies;
    add_group(*model->getRoot(), to_transform(options_.base_pose), bodies);
    return bodies;
  }

 private:
  // A link placed in the frame of its group's root link.
  struct PlacedLink {
    const urdf::Link* link;
    Transform in_group;
  };

  // The group rooted at `root` (whose frame lies at `root_in_world`), then the groups beyond its
  // floating joints.
  void add_group(const urdf::Link& root, const Transform& root_in_world,
                 std::vector<UrdfBody>& bodies) {
    std::vector<PlacedLink> links;
    std::vector<std::pair<const urdf::Link*, Transform>> floating_children;
    collect(root, Transform::Identity(), root_in_world, links, floating_children);
    bodies.push_back(make_group_body(links, root_in_world));
    for (const auto& [child, child_in_world] : floating_children) {
      add_group(*child, child_in_world, bodies);
    }
  }

  void collect(const urdf::Link& link, const Transform& in_group, const Transform& group_in_world,
               std::vector<PlacedLink>& links,
               std::vector<std::pair<const urdf::Link*, Transform>>& floating_children) {
    links.push_back({&link, in_group});
    for (size_t i = 0; i < link.child_joints.size(); ++i) {
      const urdf::Joint& joint = *link.child_joints[i];
      const urdf::Link& child = *link.child_links[i];
      const Transform child_in_group =
          in_group * to_transform(joint.parent_to_joint_origin_transform);
      if (joint.type == urdf::Joint::FIXED) {
        collect(child, child_in_group, group_in_world, links, floating_children);
      } else if (joint.type == urdf::Joint::FLOATING) {
        floating_children.emplace_back(&child, group_in_world * child_in_group);
      } else {
        throw ConfigError(fmt::format(
            "{}: joint '{}' is {}; FIGNet simulates free rigid bodies, so only fixed joints "
            "(merged into one body) and floating joints (separate bodies) are supported",
            where_, joint.name, joint_type_name(joint.type)));
      }
    }
  }

  static const char* joint_type_name(int type) {
    switch (type) {
      case urdf::Joint::REVOLUTE:
        return "revolute";
      case urdf::Joint::CONTINUOUS:
        return "continuous";
      case urdf::Joint::PRISMATIC:
        return "prismatic";
      case urdf::Joint::PLANAR:
        return "planar";
      default:
        return "of unknown type";
    }
  }

  UrdfBody make_group_body(const std::vector<PlacedLink>& links, const Transform& group_in_world) {
    UrdfBody result;
    result.name = links.front().link->name;
    MeshAssembler assembler;
    std::vector<Points> parts;
    for (const PlacedLink& placed : links) {
      result.links.push_back(placed.link->name);
      for (const auto& collision : placed.link->collision_array) {
        if (!collision || !collision->geometry) continue;
        const std::string link_where = fmt::format("{}, link '{}'", where_, placed.link->name);
        std::vector<Points> piece_parts;
        bool imported = false;
        const TriangleMesh piece =
            geometry_mesh(*collision->geometry, link_where, piece_parts, imported);
        const Transform in_group = placed.in_group * to_transform(collision->origin);
        assembler.append(piece, in_group);
        if (!imported) piece_parts = decompose_into_convex_parts(piece);
        if (piece_parts.empty()) piece_parts.push_back(piece.vertices());
        for (const Points& part : piece_parts) parts.push_back(transformed(part, in_group));
      }
    }
    if (assembler.empty()) {
      throw ConfigError(fmt::format(
          "{}, link '{}': no collision geometry, so nothing for the body to collide with", where_,
          result.name));
    }
    const TriangleMesh mesh = assembler.finish(result.name);
    const Contact contact = contacts_.count(result.name) ? contacts_.at(result.name) : Contact{};
    const double friction = contact.friction.value_or(options_.default_friction);
    const double restitution = contact.restitution.value_or(options_.default_restitution);
    const std::optional<BodyInertia> inertia = combined_inertia(links);
    const bool is_static = inertia && inertia->mass == 0.0;
    if (inertia && !is_static) {
      result.body = make_body(mesh, *inertia, friction, restitution, parts);
    } else {
      // No <inertial> anywhere: the geometry at the default density. Static bodies take the
      // geometry's frame too.
      const double density = is_static ? 1.0 : options_.default_density;
      result.body = make_body(mesh, density, friction, restitution, parts);
    }
    if (is_static) {
      result.body.kinematic = true;
      result.body.properties.mass = 0.0;
    }
    result.body.pose = to_pose(group_in_world * to_transform(result.body.pose));
    return result;
  }

  // The <inertial> data of the links combined in the group's frame (parallel-axis theorem);
  // none when no link has any.
  std::optional<BodyInertia> combined_inertia(const std::vector<PlacedLink>& links) const {
    struct PointInertia {
      double mass;
      Vec3 center;
      Eigen::Matrix3d inertia;  // about `center`, group axes
    };
    std::vector<PointInertia> pieces;
    for (const PlacedLink& placed : links) {
      const urdf::Inertial* inertial = placed.link->inertial.get();
      if (!inertial) continue;
      Eigen::Matrix3d local;
      local << inertial->ixx, inertial->ixy, inertial->ixz, inertial->ixy, inertial->iyy,
          inertial->iyz, inertial->ixz, inertial->iyz, inertial->izz;
      const bool finite = std::isfinite(inertial->mass) && local.allFinite();
      const double smallest =
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(local).eigenvalues().minCoeff();
      if (!finite || inertial->mass < 0.0 || smallest < -1e-9 * std::max(1.0, local.norm())) {
        throw ConfigError(fmt::format(
            "{}, link '{}': <inertial> needs a mass >= 0 and a positive semi-definite inertia",
            where_, placed.link->name));
      }
      const Transform frame = placed.in_group * to_transform(inertial->origin);
      pieces.push_back({inertial->mass, frame.translation(),
                        frame.rotation() * local * frame.rotation().transpose()});
    }
    if (pieces.empty()) return std::nullopt;
    BodyInertia total;
    for (const PointInertia& p : pieces) {
      total.mass += p.mass;
      total.center_of_mass += p.mass * p.center;
    }
    if (total.mass == 0.0) return total;
    total.center_of_mass /= total.mass;
    for (const PointInertia& p : pieces) {
      const Vec3 d = p.center - total.center_of_mass;
      total.inertia +=
          p.inertia + p.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
    }
    return total;
  }

  // The mesh of a collision element; a <mesh> file is imported (cleaned, repaired, simplified) and
  // its convex parts for Bullet come back in `parts` (`imported` set; empty parts: its hull).
  TriangleMesh geometry_mesh(const urdf::Geometry& geometry, const std::string& where,
                             std::vector<Points>& parts, bool& imported) const {
    const auto positive = [&](double value, const char* what) {
      if (!(value > 0.0) || !std::isfinite(value)) {
        throw ConfigError(fmt::format("{}: {} {} (must be > 0)", where, what, value));
      }
      return value;
    };
    switch (geometry.type) {
      case urdf::Geometry::SPHERE: {
        const auto& sphere = static_cast<const urdf::Sphere&>(geometry);
        return make_sphere(positive(sphere.radius, "sphere radius"));
      }
      case urdf::Geometry::BOX: {
        const auto& box = static_cast<const urdf::Box&>(geometry);
        return make_box(0.5 * Vec3(positive(box.dim.x, "box size x"),
                                   positive(box.dim.y, "box size y"),
                                   positive(box.dim.z, "box size z")));
      }
      case urdf::Geometry::CYLINDER: {
        const auto& cylinder = static_cast<const urdf::Cylinder&>(geometry);
        return make_cylinder(positive(cylinder.radius, "cylinder radius"),
                             0.5 * positive(cylinder.length, "cylinder length"));
      }
      case urdf::Geometry::MESH: {
        const auto& file = static_cast<const urdf::Mesh&>(geometry);
        const Vec3 scale(positive(file.scale.x, "mesh scale x"),
                         positive(file.scale.y, "mesh scale y"),
                         positive(file.scale.z, "mesh scale z"));
        TriangleMesh loaded = load_mesh_in_context(resolve(file.filename, where), where);
        try {
          ImportedMesh mesh = import_mesh(
              TriangleMesh(loaded.name(), loaded.vertices() * scale.asDiagonal(), loaded.faces()),
              options_.mesh);
          parts = std::move(mesh.convex_parts);
          imported = true;
          return mesh.surface;
        } catch (const MeshError& e) {
          throw MeshError(fmt::format("{}: {}", where, e.what()));
        }
      }
    }
    throw ConfigError(fmt::format("{}: unknown collision geometry", where));
  }

  static TriangleMesh load_mesh_in_context(const std::filesystem::path& path,
                                           const std::string& where) {
    try {
      return load_mesh_file(path);
    } catch (const FileError& e) {
      throw FileError(fmt::format("{}: {}", where, e.what()));
    } catch (const MeshError& e) {
      throw MeshError(fmt::format("{}: {}", where, e.what()));
    }
  }

  // A mesh URI as a path: relative to the URDF file, file://, or package://NAME/….
  std::filesystem::path resolve(const std::string& uri, const std::string& where) const {
    const std::filesystem::path folder = path_.parent_path();
    if (uri.starts_with("file://")) return uri.substr(7);
    if (!uri.starts_with("package://")) return folder / uri;
    const std::string rest = uri.substr(10);
    const std::string package = rest.substr(0, rest.find('/'));
    const std::string inside =
        rest.find('/') == std::string::npos ? "" : rest.substr(rest.find('/') + 1);
    if (options_.packages.count(package)) return options_.packages.at(package) / inside;
    for (std::filesystem::path dir = std::filesystem::absolute(folder); !dir.empty();
         dir = dir.parent_path()) {
      if (dir.filename() == package) return dir / inside;
      if (dir == dir.parent_path()) break;
    }
    throw FileError(fmt::format(
        "{}: mesh '{}': package '{}' is neither in UrdfOptions::packages nor a folder above the "
        "file",
        where, uri, package));
  }

  std::filesystem::path path_;
  const UrdfOptions& options_;
  std::string where_;
  std::map<std::string, Contact> contacts_;
};

}  // namespace

std::vector<UrdfBody> load_urdf(const std::filesystem::path& path, const UrdfOptions& options) {
  return UrdfReader(path, options).read();
}

}  // namespace fignet::bullet
