#include "training_log.h"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>

#include "fignet/error.h"
#include "fignet/nn/gemm.h"
#include "text_file.h"

namespace fignet::cli {

TrainingLog::TrainingLog(const std::filesystem::path& path, std::int64_t resume_step,
                         int resumed_batch_size, int batch_size)
    : batch_size_(batch_size), resume_step_(resume_step), resume_samples_(0) {
  std::string kept;
  if (resume_step > 0) {
    std::ifstream in(path);
    std::int64_t last_step = 0, last_samples = 0;
    int line_number = 0;
    for (std::string line; std::getline(in, line);) {
      ++line_number;
      // A line cut short by a killed run is not JSON: it is dropped with the lines after the
      // checkpoint.
      const auto record = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
      if (!record.is_object()) continue;
      auto whole_number = [&](const char* field) -> std::int64_t {
        if (!record.contains(field)) return 0;
        if (!record[field].is_number_integer()) {
          throw FileError(fmt::format("--log '{}', line {}: \"{}\" is {}, not a whole number",
                                      path.string(), line_number, field, record[field].dump()));
        }
        return record[field].get<std::int64_t>();
      };
      const std::int64_t step = whole_number("step");
      if (step > resume_step) continue;
      kept += line + '\n';
      if (record.contains("samples")) last_step = step, last_samples = whole_number("samples");
    }
    // The samples at the resume: the last line that counted them, and the checkpoint's batch
    // for the steps after it (all of them in logs from before the field).
    resume_samples_ = last_samples + (resume_step - last_step) * resumed_batch_size;
  }
  // The kept lines replace the log at once (a failure leaves the old one), then lines append.
  write_text_atomically(path, kept);
  out_.open(path, std::ios::app);
  if (!out_) throw FileError(fmt::format("--log '{}': cannot write", path.string()));
}

std::int64_t TrainingLog::samples_at(std::int64_t step) const {
  return resume_samples_ + (step - resume_step_) * batch_size_;
}

void TrainingLog::write_step(std::int64_t step, double loss, float learning_rate,
                             double steps_per_second, double gradient_norm, double heading_gap) {
  nlohmann::json line{{"step", step},
                      {"samples", samples_at(step)},
                      {"loss", loss},
                      {"learning_rate", learning_rate},
                      {"steps_per_second", steps_per_second},
                      {"gradient_norm", gradient_norm}};
  if (heading_gap >= 0.0) line["heading_gap"] = heading_gap;
  // Which steps ran on bf16 products (--bf16): their bits and speed differ from f32 ones.
  if (gemm_precision() == GemmPrecision::kBf16) line["products"] = "bf16";
  out_ << line.dump() << std::endl;
}

void TrainingLog::write_validation(std::int64_t step, const Evaluation& e,
                                   const OneStepTotals& one_step) {
  nlohmann::json line{{"step", step},
                      {"samples", samples_at(step)},
                      {"valid_translation_m", e.mean_translation},
                      {"valid_rotation_deg", e.mean_rotation},
                      {"valid_final_translation_m", e.final_translation},
                      {"valid_final_rotation_deg", e.final_rotation},
                      {"valid_travel_ratio", e.travel_ratio},
                      {"valid_impacts", one_step.impact_errors.samples},
                      {"valid_unseen_impacts", one_step.unseen_impacts}};
  // valid_one_step_m_free_flight, valid_one_step_sigma_moving_contact, …
  for (int r = 0; r < kRegimes; ++r) {
    std::string name(regime_name(static_cast<Regime>(r)));
    std::replace(name.begin(), name.end(), ' ', '_');
    line["valid_one_step_m_" + name] = mean_translation(one_step.regimes[r]);
    line["valid_one_step_sigma_" + name] = rms_sigmas(one_step.regimes[r]);
  }
  line["valid_one_step_m_impacts"] = mean_translation(one_step.impact_errors);
  line["valid_one_step_ahead_m_impacts"] = mean_ahead(one_step.impact_errors);
  // Every validation trajectory's own errors, in order: two runs on the same validation split
  // compare scene by scene (scripts/training-log.py --against), far more sharply than by means.
  nlohmann::json translations = nlohmann::json::array(), rotations = nlohmann::json::array();
  for (const RolloutErrors& t : e.per_trajectory) {
    translations.push_back(t.mean_translation);
    rotations.push_back(t.mean_rotation);
  }
  line["valid_per_trajectory_translation_m"] = std::move(translations);
  line["valid_per_trajectory_rotation_deg"] = std::move(rotations);
  out_ << line.dump() << std::endl;
}

void TrainingLog::write_stress(std::int64_t step, const std::vector<bullet::StressCase>& cases,
                               const std::vector<std::vector<bullet::StressRun>>& runs) {
  nlohmann::json stress = nlohmann::json::object();
  for (size_t i = 0; i < cases.size(); ++i) {
    nlohmann::json by_simulator = nlohmann::json::object();
    for (size_t s = 1; s < runs[i].size(); ++s) {
      const bullet::StressRun& run = runs[i][s];
      nlohmann::json figures{{"finite", run.finite}};
      // A run that went non-finite has no meaningful figure (JSON has no NaN).
      if (run.finite) {
        figures["lowest_m"] = run.lowest;
        figures["late_speed_m_s"] = run.late_speed;
        if (cases[i].at_rest) {
          figures["drift_m"] = run.drift;
          figures["drift_deg"] = run.drift_degrees;
          figures["first_step_fall"] = run.first_step_fall;
        } else {
          figures["error_m"] = run.error;
        }
      }
      by_simulator[s == 1   ? "network_alone"
                   : s == 2 ? "world"
                            : fmt::format("run_{}", s)] = std::move(figures);
    }
    stress[cases[i].name] = std::move(by_simulator);
  }
  nlohmann::json line{{"step", step}, {"samples", samples_at(step)}, {"stress", std::move(stress)}};
  out_ << line.dump() << std::endl;
}

}  // namespace fignet::cli
