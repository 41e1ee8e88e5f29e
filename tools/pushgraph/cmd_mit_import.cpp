// pushgraph mit-import RECORDING.h5|.json --object SHAPE.json --finger SHAPE.json --mass KG
//   --mu-surface MU [--mu-contact MU] [--no-trim] -o TRAJECTORY.json
// Reads an MIT pushing-dataset recording, repairs it (see docs/formats.md) and writes a
// pushgraph trajectory file; prints what was repaired on stderr. Like `estimate RECORDING.h5`, it
// keeps only the contact phase unless --no-trim is given, so both estimate the same samples.
#include "cli_common.h"

#include <pushgraph/io/mit_push.h>
#include <pushgraph/io/trajectory_json.h>

#include <iostream>

namespace pushgraph::cli {

void RegisterMitImport(CLI::App& app) {
  auto* cmd = app.add_subcommand("mit-import", "Convert an MIT pushing-dataset recording (HDF5 or JSON) to a trajectory file");
  struct Args {
    std::string recording, object, finger, output;
    double mass = 0.0, mu_surface = 0.0, mu_contact = 0.25;
    bool trim = true;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("RECORDING", a->recording, "Recording (.h5 or .json)")->required()
      ->transform(ReadOnceInput());
  cmd->add_option("--object", a->object, "Object shape JSON (e.g. from pushgraph footprint) or mesh (OBJ, STL, PLY, OFF)")
      ->required()
      ->transform(ReadOnceInput());
  cmd->add_option("--finger", a->finger, "Finger shape JSON or mesh (OBJ, STL, PLY, OFF)")->required()
      ->transform(ReadOnceInput());
  cmd->add_option("--mass", a->mass, "Object mass (kg)")->required()->check(MassValue());
  cmd->add_option("--mu-surface", a->mu_surface, "Object-table friction coefficient")->required()->check(FrictionValue(false));
  cmd->add_option("--mu-contact", a->mu_contact, "Finger-object friction coefficient")
      ->check(FrictionValue(true))
      ->capture_default_str();
  cmd->add_flag("--trim,!--no-trim", a->trim,
                "Keep only the contact phase, as `estimate RECORDING.h5` does (the default); --no-trim keeps every sample")
      ->capture_default_str();
  cmd->add_option("-o,--output", a->output, "Trajectory JSON to write")->required();
  cmd->callback([a] {
    CheckOutputsAreNew({{"RECORDING", a->recording}, {"--object", a->object}, {"--finger", a->finger}}, {{"-o", a->output}});
    if (!(a->mass > 0.0)) throw CliError("--mass must be > 0");
    if (!(a->mu_surface >= 0.0) || !(a->mu_contact >= 0.0)) throw CliError("friction coefficients must be >= 0");
    io::MitReadOptions options;
    options.trim_to_contact = a->trim;
    options.contact_force = io::MitContactForce(a->mass, a->mu_surface);
    const io::MitRecording rec = io::ReadMitPush(a->recording, options);
    push::ObjectDescription object;
    MeshReadings readings;  // a y-up export's cross-section, when the recording's contacts fit it
    object.shape = LoadShapeArgument(a->object, "--object", nullptr, &readings);
    object.mass = a->mass;
    object.mu_surface = a->mu_surface;
    push::FingerDescription finger{LoadShapeArgument(a->finger, "--finger"), a->mu_contact};
    // As simulate and footprint do: a mesh in millimetres made a 90 m block here without a word.
    WarnShapeUnits(object.shape, "--object", a->object);
    WarnShapeUnits(finger.shape, "--finger", a->finger);
    push::Trajectory trajectory = io::MitToTrajectory(rec, object, finger);
    ChooseObjectReading(a->object, readings, graph::EstimatorConfig{}, &trajectory, nullptr);
    io::SaveTrajectoryJson(trajectory, a->output);
    for (const std::string& note : rec.notes) std::cerr << "mit-import: " << note << "\n";
    std::cerr << "mit-import: " << rec.streams.object_pose.size() << " object, " << rec.streams.finger_pose.size()
              << " finger, " << rec.streams.force.size() << " force samples";
    if (rec.contact_found)
      std::cerr << "; contact " << FormatDouble(rec.contact_start) << " to " << FormatDouble(rec.contact_end);
    std::cerr << "\n";
  });
}

}  // namespace pushgraph::cli
