#include "fignet/train/training_config.h"

#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <functional>
#include <map>
#include <nlohmann/json.hpp>

#include "fignet/error.h"

namespace fignet {

namespace {

using json = nlohmann::json;

// One named field: how to read it out and how to set it from JSON.
struct Field {
  std::function<json(const TrainingConfig&)> get;
  std::function<void(TrainingConfig&, const json&)> set;
};

template <class T, class Member>
Field plain(Member member) {
  return {[member](const TrainingConfig& c) {
            const T value = member(const_cast<TrainingConfig&>(c));
            // Floats print as their shortest decimal (0.001, not 0.0010000000474974513).
            if constexpr (std::is_same_v<T, float>) return json::parse(fmt::format("{}", value));
            return json(value);
          },
          [member](TrainingConfig& c, const json& v) { member(c) = v.get<T>(); }};
}

template <class Enum>
Field named_enum(Enum& (*member)(TrainingConfig&),
                 std::vector<std::pair<Enum, std::string>> names) {
  return {[=](const TrainingConfig& c) {
            for (const auto& [value, name] : names)
              if (member(const_cast<TrainingConfig&>(c)) == value) return json(name);
            return json();
          },
          [=](TrainingConfig& c, const json& v) {
            const std::string text = v.get<std::string>();
            std::vector<std::string> known;
            for (const auto& [value, name] : names) {
              if (name == text) {
                member(c) = value;
                return;
              }
              known.push_back(name);
            }
            throw ConfigError(fmt::format("'{}' is not one of {}", text, fmt::join(known, ", ")));
          }};
}

const std::vector<std::pair<std::string, Field>>& fields() {
  static const std::vector<std::pair<std::string, Field>> table = {
      {"preset", plain<std::string>([](TrainingConfig & c) -> auto& { return c.model.preset; })},
      {"latent_size", plain<int>([](TrainingConfig & c) -> auto& { return c.model.latent_size; })},
      {"message_passing_steps",
       plain<int>([](TrainingConfig & c) -> auto& { return c.model.message_passing_steps; })},
      {"hidden_size", plain<int>([](TrainingConfig & c) -> auto& { return c.model.hidden_size; })},
      {"object_hidden_size",
       plain<int>([](TrainingConfig & c) -> auto& { return c.model.object_hidden_size; })},
      {"collision_radius",
       plain<double>([](TrainingConfig & c) -> auto& { return c.model.graph.collision_radius; })},
      {"history", plain<int>([](TrainingConfig & c) -> auto& { return c.model.graph.history; })},
      {"object_nodes",
       plain<bool>([](TrainingConfig & c) -> auto& { return c.model.graph.object_nodes; })},
      {"collisions",
       named_enum<CollisionEdges>(
           [](TrainingConfig & c) -> auto& { return c.model.graph.collisions; },
           {{CollisionEdges::kFaceFace, "face"}, {CollisionEdges::kNodeNode, "node"}})},
      {"floor",
       named_enum<FloorModel>([](TrainingConfig & c) -> auto& { return c.model.graph.floor; },
                              {{FloorModel::kMesh, "mesh"},
                               {FloorModel::kImplicit, "implicit"},
                               {FloorModel::kNone, "none"}})},
      {"floor_segments",
       plain<int>([](TrainingConfig & c) -> auto& { return c.model.graph.floor_segments; })},
      {"floor_half_extent",
       plain<double>([](TrainingConfig & c) -> auto& { return c.model.graph.floor_half_extent; })},
      {"mesh_edges",
       plain<bool>([](TrainingConfig & c) -> auto& { return c.model.graph.mesh_edges; })},
      {"static_internal_edges", plain<bool>([](TrainingConfig & c) -> auto& {
         return c.model.graph.static_internal_edges;
       })},
      {"log_mass", plain<bool>([](TrainingConfig & c) -> auto& { return c.model.graph.log_mass; })},
      {"face_span_limit",
       plain<double>([](TrainingConfig & c) -> auto& { return c.model.graph.face_span_limit; })},
      {"velocity_log_scale",
       plain<double>([](TrainingConfig & c) -> auto& { return c.model.graph.velocity_log_scale; })},
      {"distance_log_scale",
       plain<double>([](TrainingConfig & c) -> auto& { return c.model.graph.distance_log_scale; })},
      {"contact_motion",
       plain<bool>([](TrainingConfig & c) -> auto& { return c.model.graph.contact_motion; })},
      {"contact_motion_dead_zone", plain<double>([](TrainingConfig & c) -> auto& {
         return c.model.graph.contact_motion_dead_zone;
       })},
      {"omit_free_flight",
       plain<bool>([](TrainingConfig & c) -> auto& { return c.model.graph.omit_free_flight; })},
      {"noise_std", plain<double>([](TrainingConfig & c) -> auto& { return c.model.noise_std; })},
      {"noise",
       named_enum<NoiseKind>([](TrainingConfig & c) -> auto& { return c.model.noise; },
                             {{NoiseKind::kVertex, "vertex"}, {NoiseKind::kRigid, "rigid"}})},
      {"noise_correction",
       plain<double>([](TrainingConfig & c) -> auto& { return c.model.noise_correction; })},
      {"random_yaw", plain<bool>([](TrainingConfig & c) -> auto& { return c.model.random_yaw; })},
      {"normalizer_max_accumulations", plain<std::int64_t>([](TrainingConfig & c) -> auto& {
         return c.model.normalizer_max_accumulations;
       })},
      {"model_seed",
       plain<std::uint64_t>([](TrainingConfig & c) -> auto& { return c.model.seed; })},
      // The trainer's fields from here on (is_model_field).
      {"batch_size", plain<int>([](TrainingConfig & c) -> auto& { return c.trainer.batch_size; })},
      {"learning_rate_start", plain<float>([](TrainingConfig & c) -> auto& {
         return c.trainer.adam.learning_rate_start;
       })},
      {"learning_rate_end",
       plain<float>([](TrainingConfig & c) -> auto& { return c.trainer.adam.learning_rate_end; })},
      {"decay_steps",
       plain<std::int64_t>([](TrainingConfig & c) -> auto& { return c.trainer.adam.decay_steps; })},
      {"decay_start_step", plain<std::int64_t>([](TrainingConfig & c) -> auto& {
         return c.trainer.adam.decay_start_step;
       })},
      {"gradient_clip",
       plain<float>([](TrainingConfig & c) -> auto& { return c.trainer.gradient_clip; })},
      {"huber_delta",
       plain<float>([](TrainingConfig & c) -> auto& { return c.trainer.huber_delta; })},
      {"rest_loss_weight",
       plain<float>([](TrainingConfig & c) -> auto& { return c.trainer.rest_loss_weight; })},
      {"impact_loss_weight",
       plain<float>([](TrainingConfig & c) -> auto& { return c.trainer.impact_loss_weight; })},
      {"still_air_fraction",
       plain<float>([](TrainingConfig & c) -> auto& { return c.trainer.still_air_fraction; })},
      {"weight_average",
       plain<float>([](TrainingConfig & c) -> auto& { return c.trainer.weight_average; })},
      {"pushforward_fraction",
       plain<float>([](TrainingConfig & c) -> auto& { return c.trainer.pushforward_fraction; })},
      {"pushforward_skips_rest",
       plain<bool>([](TrainingConfig & c) -> auto& { return c.trainer.pushforward_skips_rest; })},
      {"pushforward_steps",
       plain<int>([](TrainingConfig & c) -> auto& { return c.trainer.pushforward_steps; })},
      {"heading_consistency",
       plain<float>([](TrainingConfig & c) -> auto& { return c.trainer.heading_consistency; })},
      {"statistics_warmup",
       plain<int>([](TrainingConfig & c) -> auto& { return c.trainer.statistics_warmup; })},
      {"data_seed",
       plain<std::uint64_t>([](TrainingConfig & c) -> auto& { return c.trainer.seed; })},
      {"steps", plain<std::int64_t>([](TrainingConfig & c) -> auto& { return c.steps; })},
  };
  return table;
}

const Field* find_field(std::string_view name) {
  for (const auto& [key, field] : fields())
    if (key == name) return &field;
  return nullptr;
}

void set_field(TrainingConfig& config, const std::string& key, const json& value,
               const std::string& where) {
  const Field* field = find_field(key);
  if (!field) {
    throw ConfigError(fmt::format("{}: unknown config field '{}'; known fields: {}", where, key,
                                  fmt::join(TrainingConfig::field_names(), ", ")));
  }
  try {
    field->set(config, value);
    if (key == "decay_steps") config.decay_steps_given = true;
  } catch (const json::exception&) {
    throw ConfigError(fmt::format("{}: '{}' = {} has the wrong type", where, key, value.dump()));
  } catch (const ConfigError& e) {
    throw ConfigError(fmt::format("{}: '{}': {}", where, key, e.what()));
  }
}

}  // namespace

TrainingConfig TrainingConfig::preset_named(std::string_view name) {
  TrainingConfig config;
  config.model = ModelConfig::preset_named(name);
  // The recipe of docs/training-study.md. The structs' own defaults stay the first recipe's,
  // which is what files written before a field existed were trained with.
  // Frozen after the warm-up's 800 batches of 8 scenes (6,400 scenes, as 50 batches of 128).
  config.model.normalizer_max_accumulations = 800;
  config.model.graph.static_internal_edges = false;  // the floor's 80 m edges skew the scales
  config.model.graph.log_mass = true;
  config.model.noise = NoiseKind::kRigid;
  // Slow sliding readable (0.1 mm per frame ~ 1): 0.98-1.00 m against 1.11-1.15 m on validation,
  // two seeds at 213k samples, and 30-40 % of Coulomb friction below 0.3 m/s instead of ~0.
  config.model.graph.velocity_log_scale = 1e-4;
  // At a fixed sample budget more, smaller steps won: batch 8 beat 32 and 128 at 213k samples
  // (docs/training-study.md). A GPU wants 128 (the paper's) to be fast: --set batch_size=128.
  config.trainer.batch_size = 8;
  config.trainer.gradient_clip = 1.0f;
  config.trainer.huber_delta = 3.0f;
  config.trainer.statistics_warmup = 800;
  // The parameters' moving average is the model: 1.19 and 1.17 m against its runs' own last
  // parameters' 1.60 and 1.53 on the test split, two seeds at 213k samples.
  config.trainer.weight_average = 0.999f;
  // Resting bodies weighed 100x, and a tenth of the samples still in the air 1.5 cm-2 m up and let
  // go: on two seeds a cube at rest moves < 1 cm over 500 steps (2 turns) and a body let go in the
  // air falls, where the rest weight alone made it hover; the rollouts pay ~20 %
  // (docs/training-study.md, LG1 and LG2).
  config.trainer.rest_loss_weight = 100.0f;
  config.trainer.still_air_fraction = 0.1f;
  // Half the paper's peak rate: at width 64 ahead of 1e-3 at 31 of 32 equal-sample validations
  // to 852k samples (by 17-32 % at 106k-240k) and 5.5 % better on the test split; at width 128
  // by 15 % at 53k (docs/training-study.md, half the peak learning rate).
  config.trainer.adam.learning_rate_start = 5e-4f;
  config.trainer.adam.learning_rate_end = 5e-5f;
  config.trainer.adam.decay_steps = config.steps;
  // Half the steps trained on the network's own one-step prediction: ahead of the same run
  // without it at all 32 equal-sample validations to 852k samples, and 16 % better on the test
  // split at the schedule's end (0.633 against 0.756 m); its network alone holds tall stacks less
  // well (docs/training-study.md, the pushforward trick; models/movi-a-small.md).
  config.trainer.pushforward_fraction = 0.5f;
  return config;
}

const std::vector<std::string>& TrainingConfig::field_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& [key, field] : fields()) out.push_back(key);
    return out;
  }();
  return names;
}

bool TrainingConfig::is_model_field(std::string_view name) {
  for (const auto& [key, field] : fields()) {
    if (key == "batch_size") return false;
    if (key == name) return true;
  }
  return false;
}

bool TrainingConfig::changes_on_resume(std::string_view name) {
  return !is_model_field(name) || name == "noise_std" || name == "noise" ||
         name == "noise_correction" || name == "random_yaw";
}

std::vector<std::string> TrainingConfig::differing_fields(const TrainingConfig& other) const {
  std::vector<std::string> names;
  for (const auto& [key, field] : fields()) {
    if (field.get(*this) != field.get(other)) names.push_back(key);
  }
  return names;
}

std::string TrainingConfig::field_text(std::string_view name) const {
  const Field* field = find_field(name);
  if (!field) throw ConfigError(fmt::format("unknown config field '{}'", name));
  return field->get(*this).dump();
}

std::string TrainingConfig::to_json() const {
  json out = json::object();
  for (const auto& [key, field] : fields()) out[key] = field.get(*this);
  // Keep the documented field order rather than nlohmann's sorted keys.
  std::string text = "{\n";
  for (size_t i = 0; i < fields().size(); ++i) {
    const auto& key = fields()[i].first;
    text +=
        fmt::format("  \"{}\": {}{}\n", key, out[key].dump(), i + 1 < fields().size() ? "," : "");
  }
  return text + "}";
}

void TrainingConfig::apply_json(std::string_view text, const std::string& where) {
  json parsed;
  try {
    parsed = json::parse(text);
  } catch (const json::parse_error& e) {
    throw ConfigError(fmt::format("{}: not valid JSON ({})", where, e.what()));
  }
  if (!parsed.is_object()) throw ConfigError(fmt::format("{}: expected a JSON object", where));
  // The preset first, so the other fields override its values.
  if (parsed.contains("preset")) {
    const std::string preset =
        parsed["preset"].is_string() ? parsed["preset"].get<std::string>() : "";
    const TrainingConfig base = preset_named(preset);
    model = base.model;
  }
  for (const auto& [key, value] : parsed.items()) set_field(*this, key, value, where);
}

void TrainingConfig::apply_setting(std::string_view setting) {
  const auto equals = setting.find('=');
  const std::string where = fmt::format("--set '{}'", setting);
  if (equals == std::string_view::npos || equals == 0) {
    throw ConfigError(fmt::format("{}: expected key=value", where));
  }
  const std::string key(setting.substr(0, equals));
  const std::string text(setting.substr(equals + 1));
  json value = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (value.is_discarded()) value = text;  // a bare word such as floor=implicit
  if (key == "preset") {
    apply_json(json{{"preset", value}}.dump(), where);  // a preset resets the model's fields
  } else {
    set_field(*this, key, value, where);
  }
}

void TrainingConfig::validate() const {
  model.validate();
  if (trainer.batch_size < 1 || trainer.batch_size > 4096) {
    throw ConfigError(fmt::format("batch_size = {} (must be in 1..4096)", trainer.batch_size));
  }
  const AdamConfig& adam = trainer.adam;
  for (const auto& [name, rate] : {std::pair("learning_rate_start", adam.learning_rate_start),
                                   std::pair("learning_rate_end", adam.learning_rate_end)}) {
    if (!(rate > 0) || !std::isfinite(rate)) {
      throw ConfigError(fmt::format("{} = {} (must be > 0)", name, rate));
    }
  }
  if (adam.decay_steps < 1) {
    throw ConfigError(fmt::format("decay_steps = {} (must be >= 1)", adam.decay_steps));
  }
  if (adam.decay_start_step < 0) {
    throw ConfigError(fmt::format("decay_start_step = {} (must be >= 0)", adam.decay_start_step));
  }
  if (steps < 0) throw ConfigError(fmt::format("steps = {} (must be >= 0)", steps));
  for (const auto& [name, value] : {std::pair("gradient_clip", trainer.gradient_clip),
                                    std::pair("huber_delta", trainer.huber_delta)}) {
    if (!(value >= 0.0f) || !std::isfinite(value)) {
      throw ConfigError(fmt::format("{} = {} (must be >= 0; 0 turns it off)", name, value));
    }
  }
  if (!(trainer.rest_loss_weight >= 0.0f) || !std::isfinite(trainer.rest_loss_weight)) {
    throw ConfigError(
        fmt::format("rest_loss_weight = {} (must be >= 0; 1: resting bodies count like the others)",
                    trainer.rest_loss_weight));
  }
  if (!(trainer.impact_loss_weight >= 0.0f) || !std::isfinite(trainer.impact_loss_weight)) {
    throw ConfigError(fmt::format(
        "impact_loss_weight = {} (must be >= 0; 1: bodies in an impact count like the others)",
        trainer.impact_loss_weight));
  }
  if (!(trainer.still_air_fraction >= 0.0f && trainer.still_air_fraction <= 1.0f)) {
    throw ConfigError(fmt::format(
        "still_air_fraction = {} (must be in [0, 1]: the share of samples whose bodies are held "
        "still in the air and let go; 0: none)",
        trainer.still_air_fraction));
  }
  if (!(trainer.pushforward_fraction >= 0.0f && trainer.pushforward_fraction <= 1.0f)) {
    throw ConfigError(fmt::format(
        "pushforward_fraction = {} (must be in [0, 1]: the share of steps that train on the "
        "network's own one-step prediction; 0: none)",
        trainer.pushforward_fraction));
  }
  if (trainer.pushforward_steps < 1 || trainer.pushforward_steps > kMaxPushforwardSteps) {
    throw ConfigError(fmt::format(
        "pushforward_steps = {} (must be in 1..{}: the network's steps from the frame a pushed "
        "scene is drawn at to its own)",
        trainer.pushforward_steps, kMaxPushforwardSteps));
  }
  if (!(trainer.heading_consistency >= 0.0f) || !std::isfinite(trainer.heading_consistency)) {
    throw ConfigError(fmt::format(
        "heading_consistency = {} (must be >= 0: the loss weight of the difference between a "
        "prediction and the prediction for the scene turned about the vertical; 0: none)",
        trainer.heading_consistency));
  }
  if (!(trainer.weight_average >= 0.0f && trainer.weight_average < 1.0f)) {
    throw ConfigError(fmt::format(
        "weight_average = {} (must be in [0, 1): the decay of the parameters' moving average; "
        "0: none, 0.999: ~1000 steps)",
        trainer.weight_average));
  }
  if (trainer.statistics_warmup < 0 || trainer.statistics_warmup > 1'000'000) {
    throw ConfigError(fmt::format("statistics_warmup = {} (must be in 0..1000000 batches)",
                                  trainer.statistics_warmup));
  }
}

}  // namespace fignet
