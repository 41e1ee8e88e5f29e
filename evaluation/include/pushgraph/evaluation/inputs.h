#pragma once
// The evaluation's inputs: what a file holds (a pushgraph trajectory or an MIT recording), the
// MIT objects and their meshes, the paper's noise added to clean streams, simulated pushes, and
// the one loader used by `pushgraph estimate` and the evaluation.
//
//   evaluation::InputOverrides given;                    // e.g. from --object/--finger/--mass/--mu
//   given.object_shape = geometry::LoadShapeJson("rect1.json");
//   given.finger_shape = geometry::Shape::Disk(0.00235);
//   given.mass = 0.8374;  given.mu_surface = 0.35;
//   std::vector<std::string> notes;
//   push::Trajectory t = evaluation::LoadEstimationInput("push.h5", given, &notes);
//   push::Trajectory noisy = evaluation::AddNoise(t, evaluation::MakePaperNoise(push::NoiseKind::kGaussian), 7);
//
// Errors: EvaluationError naming the file (io::IoError from the readers passes through).
#include <pushgraph/evaluation/errors.h>
#include <pushgraph/geometry/shape.h>
#include <pushgraph/push/noise.h>
#include <pushgraph/push/trajectory.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pushgraph::evaluation {

/// Noise added to the clean streams (per axis, standard deviations). The paper's Sec. IV values
/// are 0.5 cm and 0.5 N; its 0.5 rad for orientations (29 degrees) is implausible for a vision
/// tracker and would make orientation unobservable from the poses, so 0.05 rad is used.
struct PaperNoise {
  double position = 0.005;  ///< m: object, finger and contact point
  double rotation = 0.05;   ///< rad: object orientation (the finger's angle is not measured)
  double force = 0.5;       ///< N
};

/// Noise model for `kind` (kGaussian or kBimodal) with the given sigmas on every stream.
push::NoiseModel MakePaperNoise(push::NoiseKind kind, const PaperNoise& sigmas = {});

/// The trajectory with ground truth = its clean streams (its ground truth when it has one, else
/// its measured streams) and measured = clean + noise (push::ApplyNoise with `seed`);
/// measurement_sigmas set to the noise's sigmas. Throws EvaluationError for a trajectory without ground
/// truth whose measurement_sigmas say its streams are already noisy (noise added twice, metrics
/// scored against noisy streams).
push::Trajectory AddNoise(const push::Trajectory& trajectory, const push::NoiseModel& noise,
                                   std::uint64_t seed);

/// What a file holds, decided by its content: HDF5 signature or MIT arrays
/// (tip_pose/object_pose/ft_wrench) -> kMitRecording; {"format": "pushgraph-trajectory-1"} ->
/// kTrajectory. Throws EvaluationError naming the file when it is neither (or cannot be read).
enum class InputKind { kMitRecording, kTrajectory };
InputKind DetectInputKind(const std::string& path);

/// An object and the finger that pushes it (an MIT object and its probe, or any other): the
/// push module's descriptions, as every trajectory carries them.
struct ObjectModel {
  push::ObjectDescription object;
  push::FingerDescription finger{geometry::Shape(), 0.25};
  /// Other readings of the object's mesh besides its footprint along z: its cross-sections when
  /// it is a prism along x or y (a y-up export, or an object lying on its side), with their axes
  /// ("x", "y"). RegisterGroups lets the group's recordings choose (graph::ChooseShapeReading).
  std::vector<geometry::Shape> other_readings;
  std::vector<std::string> reading_axes;
};

/// Masses of the dataset's eleven objects from its own shape table: rect1 0.8374, rect2 1.045,
/// rect3 1.2508, ellip1 0.8937, ellip2 1.1104, ellip3 1.3338, tri1 0.8028, tri2 0.9826, tri3
/// 1.1326, hex 0.9827, butter 1.1974 kg. nullopt for other names.
std::optional<double> MitObjectMass(const std::string& object_name);

/// The MIT object named `object_name` with its footprint from `mesh_dir`/NAME.obj (up z), the
/// probe a disk of the radius of `mesh_dir`/tip.obj (a cylinder along y: 4.7 mm), the dataset mass, mu_surface 0.35 (the apparent
/// friction of the ellip1 recordings, dataset README) and mu_contact 0.25. Throws EvaluationError when
/// the name or a mesh is unknown.
ObjectModel MitObjectModel(const std::string& object_name, const std::string& mesh_dir);

/// What replaces a file's object and finger (the command line's --object, --finger, --mass,
/// --mu). An MIT recording carries neither shape nor mass: it needs all four.
struct InputOverrides {
  std::optional<geometry::Shape> object_shape, finger_shape;
  std::optional<double> mass, mu_surface;
  /// An MIT recording: keep only its contact phase (false: every sample, the finger's approach
  /// and the rest after the push included).
  bool trim_to_contact = true;
};

/// A trajectory file or an MIT recording (DetectInputKind) as the estimator's input: a trajectory
/// with the overrides applied; a recording trimmed to its contact phase (refused when nothing was
/// pushed), time stamps its own, object and finger from the overrides (mu_contact 0.25). The
/// readers' notes (rows sorted, samples dropped) go to `notes`; `kind` receives the input's kind.
push::Trajectory LoadEstimationInput(const std::string& path, const InputOverrides& overrides,
                                     std::vector<std::string>* notes = nullptr, InputKind* kind = nullptr);

/// An MIT recording trimmed to its contact phase (force above io::MitContactForce of the model's
/// object; refused when nothing was pushed; `trim` false keeps every sample), each stream
/// decimated to at most one sample per 1/rate s (0: every sample), with `model`'s object and
/// finger. Notes as above.
push::Trajectory ReadMitTrajectory(const std::string& path, const ObjectModel& model, double rate,
                                   std::vector<std::string>* notes = nullptr, bool trim = true);

/// Simulated pushes: the finger pushes `shape` straight over `push_distance` at `speed`; push
/// direction uniform in [0, 2 pi) and sideways offset uniform in +-offset_fraction of the shape's
/// smaller half-extent, drawn from a generator seeded with (seed, index). Rates: the paper's
/// Sec. V (object 25 Hz, finger/contact/force 250 Hz).
struct SimulationSpec {
  int count = 0;
  std::string name = "sim";  ///< group name in the tables
  push::ObjectDescription object;
  push::FingerDescription finger{geometry::Shape(), 0.25};
  double push_distance = 0.05;  ///< m
  double speed = 0.05;          ///< m/s
  double offset_fraction = 0.5;
  double standoff = 0.005;  ///< m
  /// Every contact of the finger (push::PushPlan::multi_contact): a finger pushed into a notch
  /// wedges and touches both walls, and the estimator gets two contact rows at those times.
  bool multi_contact = false;
};

/// What push `index` of a multi-contact group (SimulationSpec::multi_contact) is, in a cycle of
/// four: one finger (0, 2: the single-contact group's push on the same line, which may wedge in a
/// notch), two fingers side by side (1: two copies of the finger moving together, 0.8 of the
/// object's smaller half-extent apart, either side of the push line), and a flat pusher
/// (3: a bar 1.6 half-extents long and as thick as the finger, its face across the push).
enum class MultiContactPushKind { kOneFinger, kTwoFingers, kFlatPusher };
MultiContactPushKind MultiContactPushKindOf(int index);
/// "one-finger", "two-fingers", "flat-pusher".
const char* MultiContactPushKindName(MultiContactPushKind kind);

/// The clean (noise-free) simulated push number `index` (with spec.multi_contact: of the kind
/// MultiContactPushKindOf(index), on the push line of the single-contact group's push `index`).
push::Trajectory SimulatedPush(const SimulationSpec& spec, int index, std::uint64_t seed);

/// Files from paths, folders (recursively: *.h5, *.hdf5, *.json) and glob patterns, sorted and
/// without duplicates. Throws EvaluationError for a path or pattern that matches no file.
std::vector<std::string> ExpandInputs(const std::vector<std::string>& patterns);

}  // namespace pushgraph::evaluation
