// Triangle–triangle closest points against an independent oracle: dense sampling of both
// triangles. The exact distance can never exceed the sampled minimum, and the sampled minimum can
// exceed it by at most the two sampling resolutions.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "fignet/geometry/triangle_distance.h"

namespace fignet {
namespace {

constexpr int kSamplesPerEdge = 24;

std::vector<Vec3> sample(const Triangle& t) {
  std::vector<Vec3> points;
  for (int i = 0; i <= kSamplesPerEdge; ++i) {
    for (int j = 0; i + j <= kSamplesPerEdge; ++j) {
      const double u = double(i) / kSamplesPerEdge, v = double(j) / kSamplesPerEdge;
      points.push_back(t.v[0] + u * (t.v[1] - t.v[0]) + v * (t.v[2] - t.v[0]));
    }
  }
  return points;
}

// Every point of a triangle lies within this distance of one of its samples.
double sampling_resolution(const Triangle& t) {
  const double longest =
      std::max({(t.v[1] - t.v[0]).norm(), (t.v[2] - t.v[0]).norm(), (t.v[2] - t.v[1]).norm()});
  return longest / kSamplesPerEdge;
}

double min_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double best = INFINITY;
  for (const Vec3& p : a) {
    for (const Vec3& q : b) best = std::min(best, (p - q).squaredNorm());
  }
  return std::sqrt(best);
}

enum class Case { kGeneral, kParallel, kCoplanar, kTouching, kIntersecting, kSliver };

class TrianglePairs {
 public:
  explicit TrianglePairs(unsigned seed) : rng_(seed) {}

  Vec3 point(double scale = 1.0) { return scale * Vec3(u_(rng_), u_(rng_), u_(rng_)); }
  Triangle triangle(const Vec3& center, double scale) {
    return {{center + point(scale), center + point(scale), center + point(scale)}};
  }

  std::pair<Triangle, Triangle> make(Case c) {
    Triangle a = triangle(Vec3::Zero(), 1.0);
    switch (c) {
      case Case::kGeneral:
        return {a, triangle(point(1.5), 1.0)};
      case Case::kParallel: {  // b in a plane parallel to a, offset along the normal
        const Vec3 n = (a.v[1] - a.v[0]).cross(a.v[2] - a.v[0]).normalized();
        Triangle b = a;
        const Vec3 shift = 0.3 * u_(rng_) * n + 0.5 * (a.v[1] - a.v[0]) * u_(rng_);
        for (auto& v : b.v) v += shift;
        return {a, b};
      }
      case Case::kCoplanar: {  // b's vertices are random points of a's plane
        Triangle b;
        for (auto& v : b.v) {
          v = a.v[0] + 1.5 * u_(rng_) * (a.v[1] - a.v[0]) + 1.5 * u_(rng_) * (a.v[2] - a.v[0]);
        }
        return {a, b};
      }
      case Case::kTouching: {  // a vertex of b lies on a (interior or edge)
        double s = std::abs(u_(rng_)), t = std::abs(u_(rng_)) * (1 - s);
        if (rng_() % 3 == 0) t = 0;  // on an edge
        Triangle b = triangle(Vec3::Zero(), 1.0);
        const Vec3 on_a = a.v[0] + s * (a.v[1] - a.v[0]) + t * (a.v[2] - a.v[0]);
        const Vec3 n = (a.v[1] - a.v[0]).cross(a.v[2] - a.v[0]).normalized();
        b.v[0] = on_a;
        b.v[1] = on_a + n + 0.5 * point();
        b.v[2] = on_a + n + 0.5 * point();
        return {a, b};
      }
      case Case::kIntersecting:  // centred near each other: they cross most of the time
        return {a, triangle(0.1 * point(), 1.0)};
      case Case::kSliver: {  // b nearly degenerate: third vertex almost on its first edge
        Triangle b = triangle(point(1.2), 1.0);
        b.v[2] = 0.5 * (b.v[0] + b.v[1]) + 1e-9 * point();
        return {a, b};
      }
    }
    return {a, a};
  }

 private:
  std::mt19937 rng_;
  std::uniform_real_distribution<double> u_{-1.0, 1.0};
};

void check_against_sampling(const Triangle& a, const Triangle& b) {
  const ClosestPoints exact = closest_points_triangles(a, b);
  const auto samples_a = sample(a), samples_b = sample(b);
  const double sampled = min_distance(samples_a, samples_b);
  const double tolerance = sampling_resolution(a) + sampling_resolution(b);
  ASSERT_TRUE(std::isfinite(exact.distance));
  // The distance is the distance between the reported points…
  EXPECT_NEAR((exact.on_first - exact.on_second).norm(), exact.distance, 1e-12);
  // …which lie on their triangles…
  EXPECT_LE(min_distance({exact.on_first}, samples_a), sampling_resolution(a) + 1e-12);
  EXPECT_LE(min_distance({exact.on_second}, samples_b), sampling_resolution(b) + 1e-12);
  // …and no sampled pair is closer, while the densest samples come within their resolution.
  EXPECT_LE(exact.distance, sampled + 1e-12);
  EXPECT_LE(sampled, exact.distance + tolerance);
}

TEST(TriangleDistance, MatchesDenseSamplingOnTenThousandPairs) {
  TrianglePairs pairs(1234);
  const Case cases[] = {Case::kGeneral,  Case::kParallel,     Case::kCoplanar,
                        Case::kTouching, Case::kIntersecting, Case::kSliver};
  int intersecting = 0;
  for (int i = 0; i < 10000; ++i) {
    const Case c = cases[i % 6];
    auto [a, b] = pairs.make(c);
    if (i % 2) std::swap(a, b);
    SCOPED_TRACE(::testing::Message() << "pair " << i << ", case " << int(c));
    check_against_sampling(a, b);
    if (closest_points_triangles(a, b).distance == 0.0) ++intersecting;
    if (::testing::Test::HasFailure()) break;
  }
  // The generator must really exercise the intersecting and touching branches.
  EXPECT_GT(intersecting, 2000);
}

TEST(TriangleDistance, ParallelStackedTrianglesAreTheirGapApart) {
  const Triangle a{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}};
  const Triangle b{{Vec3(0.1, 0.1, 0.25), Vec3(0.5, 0.1, 0.25), Vec3(0.1, 0.5, 0.25)}};
  const ClosestPoints cp = closest_points_triangles(a, b);
  EXPECT_DOUBLE_EQ(cp.distance, 0.25);
  EXPECT_DOUBLE_EQ(cp.on_first.z(), 0.0);
  EXPECT_DOUBLE_EQ(cp.on_second.z(), 0.25);
}

TEST(TriangleDistance, CrossingTrianglesReportAPointOfTheIntersection) {
  const Triangle a{{Vec3(-1, -1, 0), Vec3(2, -1, 0), Vec3(-1, 2, 0)}};
  const Triangle b{{Vec3(0.2, 0.3, -1), Vec3(0.2, 0.3, 1), Vec3(0.9, -0.5, 0.3)}};
  const ClosestPoints cp = closest_points_triangles(a, b);
  EXPECT_EQ(cp.distance, 0.0);
  EXPECT_EQ(cp.on_first, cp.on_second);
  EXPECT_NEAR(cp.on_first.z(), 0.0, 1e-15);  // on a's plane
  const Vec3 n = (b.v[1] - b.v[0]).cross(b.v[2] - b.v[0]);
  EXPECT_NEAR(n.dot(cp.on_first - b.v[0]), 0.0, 1e-12);  // and on b's
}

TEST(TriangleDistance, PointLikeAndSegmentLikeTrianglesWork) {
  const Triangle a{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}};
  const Triangle point{{Vec3(0.2, 0.2, 0.5), Vec3(0.2, 0.2, 0.5), Vec3(0.2, 0.2, 0.5)}};
  EXPECT_DOUBLE_EQ(closest_points_triangles(a, point).distance, 0.5);
  const Triangle segment{{Vec3(2, 0, 1), Vec3(3, 0, 1), Vec3(2.5, 0, 1)}};
  EXPECT_NEAR(closest_points_triangles(a, segment).distance, std::sqrt(2.0), 1e-12);
}

TEST(SegmentDistance, ParallelAndDegenerateSegments) {
  EXPECT_DOUBLE_EQ(
      closest_points_segments(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(2, 1, 0))
          .distance,
      1.0);
  EXPECT_DOUBLE_EQ(
      closest_points_segments(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(3, 4, 0), Vec3(3, 4, 0)).distance,
      5.0);
}

}  // namespace
}  // namespace fignet
