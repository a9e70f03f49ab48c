#include "fignet/graph/config.h"

#include <fmt/format.h>

#include <cmath>

#include "fignet/error.h"

namespace fignet {

void GraphConfig::validate() const {
  auto fail = [](const char* field, auto value, const char* rule) {
    throw ConfigError(fmt::format("graph config: {} = {} ({})", field, value, rule));
  };
  if (!(collision_radius > 0.0) || !std::isfinite(collision_radius)) {
    fail("collision_radius", collision_radius, "must be a positive finite distance in metres");
  }
  if (history < 1 || history > 16) fail("history", history, "must be in 1..16");
  if (!(floor_half_extent > 0.0) || !std::isfinite(floor_half_extent)) {
    fail("floor_half_extent", floor_half_extent, "must be positive and finite");
  }
  if (floor_segments < 1 || floor_segments > 1024) {
    fail("floor_segments", floor_segments, "must be in 1..1024");
  }
  if (!(velocity_log_scale >= 0.0) || !std::isfinite(velocity_log_scale)) {
    fail("velocity_log_scale", velocity_log_scale, "must be >= 0 metres per frame (0: off)");
  }
  if (!(distance_log_scale >= 0.0) || !std::isfinite(distance_log_scale)) {
    fail("distance_log_scale", distance_log_scale, "must be >= 0 metres (0: off)");
  }
  if (!(contact_motion_dead_zone >= 0.0) || !std::isfinite(contact_motion_dead_zone)) {
    fail("contact_motion_dead_zone", contact_motion_dead_zone,
         "must be >= 0 metres per frame (0: off)");
  }
  if (contact_motion_dead_zone > 0.0 && !contact_motion) {
    fail("contact_motion_dead_zone", contact_motion_dead_zone,
         "shapes the contact motion's columns: needs contact_motion");
  }
  if (!(face_span_limit >= 0.0) || !std::isfinite(face_span_limit)) {
    fail("face_span_limit", face_span_limit, "must be >= 0 metres (0: no limit)");
  }
  if (!mesh_edges && !object_nodes) {
    fail("mesh_edges", "false", "needs object_nodes: without both, nothing couples a body's nodes");
  }
}

FeatureSizes feature_sizes(const GraphConfig& config) {
  const int log_velocities = config.velocity_log_scale > 0.0 ? 3 * config.history : 0;
  const int dynamic_part = 4 * config.history + log_velocities + 3 + 1 + 4;
  return {
      .mesh_node = dynamic_part + (config.floor == FloorModel::kImplicit ? 2 : 0),
      .object_node = dynamic_part,
      .mesh_edge = 8,
      .world_edge = 4,
      .face_edge = 34 + (config.distance_log_scale > 0.0 ? 1 : 0) + (config.contact_motion ? 5 : 0),
  };
}

}  // namespace fignet
