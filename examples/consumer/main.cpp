// Uses the installed pushgraph libraries: an exact signed distance with its pose Jacobian, the
// separation of a disk finger from a box, and a trajectory file round trip.
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape_pair.h>
#include <pushgraph/io/trajectory_json.h>

#include <cmath>
#include <cstdio>

int main() {
  using namespace pushgraph::geometry;
  const Shape box = Shape::Box(0.09, 0.09);
  PointQueryJacobians J;
  const PointQuery q = QueryPoint(box, Pose2{0.0, 0.0, 0.1}, Vec2(0.1, 0.0), &J);
  const ShapePairResult r = QueryShapePair(box, Pose2{}, Shape::Disk(0.005), Pose2{-0.06, 0.0, 0.0});
  pushgraph::push::Trajectory t;
  t.object.shape = box;
  t.object.mass = 0.8374;
  t.finger.shape = Shape::Disk(0.00235);
  const auto back = pushgraph::io::ParseTrajectoryJson(pushgraph::io::TrajectoryToJson(t));
  std::printf("signed distance %.6f (d/dtheta %.6f), finger separation %.6f, mass %.4f\n", q.signed_distance,
              J.J_sd_pose(2), r.signed_distance, back.object.mass);
  const bool ok = q.signed_distance > 0.05 && q.signed_distance < 0.06 && std::abs(r.signed_distance - 0.01) < 1e-15 && back.object.mass == 0.8374;
  return ok ? 0 : 1;
}
