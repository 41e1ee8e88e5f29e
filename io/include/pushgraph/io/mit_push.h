#pragma once
// Recordings of the MIT planar pushing dataset (Yu, Bauza, Fazeli, Rodriguez, IROS 2016), read
// from the dataset's HDF5 files or its JSON variant, and repaired the way the data needs:
//
// - three unsynchronised N x 4 arrays, tip_pose [t, x, y, yaw], object_pose [t, x, y, yaw] and
//   ft_wrench [t, fx, fy, tz]; time stamps sometimes out of order by ~2 ms: sorted (stable),
//   exact duplicates dropped;
// - ft_wrench is the force ON THE SENSOR: the force the probe applies to the object is -(fx, fy);
// - object yaw is unwrapped, and the tracker's jumps by multiples of pi/2 (a square looks the
//   same turned by 90 degrees) are removed: a step of more than 0.5 rad between samples ~4 ms apart
//   is physically impossible, so it is snapped to the nearest multiple of pi/2 and subtracted;
// - the tip's yaw is meaningless: the finger pose's theta is set to 0;
// - a frozen force sensor (the rect1 files: 2 to 4 distinct values with spikes) is detected and
//   the force stream dropped, with the reason in `force_fault`;
// - the contact phase (files start and end without contact) is found from the force magnitude,
//   or, when the force sensor is frozen, from the object's motion (it moves only while pushed,
//   and comes to rest at its final pose when the finger leaves it).
//   Not from the shapes' separation: with time-interpolated poses the probe stays 1 to 2 mm from
//   the ellip1 block throughout its pushes (stream latencies, calibration), so a distance test
//   is unreliable on this data.
//
//   io::MitReadOptions options;
//   options.trim_to_contact = true;
//   io::MitRecording rec = io::ReadMitPush("motion_surface=abs_shape=rect1_....h5", options);
//   if (rec.force_frozen) std::cerr << rec.force_fault << "\n";
#include <pushgraph/geometry/shape.h>
#include <pushgraph/push/trajectory.h>

#include <string>
#include <vector>

namespace pushgraph::io {

struct MitReadOptions {
  /// Force magnitude that means contact (N). For a known object, MitContactForce(mass, mu):
  /// 0.3 N, or a quarter of a light object's friction load.
  double contact_force = 0.3;
  double moving_speed = 2e-3;         ///< object speed that means it is pushed, without force (m/s)
  /// Without force: the contact phase ends where the object stays within this of its final pose
  /// (m, translation plus 0.05 m times the rotation).
  double rest_tolerance = 1e-3;
  double max_yaw_step = 0.5;          ///< larger steps between samples are tracker jumps (rad)
  int frozen_max_distinct = 8;        ///< at most this many distinct force values: frozen
  bool trim_to_contact = false;       ///< keep only samples within the contact phase
};

struct MitRecording {
  std::string file;
  push::Streams streams;     ///< object_pose, finger_pose, force (probe on object)
  bool force_frozen = false;
  std::string force_fault;            ///< why the force stream was dropped
  double contact_start = 0.0, contact_end = 0.0;  ///< contact phase (recording's own clock)
  bool contact_found = false;
  int samples_reordered = 0;          ///< samples that were out of time order
  int duplicates_dropped = 0;
  int yaw_jumps_repaired = 0;
  std::vector<std::string> notes;     ///< one line per repair, for the user
};

/// The contact threshold for an object of `mass` (kg) on a table of friction `mu_surface`: 0.3 N
/// (the dataset's objects need 1 N or more to slide), or a quarter of the friction load
/// mu m g when that is less (below 0.49 kg at mu 0.25), and at least 0.05 N (the estimator's
/// contact_force_threshold). A fixed 0.3 N cut a 45 g object's push to 20 ms, or found none.
double MitContactForce(double mass, double mu_surface);

/// Reads a .h5 (HDF5) or .json recording, chosen by the file's extension. Throws IoError naming
/// the file and dataset/row for missing datasets, wrong shapes, non-finite values, empty streams.
MitRecording ReadMitPush(const std::string& path, const MitReadOptions& options = {});

/// The recording as a trajectory: the measured streams, and the same clean streams as ground
/// truth (the dataset's motion capture is the paper's ground truth).
push::Trajectory MitToTrajectory(const MitRecording& recording, const push::ObjectDescription& object,
                                          const push::FingerDescription& finger);

}  // namespace pushgraph::io
