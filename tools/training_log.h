// The machine-readable training log: one JSON object per line, appended as training goes. A
// resumed run first drops the lines written after its checkpoint, so the log matches the model.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include "fignet/bullet/stress.h"
#include "fignet/rollout/evaluation.h"
#include "fignet/rollout/one_step.h"

namespace fignet::cli {

class TrainingLog {
 public:
  // Opens `path` for appending, keeping only the lines of steps <= `resume_step` (a fresh run
  // passes 0 and starts an empty log). Every line has "samples", the scenes trained on so far:
  // steps from here on count `batch_size` each, those before as the kept lines say, and steps
  // after the last line that counted them `resumed_batch_size` each (the checkpoint's; a resume
  // may change the batch).
  TrainingLog(const std::filesystem::path& path, std::int64_t resume_step, int resumed_batch_size,
              int batch_size);

  // `heading_gap` (TrainStep::heading_gap) is written when not negative.
  void write_step(std::int64_t step, double loss, float learning_rate, double steps_per_second,
                  double gradient_norm, double heading_gap = -1.0);
  // Validation rollouts and the one-step errors by regime of the same trajectories.
  void write_validation(std::int64_t step, const Evaluation& evaluation,
                        const OneStepTotals& one_step);
  // The stress cases run at a validation, each by stress_simulators with one model: Bullet (the
  // reference), the network alone, the world. One line: {"stress": {case: {"network_alone":
  // {...}, "world": {...}}}} with finite, lowest_m, late_speed_m_s, and drift_m / drift_deg for
  // cases started at rest or error_m for the others.
  void write_stress(std::int64_t step, const std::vector<bullet::StressCase>& cases,
                    const std::vector<std::vector<bullet::StressRun>>& runs);

 private:
  std::int64_t samples_at(std::int64_t step) const;

  std::ofstream out_;
  int batch_size_;
  std::int64_t resume_step_, resume_samples_;
};

}  // namespace fignet::cli
