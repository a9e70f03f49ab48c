#include "fignet/io/model_file.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "fignet/error.h"
#include "hdf5_util.h"
#include "model_contents.h"

namespace fignet {

namespace {

constexpr const char* kFormat = "fignet-model";
constexpr const char* kWhat = "model file";

// Normalisers by stable name: "mesh_node", "object_node", "face_edge", "target", "edge_<kind>".
// `N` is Normalizers or const Normalizers: saving reads them, loading fills them.
template <class N>
auto named(N& n, const Network& network) {
  using Pointer = decltype(&n.mesh_node);
  std::vector<std::pair<std::string, Pointer>> result = {{"mesh_node", &n.mesh_node},
                                                         {"object_node", &n.object_node},
                                                         {"face_edge", &n.face_edge},
                                                         {"target", &n.target}};
  for (size_t t = 0; t < network.edge_kinds().size(); ++t) {
    result.emplace_back(std::string("edge_") + edge_kind_name(network.edge_kinds()[t]),
                        &n.edges[t]);
  }
  return result;
}

void write_config(H5::Group group, const ModelConfig& c) {
  using hdf5::write_attribute;
  write_attribute(group, "preset", c.preset);
  write_attribute(group, "latent_size", static_cast<long long>(c.latent_size));
  write_attribute(group, "message_passing_steps", static_cast<long long>(c.message_passing_steps));
  write_attribute(group, "hidden_size", static_cast<long long>(c.hidden_size));
  write_attribute(group, "object_hidden_size", static_cast<long long>(c.object_hidden_size));
  write_attribute(group, "noise_std", c.noise_std);
  write_attribute(group, "normalizer_max_accumulations",
                  static_cast<long long>(c.normalizer_max_accumulations));
  write_attribute(group, "time_step", c.time_step);
  for (int i = 0; i < 3; ++i)
    write_attribute(group, fmt::format("gravity_{}", "xyz"[i]), c.gravity[i]);
  write_attribute(group, "seed", static_cast<long long>(c.seed));
  write_attribute(group, "mesh_vertices", static_cast<long long>(c.mesh_vertices));
  write_attribute(group, "min_mass", c.min_mass);
  write_attribute(group, "max_mass", c.max_mass);
  // The training data's materials as min_NAME and max_NAME, absent when unknown.
  for (const auto& [name, range] : c.material_ranges()) {
    if (!range->known()) continue;
    write_attribute(group, fmt::format("min_{}", name), range->lowest);
    write_attribute(group, fmt::format("max_{}", name), range->highest);
  }
  write_attribute(group, "collision_radius", c.graph.collision_radius);
  write_attribute(group, "history", static_cast<long long>(c.graph.history));
  write_attribute(group, "object_nodes", static_cast<long long>(c.graph.object_nodes));
  write_attribute(group, "collisions",
                  std::string(c.graph.collisions == CollisionEdges::kFaceFace ? "face" : "node"));
  const char* floors[] = {"mesh", "implicit", "none"};
  write_attribute(group, "floor", std::string(floors[static_cast<int>(c.graph.floor)]));
  write_attribute(group, "floor_half_extent", c.graph.floor_half_extent);
  write_attribute(group, "floor_segments", static_cast<long long>(c.graph.floor_segments));
  write_attribute(group, "mesh_edges", static_cast<long long>(c.graph.mesh_edges));
  write_attribute(group, "static_internal_edges",
                  static_cast<long long>(c.graph.static_internal_edges));
  write_attribute(group, "log_mass", static_cast<long long>(c.graph.log_mass));
  write_attribute(group, "face_span_limit", c.graph.face_span_limit);
  write_attribute(group, "velocity_log_scale", c.graph.velocity_log_scale);
  write_attribute(group, "distance_log_scale", c.graph.distance_log_scale);
  write_attribute(group, "contact_motion", static_cast<long long>(c.graph.contact_motion));
  write_attribute(group, "contact_motion_dead_zone", c.graph.contact_motion_dead_zone);
  write_attribute(group, "omit_free_flight", static_cast<long long>(c.graph.omit_free_flight));
  write_attribute(group, "noise", std::string(c.noise == NoiseKind::kRigid ? "rigid" : "vertex"));
  write_attribute(group, "noise_correction", c.noise_correction);
  write_attribute(group, "random_yaw", static_cast<long long>(c.random_yaw));
}

ModelConfig read_config(const H5::Group& group) {
  using namespace hdf5;
  ModelConfig c;
  c.preset = read_string(group, "preset");
  c.latent_size = static_cast<int>(read_integer(group, "latent_size"));
  c.message_passing_steps = static_cast<int>(read_integer(group, "message_passing_steps"));
  c.hidden_size = static_cast<int>(read_integer_or(group, "hidden_size", c.hidden_size));
  c.object_hidden_size =
      static_cast<int>(read_integer_or(group, "object_hidden_size", c.object_hidden_size));
  c.noise_std = read_double(group, "noise_std");
  c.normalizer_max_accumulations = read_integer(group, "normalizer_max_accumulations");
  c.time_step = read_double(group, "time_step");
  for (int i = 0; i < 3; ++i)
    c.gravity[i] = read_double(group, fmt::format("gravity_{}", "xyz"[i]));
  c.seed = static_cast<std::uint64_t>(read_integer(group, "seed"));
  c.mesh_vertices = static_cast<int>(read_integer_or(group, "mesh_vertices", c.mesh_vertices));
  if (group.attrExists("min_mass") && group.attrExists("max_mass")) {
    c.min_mass = read_double(group, "min_mass");
    c.max_mass = read_double(group, "max_mass");
  }
  for (const auto& [name, range] : c.material_ranges()) {
    const std::string low = fmt::format("min_{}", name), high = fmt::format("max_{}", name);
    if (group.attrExists(low) && group.attrExists(high)) {
      range->lowest = read_double(group, low);
      range->highest = read_double(group, high);
    }
  }
  c.graph.collision_radius = read_double(group, "collision_radius");
  c.graph.history = static_cast<int>(read_integer(group, "history"));
  c.graph.object_nodes = read_integer(group, "object_nodes") != 0;
  const std::string collisions = read_string(group, "collisions");
  if (collisions != "face" && collisions != "node") {
    throw ConfigError(fmt::format("config/collisions = '{}' (must be face or node)", collisions));
  }
  c.graph.collisions = collisions == "face" ? CollisionEdges::kFaceFace : CollisionEdges::kNodeNode;
  const std::string floor = read_string(group, "floor");
  if (floor == "mesh")
    c.graph.floor = FloorModel::kMesh;
  else if (floor == "implicit")
    c.graph.floor = FloorModel::kImplicit;
  else if (floor == "none")
    c.graph.floor = FloorModel::kNone;
  else
    throw ConfigError(fmt::format("config/floor = '{}' (must be mesh, implicit or none)", floor));
  c.graph.floor_half_extent = read_double(group, "floor_half_extent");
  c.graph.floor_segments = static_cast<int>(read_integer(group, "floor_segments"));
  // Added after the first model files: absent means what those files were made with.
  auto flag = [&](const char* name, bool absent) {
    return read_integer_or(group, name, absent ? 1 : 0) != 0;
  };
  c.graph.mesh_edges = flag("mesh_edges", true);
  c.graph.static_internal_edges = flag("static_internal_edges", true);
  c.graph.log_mass = flag("log_mass", false);
  c.graph.contact_motion = flag("contact_motion", false);
  c.graph.omit_free_flight = flag("omit_free_flight", false);
  c.graph.face_span_limit = read_double_or(group, "face_span_limit", c.graph.face_span_limit);
  c.graph.velocity_log_scale =
      read_double_or(group, "velocity_log_scale", c.graph.velocity_log_scale);
  c.graph.distance_log_scale =
      read_double_or(group, "distance_log_scale", c.graph.distance_log_scale);
  c.graph.contact_motion_dead_zone =
      read_double_or(group, "contact_motion_dead_zone", c.graph.contact_motion_dead_zone);
  if (group.attrExists("noise")) {
    const std::string noise = read_string(group, "noise");
    if (noise != "vertex" && noise != "rigid") {
      throw ConfigError(fmt::format("config/noise = '{}' (must be vertex or rigid)", noise));
    }
    c.noise = noise == "rigid" ? NoiseKind::kRigid : NoiseKind::kVertex;
  }
  c.noise_correction = read_double_or(group, "noise_correction", c.noise_correction);
  c.random_yaw = flag("random_yaw", false);
  c.validate();
  return c;
}

}  // namespace

void write_model_contents(H5::H5File& file, const Model& model) {
  H5::Group root = file.openGroup("/");
  hdf5::write_attribute(root, "format", std::string(kFormat));
  hdf5::write_attribute(root, "version", kModelFileVersion);
  write_config(hdf5::create_group(file, "config"), model.config());
  H5::Group parameters = hdf5::create_group(file, "parameters");
  for (const TensorInfo& t : model.network().layout().tensors()) {
    hdf5::write_floats(parameters, t.name, model.parameters().data() + t.offset,
                       {static_cast<hsize_t>(t.rows), static_cast<hsize_t>(t.cols)});
  }
  H5::Group normalizers = hdf5::create_group(file, "normalizers");
  for (const auto& [name, normalizer] : named(model.normalizers(), model.network())) {
    H5::Group group = hdf5::create_group(normalizers, name);
    hdf5::write_attribute(group, "accumulations",
                          static_cast<long long>(normalizer->accumulations()));
    hdf5::write_attribute(group, "count", normalizer->count());
    const hsize_t n = static_cast<hsize_t>(normalizer->size());
    hdf5::write_doubles(group, "sum", normalizer->sum().data(), {n});
    hdf5::write_doubles(group, "sum_squares", normalizer->sum_squares().data(), {n});
  }
}

void save_model(const Model& model, const std::filesystem::path& path) {
  hdf5::write_atomically(path, kWhat, [&](H5::H5File& file) { write_model_contents(file, model); });
}

Model load_model(const std::filesystem::path& path) {
  const H5::H5File file = hdf5::open_for_reading(path, kWhat);
  return read_model_contents(file, fmt::format("{} '{}'", kWhat, path.string()));
}

Model read_model_contents(const H5::H5File& file, const std::string& where) {
  std::string object = "/";  // what is being read, for error messages
  try {
    const H5::Group root = file.openGroup("/");
    if (!root.attrExists("format") || hdf5::read_string(root, "format") != kFormat) {
      throw FileError(
          fmt::format("{}: not a fignet model (no format = '{}' attribute)", where, kFormat));
    }
    const long long version = hdf5::read_integer(root, "version");
    if (version != kModelFileVersion) {
      throw FileError(fmt::format("{}: format version {} is not supported (this build reads {})",
                                  where, version, kModelFileVersion));
    }
    object = "config";
    ModelConfig config;
    try {
      config = read_config(file.openGroup("config"));
    } catch (const ConfigError& e) {
      throw FileError(fmt::format("{}: invalid config: {}", where, e.what()));
    }
    const Network network(config);
    std::vector<float> parameters(network.layout().size());
    const H5::Group group = file.openGroup("parameters");
    for (const TensorInfo& t : network.layout().tensors()) {
      object = "parameters/" + t.name;
      if (!hdf5::exists(group, t.name)) {
        throw FileError(fmt::format("{}: missing tensor '{}'", where, object));
      }
      const H5::DataSet dataset = group.openDataSet(t.name);
      const auto shape = hdf5::shape_of(dataset, where);
      if (shape != std::vector<hsize_t>{hsize_t(t.rows), hsize_t(t.cols)}) {
        throw FileError(fmt::format("{}: tensor '{}' has shape [{}], expected [{}, {}]", where,
                                    object, fmt::join(shape, ", "), t.rows, t.cols));
      }
      hdf5::read_floats(dataset, parameters.data() + t.offset);
    }
    Normalizers normalizers = network.make_normalizers();
    for (auto& [name, normalizer] : named(normalizers, network)) {
      object = "normalizers/" + name;
      if (!hdf5::exists(file.openGroup("/"), object)) {
        throw FileError(fmt::format("{}: missing normaliser '{}'", where, object));
      }
      const H5::Group g = file.openGroup(object);
      Eigen::VectorXd sum(normalizer->size()), squares(normalizer->size());
      for (auto [dataset_name, out] :
           {std::pair("sum", &sum), std::pair("sum_squares", &squares)}) {
        const H5::DataSet dataset = g.openDataSet(dataset_name);
        if (hdf5::shape_of(dataset, where) != std::vector<hsize_t>{hsize_t(normalizer->size())}) {
          throw FileError(fmt::format("{}: '{}/{}' does not have {} entries", where, object,
                                      dataset_name, normalizer->size()));
        }
        hdf5::read_doubles(dataset, out->data());
      }
      normalizer->set_state(hdf5::read_integer(g, "accumulations"), hdf5::read_double(g, "count"),
                            sum, squares);
    }
    return Model(config, std::move(parameters), std::move(normalizers));
  } catch (const H5::Exception& e) {
    throw FileError(fmt::format("{}: cannot read '{}' ({})", where, object, e.getDetailMsg()));
  }
}

}  // namespace fignet
