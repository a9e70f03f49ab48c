#include <H5Cpp.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "../temp_folder.h"
#include "fignet/error.h"
#include "fignet/io/model_file.h"
#include "hdf5_time_stamps.h"

namespace fignet {
namespace {

namespace fs = std::filesystem;

class ModelFile : public testing::TempFolderTest {
 protected:
  void SetUp() override {
    TempFolderTest::SetUp();
    ModelConfig config = ModelConfig::preset_named("small");
    config.latent_size = 16;
    config.message_passing_steps = 2;
    config.hidden_size = 24;
    config.object_hidden_size = 40;
    config.seed = 42;
    config.noise_correction = 0.25;
    config.random_yaw = true;
    config.graph.face_span_limit = 0.75;
    config.graph.velocity_log_scale = 1e-4;
    config.graph.distance_log_scale = 2e-3;
    config.graph.contact_motion = true;
    config.graph.contact_motion_dead_zone = 7e-4;
    config.graph.omit_free_flight = true;
    config.min_mass = 1.6;
    config.max_mass = 59.0;
    config.friction = {0.4, 0.8};
    config.restitution = {0.3, 0.7};
    config.floor_friction = {0.3, 0.3};  // floor_restitution left unknown
    Model fresh(config);
    Normalizers normalizers = fresh.normalizers();
    RowMatrixXf rows = RowMatrixXf::Random(10, normalizers.mesh_node.size());
    normalizers.mesh_node.accumulate(rows);
    model_ = std::make_unique<Model>(config, fresh.parameters(), normalizers);
    path_ = dir_ / "model.h5";
    save_model(*model_, path_);
  }

  std::string load_error(const fs::path& path) {
    try {
      load_model(path);
    } catch (const FileError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no FileError";
    return {};
  }

  fs::path path_;
  std::unique_ptr<Model> model_;
};

void expect_contains(const std::string& text, const std::string& part) {
  EXPECT_NE(text.find(part), std::string::npos) << "'" << text << "' lacks '" << part << "'";
}

TEST_F(ModelFile, SaveThenLoadIsBitExact) {
  const Model loaded = load_model(path_);
  EXPECT_EQ(loaded.parameters(), model_->parameters());
  EXPECT_EQ(loaded.config().latent_size, 16);
  EXPECT_EQ(loaded.config().hidden_size, 24);
  EXPECT_EQ(loaded.config().object_hidden_size, 40);
  EXPECT_EQ(loaded.config().seed, 42u);
  EXPECT_EQ(loaded.config().graph.collision_radius, model_->config().graph.collision_radius);
  EXPECT_EQ(loaded.config().time_step, model_->config().time_step);
  EXPECT_EQ(loaded.config().noise_correction, 0.25);
  EXPECT_TRUE(loaded.config().random_yaw);
  EXPECT_EQ(loaded.config().graph.face_span_limit, 0.75);
  EXPECT_EQ(loaded.config().graph.velocity_log_scale, 1e-4);
  EXPECT_EQ(loaded.config().graph.distance_log_scale, 2e-3);
  EXPECT_TRUE(loaded.config().graph.contact_motion);
  EXPECT_EQ(loaded.config().graph.contact_motion_dead_zone, 7e-4);
  EXPECT_TRUE(loaded.config().graph.omit_free_flight);
  EXPECT_EQ(loaded.config().min_mass, 1.6);
  EXPECT_EQ(loaded.config().max_mass, 59.0);
  EXPECT_EQ(loaded.config().friction.lowest, 0.4);
  EXPECT_EQ(loaded.config().friction.highest, 0.8);
  EXPECT_EQ(loaded.config().restitution.lowest, 0.3);
  EXPECT_EQ(loaded.config().restitution.highest, 0.7);
  EXPECT_EQ(loaded.config().floor_friction.highest, 0.3);
  EXPECT_FALSE(loaded.config().floor_restitution.known());
  EXPECT_EQ(loaded.normalizers().face_edge.size(), 34 + 1 + 5);  // the logarithm, the motion
  EXPECT_EQ(loaded.normalizers().mesh_node.sum(), model_->normalizers().mesh_node.sum());
  EXPECT_EQ(loaded.normalizers().mesh_node.sum_squares(),
            model_->normalizers().mesh_node.sum_squares());
  EXPECT_EQ(loaded.normalizers().mesh_node.count(), 10.0);
  EXPECT_EQ(loaded.normalizers().mesh_node.accumulations(), 1);
  // No temporary file is left beside the model.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

// Attributes added after the first model files: a file without them reads as those files were
// made (the config's defaults; the fixture's model sets each to something else).
TEST_F(ModelFile, AFileWithoutLaterAttributesReadsWhatOlderFilesWereMadeWith) {
  {
    H5::H5File file(path_.string(), H5F_ACC_RDWR);
    H5::Group config = file.openGroup("config");
    // (Not those that shape the parameters: their files would not load without them.)
    for (const char* name : {"face_span_limit", "contact_motion_dead_zone", "omit_free_flight",
                             "noise_correction", "random_yaw"}) {
      config.removeAttr(name);
    }
  }
  const ModelConfig loaded = load_model(path_).config(), defaults;
  EXPECT_EQ(loaded.graph.face_span_limit, defaults.graph.face_span_limit);
  EXPECT_EQ(loaded.graph.contact_motion_dead_zone, 0.0);
  EXPECT_FALSE(loaded.graph.omit_free_flight);
  EXPECT_EQ(loaded.noise_correction, defaults.noise_correction);
  EXPECT_FALSE(loaded.random_yaw);
  EXPECT_TRUE(loaded.graph.contact_motion);  // still in the file
}

TEST_F(ModelFile, NoObjectCarriesATimeStamp) {
  EXPECT_EQ(testing::objects_with_time_stamps(path_), std::vector<std::string>{});
}

// A byte flipped in the file's last half (parameters and statistics) loads as a valid model or
// fails with a FileError naming the file: never another exception or a crash. (HDF5 metadata
// flips can hit libhdf5's own bugs: docs/model-file.md.)
TEST_F(ModelFile, FlippedBytesLoadValidOrFailClearly) {
  std::string bytes;
  {
    std::ifstream in(path_, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  int tried = 0;
  for (size_t at = bytes.size() / 2; at < bytes.size(); at += bytes.size() / 97, ++tried) {
    std::string flipped = bytes;
    flipped[at] = static_cast<char>(flipped[at] ^ 0xA5);
    std::ofstream(dir_ / "flipped.h5", std::ios::binary) << flipped;
    try {
      const Model loaded = load_model(dir_ / "flipped.h5");
      EXPECT_EQ(loaded.parameters().size(), model_->parameters().size());
    } catch (const FileError& e) {
      expect_contains(e.what(), "flipped.h5");
    }
  }
  EXPECT_GT(tried, 40);
}

TEST_F(ModelFile, MissingTruncatedAndForeignFilesFailClearly) {
  expect_contains(load_error(dir_ / "absent.h5"), "no such file");
  const auto size = fs::file_size(path_);
  fs::copy_file(path_, dir_ / "truncated.h5");
  fs::resize_file(dir_ / "truncated.h5", size / 2);
  expect_contains(load_error(dir_ / "truncated.h5"), "not a readable HDF5 file");
  std::ofstream(dir_ / "text.h5") << "not hdf5";
  expect_contains(load_error(dir_ / "text.h5"), "not a readable HDF5 file");
  { H5::H5File(std::string(dir_ / "foreign.h5"), H5F_ACC_TRUNC).createGroup("data"); }
  expect_contains(load_error(dir_ / "foreign.h5"), "not a fignet model");
}

TEST_F(ModelFile, OtherVersionMissingTensorAndWrongShapeFailClearly) {
  {
    H5::H5File file(path_.string(), H5F_ACC_RDWR);
    file.openGroup("/").removeAttr("version");
    const long long version = 99;
    file.openGroup("/")
        .createAttribute("version", H5::PredType::NATIVE_LLONG, H5::DataSpace())
        .write(H5::PredType::NATIVE_LLONG, &version);
  }
  expect_contains(load_error(path_), "format version 99 is not supported");
  save_model(*model_, path_);
  { H5::H5File(path_.string(), H5F_ACC_RDWR).unlink("parameters/decoder/mesh_node/linear_2/b"); }
  expect_contains(load_error(path_), "missing tensor 'parameters/decoder/mesh_node/linear_2/b'");
  save_model(*model_, path_);
  {
    H5::H5File file(path_.string(), H5F_ACC_RDWR);
    file.unlink("parameters/decoder/mesh_node/linear_2/b");
    const hsize_t shape[2] = {1, 4};
    const float zeros[4] = {};
    file.openGroup("parameters/decoder/mesh_node/linear_2")
        .createDataSet("b", H5::PredType::IEEE_F32LE, H5::DataSpace(2, shape))
        .write(zeros, H5::PredType::NATIVE_FLOAT);
  }
  expect_contains(load_error(path_), "has shape [1, 4], expected [1, 3]");
}

TEST_F(ModelFile, UnwritablePathFailsAndLeavesNothing) {
  EXPECT_THROW(save_model(*model_, dir_ / "missing_dir" / "model.h5"), FileError);
  EXPECT_FALSE(fs::exists(dir_ / "missing_dir"));
}

}  // namespace
}  // namespace fignet
