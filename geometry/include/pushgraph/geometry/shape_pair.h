#pragma once
// Shape-versus-shape queries between an object and a finger, each at its own pose.
//
// Signed separation: positive when apart (the exact Euclidean distance between the shapes);
// negative when they overlap, minus the translational penetration depth (the length of the
// shortest translation of the finger that separates them). Witness points: when apart, the
// closest pair; when overlapping, the paper's deepest finger point delta (the finger point
// that ends up touching the object after the separating translation) and its projection onto
// the object's boundary G_delta (Lambert et al., factor S).
//
// Exactness. The depth is computed on the configuration-space obstacle
// C = object_core (+) (-finger_core) at the current relative angle, built exactly with CGAL
// (Epeck Minkowski sums, reduced convolution; cached per relative angle) and queried with the
// exact point query. For a finger whose core is a point (a disk) C is the object itself and no
// Minkowski sum is needed. With rounding radii (a disk finger's, a rounded object's) the obstacle
// is C grown by a disk of their sum, and the depth is the distance to that grown obstacle's
// boundary: its offset segments and arcs, split where they cross in concave corners, notches and
// holes narrower than the finger (rounded_boundary.h; built once per relative angle, or once for
// a disk finger, on the first overlapping query). Where the finger can leave along the core's
// normal this equals "core depth + radii"; where the grown obstacle fills a concave region the
// depth is larger and the witness points sit at the corner where two offsets cross. Depths are
// within a few ulps of the coordinates' scale of an independent extended-precision oracle
// (tests/geometry/test_rounded_depth.cpp); separations of apart shapes are exact.
//
// The fast path (Method::kVertexSampling) takes the deepest vertex of either shape inside the
// other; it is exact when apart and for point/disk fingers, and an estimate for polygonal
// fingers overlapping an object (its error against the exact path is tested).
//
//   ShapePairQuerier contact(object, finger);           // keep it: it caches obstacles
//   ShapePairResult r = contact.Query(object_pose, finger_pose);
//   if (r.intersecting) { move the finger along r.normal by r.depth to separate }
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>

#include <Eigen/Core>

#include <memory>

namespace pushgraph::geometry {

struct ShapePairResult {
  double signed_distance = 0.0;  ///< > 0 apart, < 0 overlap (-depth), 0 touching
  bool intersecting = false;     ///< interiors overlap
  Vec2 object_point{0.0, 0.0};   ///< world frame: closest object point / projection G_delta
  Vec2 finger_point{0.0, 0.0};   ///< world frame: closest finger point / deepest point delta
  double depth = 0.0;            ///< max(0, -signed_distance)
  /// False when `depth` is not the penetration depth: the vertex-sampling estimate of a
  /// polygonal finger, or (with Options::exact_rounded_depth off) the "core depth + radii" lower
  /// bound of a rounded pair where moving the finger by it leaves the shapes overlapping (checked
  /// with Options::check_rounded_depth).
  bool depth_exact = true;
  /// Unit vector, world frame, in which the finger moves to increase the separation fastest
  /// (to separate, when intersecting); object_point - finger_point = -signed_distance * normal.
  Vec2 normal{1.0, 0.0};
};

/// Derivatives with respect to (x, y, theta) of each pose.
struct ShapePairJacobians {
  Eigen::Matrix<double, 1, 3> J_sd_object_pose;
  Eigen::Matrix<double, 1, 3> J_sd_finger_pose;
  Eigen::Matrix<double, 2, 3> J_object_point_object_pose;
  Eigen::Matrix<double, 2, 3> J_object_point_finger_pose;
  Eigen::Matrix<double, 2, 3> J_finger_point_object_pose;
  Eigen::Matrix<double, 2, 3> J_finger_point_finger_pose;
};

class ShapePairQuerier {
 public:
  enum class Method {
    kExact,           ///< C-obstacle (Minkowski sum) for polygonal fingers; exact
    kVertexSampling,  ///< deepest vertex; exact when apart and for disk fingers
  };
  struct Options {
    Method method = Method::kExact;
    /// Relative angles are cached at this resolution (radians) for kExact with polygonal
    /// fingers; 0 caches exact angles only (bit-identical angles share an obstacle).
    double angle_cache_resolution = 0.0;
    int max_cached_angles = 256;
    /// Rounded shapes: the exact depth from the grown obstacle's boundary (header). Off: "core
    /// depth + radii", a lower bound where the grown obstacle fills a concave region (kept for
    /// comparison and benchmarks).
    bool exact_rounded_depth = true;
    /// Check every overlapping rounded query by moving the finger by its depth and querying
    /// again (ShapePairResult::depth_exact); a self-test for the exact depth, which never fails
    /// it, and the way to see where the bound falls short with exact_rounded_depth off.
    bool check_rounded_depth = false;
  };

  ShapePairQuerier(Shape object, Shape finger);
  ShapePairQuerier(Shape object, Shape finger, Options options);
  ~ShapePairQuerier();
  ShapePairQuerier(ShapePairQuerier&&) noexcept;
  ShapePairQuerier& operator=(ShapePairQuerier&&) noexcept;

  ShapePairResult Query(const Pose2& object_pose, const Pose2& finger_pose,
                        ShapePairJacobians* jacobians = nullptr) const;

  const Shape& object() const;
  const Shape& finger() const;
  /// Number of Minkowski obstacles built so far (for tests and tuning).
  int obstacles_built() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One-off convenience wrapper (builds a querier each call; keep a ShapePairQuerier instead
/// in loops).
ShapePairResult QueryShapePair(const Shape& object, const Pose2& object_pose, const Shape& finger,
                               const Pose2& finger_pose);

}  // namespace pushgraph::geometry
