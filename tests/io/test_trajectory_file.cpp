#include <H5Cpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "../model/trajectory_fixtures.h"
#include "../temp_folder.h"
#include "fignet/error.h"
#include "fignet/io/trajectory_file.h"
#include "hdf5_time_stamps.h"

namespace fignet {
namespace {

namespace fs = std::filesystem;

std::vector<Trajectory> make_data(int count) {
  std::vector<Trajectory> data;
  for (int i = 0; i < count; ++i) {
    Trajectory t;
    t.seed = 100 + i;
    t.floor = Floor{0.1 * i};
    t.objects.push_back(testing::ballistic_object(testing::small_cube(), Vec3(i, 0, 2),
                                                  Vec3(1, 0, 0), Vec3(0, 1, 2), 8, t.time_step,
                                                  t.gravity));
    TrajectoryObject pusher = testing::ballistic_object(
        std::make_shared<const TriangleMesh>(make_cylinder(0.1, 0.2)), Vec3(0, 1, 0),
        Vec3(0, -1, 0), Vec3::Zero(), 8, t.time_step, Vec3::Zero());
    pusher.kinematic = true;
    pusher.properties.mass = 0.0;
    for (int f = 0; f < 8; ++f) {
      pusher.linear_velocities.push_back(Vec3(0, -1, 0));
      pusher.angular_velocities.push_back(Vec3::Zero());
    }
    t.objects.push_back(pusher);
    data.push_back(t);
  }
  return data;
}

class TrajectoryFile : public testing::TempFolderTest {
 protected:
  std::string read_error(const fs::path& path) {
    try {
      read_trajectories(path);
    } catch (const FileError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no FileError";
    return {};
  }
};

TEST_F(TrajectoryFile, WriteThenReadRoundTripsExactly) {
  const auto data = make_data(3);
  const DatasetInfo written{"movi-a", "0.1.0", 7, 2, 3, 5, 1, 4, 8, 0.25};
  write_trajectories(dir_ / "set.h5", data, written);
  DatasetInfo info;
  const auto read = read_trajectories(dir_ / "set.h5", &info);
  EXPECT_EQ(info, written);
  ASSERT_EQ(read.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(read[i].seed, data[i].seed);
    EXPECT_EQ(read[i].floor->height, data[i].floor->height);
    EXPECT_EQ(read[i].time_step, data[i].time_step);
    ASSERT_EQ(read[i].objects.size(), 2u);
    for (size_t o = 0; o < 2; ++o) {
      const auto& a = read[i].objects[o];
      const auto& b = data[i].objects[o];
      EXPECT_EQ(a.mesh->vertices(), b.mesh->vertices());
      EXPECT_EQ(a.mesh->faces(), b.mesh->faces());
      EXPECT_EQ(a.mesh->name(), b.mesh->name());
      EXPECT_EQ(a.kinematic, b.kinematic);
      EXPECT_EQ(a.properties.mass, b.properties.mass);
      ASSERT_EQ(a.poses.size(), b.poses.size());
      for (size_t f = 0; f < a.poses.size(); ++f) {
        EXPECT_EQ(a.poses[f].position, b.poses[f].position);
        EXPECT_EQ(a.poses[f].orientation.coeffs(), b.poses[f].orientation.coeffs());
      }
      EXPECT_EQ(a.linear_velocities, b.linear_velocities);
    }
  }
  // A file from before stacks, their levels and piles were options reads as the preset's scenes:
  // no stacks (1-3 levels when asked), no spheres on them and no piles (3-6 objects when asked).
  {
    H5::H5File file(std::string(dir_ / "set.h5"), H5F_ACC_RDWR);
    H5::Group root = file.openGroup("/");
    for (const char* name : {"stacks", "min_stack_levels", "max_stack_levels", "piles",
                             "min_pile_objects", "max_pile_objects", "sphere_topped_stacks"})
      root.removeAttr(name);
  }
  read_trajectories(dir_ / "set.h5", &info);
  EXPECT_EQ(info, (DatasetInfo{"movi-a", "0.1.0", 7, 0, 1, 3, 0, 3, 6}));
  // Shards read back in order.
  write_trajectories(dir_ / "shard1.h5", make_data(2), {"movi-a", "0.1.0", 8});
  EXPECT_EQ(read_trajectories({dir_ / "set.h5", dir_ / "shard1.h5"}).size(), 5u);
  // A file without piles or spheres carries no attributes for them: its bytes are those of before
  // they existed.
  {
    H5::H5File file(std::string(dir_ / "shard1.h5"), H5F_ACC_RDONLY);
    const H5::Group root = file.openGroup("/");
    for (const char* name :
         {"piles", "min_pile_objects", "max_pile_objects", "sphere_topped_stacks"})
      EXPECT_FALSE(root.attrExists(name)) << name;
  }
}

// No object carries HDF5's time stamps: the same scenes written at another time are the same
// bytes, so a data set regenerated from its seeds can be checked with a checksum.
TEST_F(TrajectoryFile, SameTrajectoriesGiveTheSameBytes) {
  write_trajectories(dir_ / "a.h5", make_data(2), {"movi-a", "0.1.0", 7});
  EXPECT_EQ(testing::objects_with_time_stamps(dir_ / "a.h5"), std::vector<std::string>{});
  write_trajectories(dir_ / "b.h5", make_data(2), {"movi-a", "0.1.0", 7});
  std::ifstream a(dir_ / "a.h5", std::ios::binary), b(dir_ / "b.h5", std::ios::binary);
  EXPECT_TRUE(std::equal(std::istreambuf_iterator<char>(a), std::istreambuf_iterator<char>(),
                         std::istreambuf_iterator<char>(b), std::istreambuf_iterator<char>()));
}

// A byte flipped anywhere in the file's last half (the datasets' contents: vertices, faces,
// poses) either reads back as a valid set or fails with a FileError: never another exception,
// a crash, or an invalid trajectory. (Flips in HDF5's own metadata can hit libhdf5 bugs; see
// docs/model-file.md and tests/fuzz.)
TEST_F(TrajectoryFile, FlippedBytesInTheDataFailCleanlyOrReadValid) {
  write_trajectories(dir_ / "set.h5", make_data(2), {"movi-a", "0.1.0", 7});
  std::string bytes;
  {
    std::ifstream in(dir_ / "set.h5", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  int rejected = 0, accepted = 0;
  for (size_t at = bytes.size() / 2; at < bytes.size(); at += bytes.size() / 97) {
    std::string flipped = bytes;
    flipped[at] = static_cast<char>(flipped[at] ^ 0xA5);
    std::ofstream(dir_ / "flipped.h5", std::ios::binary) << flipped;
    try {
      for (const Trajectory& t : read_trajectories(dir_ / "flipped.h5")) t.validate();
      ++accepted;
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find("flipped.h5"), std::string::npos) << e.what();
      ++rejected;
    }
  }
  EXPECT_GT(rejected + accepted, 40);
}

TEST_F(TrajectoryFile, WrongForeignAndTruncatedFilesFailClearly) {
  write_trajectories(dir_ / "set.h5", make_data(4), {"movi-a", "0.1.0", 7});
  fs::copy_file(dir_ / "set.h5", dir_ / "truncated.h5");
  fs::resize_file(dir_ / "truncated.h5", fs::file_size(dir_ / "set.h5") / 2);
  EXPECT_NE(read_error(dir_ / "truncated.h5").find("not a readable HDF5 file"), std::string::npos);
  EXPECT_NE(read_error(dir_ / "missing.h5").find("no such file"), std::string::npos);
  { H5::H5File(std::string(dir_ / "foreign.h5"), H5F_ACC_TRUNC).createGroup("data"); }
  EXPECT_NE(read_error(dir_ / "foreign.h5").find("not a fignet trajectory file"),
            std::string::npos);
  // A model file is not a trajectory file.
  {
    H5::H5File file(std::string(dir_ / "model.h5"), H5F_ACC_TRUNC);
    const H5::StrType type(H5::PredType::C_S1, 12);
    file.openGroup("/")
        .createAttribute("format", type, H5::DataSpace())
        .write(type, std::string("fignet-model"));
  }
  EXPECT_NE(read_error(dir_ / "model.h5").find("not a fignet trajectory file"), std::string::npos);
  // A dataset of the wrong shape names the trajectory, object and dataset.
  {
    H5::H5File file(std::string(dir_ / "set.h5"), H5F_ACC_RDWR);
    file.unlink("trajectories/000002/object_1/orientation");
    const hsize_t shape[2] = {8, 3};
    const double zeros[24] = {};
    file.openGroup("trajectories/000002/object_1")
        .createDataSet("orientation", H5::PredType::IEEE_F64LE, H5::DataSpace(2, shape))
        .write(zeros, H5::PredType::NATIVE_DOUBLE);
  }
  const std::string message = read_error(dir_ / "set.h5");
  EXPECT_NE(message.find("trajectory 000002/object_1"), std::string::npos) << message;
  EXPECT_NE(message.find("'orientation' has shape [8, 3], expected [8, 4]"), std::string::npos)
      << message;
}

TEST_F(TrajectoryFile, UnwritablePathLeavesNothing) {
  EXPECT_THROW(write_trajectories(dir_ / "no_dir" / "set.h5", make_data(1), {}), FileError);
  EXPECT_TRUE(fs::is_empty(dir_));
}

}  // namespace
}  // namespace fignet
