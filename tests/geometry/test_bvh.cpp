#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "fignet/geometry/bvh.h"

namespace fignet {
namespace {

std::vector<Aabb> random_boxes(std::mt19937& rng, int count, double spread, double size) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), s(0.0, 1.0);
  std::vector<Aabb> boxes(count);
  for (auto& box : boxes) {
    const Vec3 c = spread * Vec3(u(rng), u(rng), u(rng));
    const Vec3 e = size * Vec3(s(rng), s(rng), s(rng));
    box = Aabb{c - e, c + e};
  }
  return boxes;
}

std::set<std::pair<int, int>> brute_force(const std::vector<Aabb>& a, const std::vector<Aabb>& b,
                                          double margin) {
  std::set<std::pair<int, int>> pairs;
  for (int i = 0; i < int(a.size()); ++i) {
    for (int j = 0; j < int(b.size()); ++j) {
      if (squared_distance(a[i], b[j]) <= margin * margin) pairs.insert({i, j});
    }
  }
  return pairs;
}

std::set<std::pair<int, int>> query(const Bvh& a, const Bvh& b, double margin) {
  std::set<std::pair<int, int>> pairs;
  int visits = 0;
  a.for_each_pair_within(b, margin, [&](int i, int j) {
    pairs.insert({i, j});
    ++visits;
  });
  EXPECT_EQ(visits, int(pairs.size())) << "a pair was visited twice";
  return pairs;
}

TEST(Bvh, PairQueryEqualsBruteForce) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const auto a = random_boxes(rng, 1 + trial * 37, 2.0, 0.1);
    const auto b = random_boxes(rng, 1 + trial * 23, 2.0, 0.2);
    Bvh ta, tb;
    ta.build(a);
    tb.build(b);
    for (double margin : {0.0, 0.05, 0.3}) {
      EXPECT_EQ(query(ta, tb, margin), brute_force(a, b, margin)) << "trial " << trial;
    }
  }
}

TEST(Bvh, RefitAfterMotionEqualsRebuild) {
  std::mt19937 rng(11);
  auto boxes = random_boxes(rng, 500, 2.0, 0.05);
  const auto others = random_boxes(rng, 300, 2.0, 0.05);
  Bvh refitted, fixed;
  refitted.build(boxes);
  fixed.build(others);
  // Rotate every box centre by 90 degrees about z: the topology no longer fits, results must.
  for (auto& box : boxes) {
    const Vec3 c = box.center(), e = 0.5 * box.extent();
    const Vec3 moved(-c.y(), c.x(), c.z());
    box = Aabb{moved - e, moved + e};
  }
  refitted.refit(boxes);
  EXPECT_EQ(query(refitted, fixed, 0.1), brute_force(boxes, others, 0.1));
  Aabb all;
  for (const auto& box : boxes) all.extend(box);
  EXPECT_EQ(refitted.bounds().min, all.min);
  EXPECT_EQ(refitted.bounds().max, all.max);
}

TEST(Bvh, IdenticalCentresStillGiveABalancedTree) {
  // Median splits by count: coincident primitives must not recurse forever.
  std::vector<Aabb> boxes(2000, Aabb{Vec3::Zero(), Vec3::Ones()});
  Bvh tree;
  tree.build(boxes);
  int visits = 0;
  tree.for_each_pair_within(tree, 0.0, [&](int, int) { ++visits; });
  EXPECT_EQ(visits, 2000 * 2000);
}

}  // namespace
}  // namespace fignet
