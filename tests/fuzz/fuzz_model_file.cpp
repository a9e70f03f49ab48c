// libFuzzer harness: arbitrary bytes as a model file. Loading may fail only with a fignet::Error;
// a model that loads must run on a small scene.
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <string>

#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"
#include "fignet/io/model_file.h"
#include "fignet/rollout/predictor.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = "/tmp/fignet_fuzz_model_" + std::to_string(::getpid()) + ".h5";
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  try {
    auto model = std::make_shared<const fignet::Model>(fignet::load_model(path));
    static const fignet::TriangleMesh cube =
        fignet::centered_on_center_of_mass(fignet::make_box(fignet::Vec3::Constant(0.5), 1));
    fignet::Scene scene;
    scene.objects.emplace_back();
    fignet::SceneObject& object = scene.objects.back();
    object.mesh = &cube;
    std::vector<fignet::Pose> poses(static_cast<size_t>(model->config().graph.history + 1));
    fignet::set_pose_history(object, poses, std::nullopt);
    fignet::ModelPredictor predictor(model);
    fignet::Points accelerations;
    predictor.predict(scene, accelerations);
  } catch (const fignet::Error&) {
  }
  return 0;
}
