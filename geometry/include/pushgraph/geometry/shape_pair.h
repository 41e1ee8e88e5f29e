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
// Minkowski sum is needed. Rounding radii (a disk finger's, a rounded object's) add to the core
// depth (the rounded-shape convention of point_query.h). That sum is the true depth when the
// finger can leave along the core's normal, but only a lower bound where the rounded obstacle
// fills a concave corner, a notch or a hole narrower than the finger (moving by it still
// overlaps): each overlapping rounded query checks its own answer by moving the finger and
// reports the outcome in depth_exact (Options::check_rounded_depth). Separations of apart
// shapes are always exact.
//
// The fast path (Method::kVertexSampling) takes the deepest vertex of either shape inside the
// other; it is exact when apart and for point/disk fingers, and an estimate for polygonal
// fingers overlapping an object (its error against the exact path is tested).
//
//   ShapePairQuerier contact(object, finger);           // keep it: it caches obstacles
//   ShapePairResult r = contact.Query(object_pose, finger_pose);
//   if (r.intersecting) { push finger along r.direction by r.depth to separate }
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
  /// False when `depth` is only a lower bound of the penetration depth: rounded shapes whose
  /// obstacle fills a concave corner, notch or hole (moving the finger by depth along normal
  /// leaves it overlapping; checked only with Options::check_rounded_depth), or the
  /// vertex-sampling estimate of a polygonal finger.
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
    /// Check an overlapping rounded query's depth by a second query (ShapePairResult::
    /// depth_exact); off, depth_exact is left true and the query costs one point query less.
    bool check_rounded_depth = true;
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
