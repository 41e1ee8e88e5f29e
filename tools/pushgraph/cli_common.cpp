#include "cli_common.h"

#include <pushgraph/graph/registration.h>
#include <pushgraph/io/errors.h>
#include <pushgraph/io/footprint.h>
#include <pushgraph/io/points_csv.h>
#include <pushgraph/limit_surface/support.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include <signal.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

namespace pushgraph::cli {

std::string DefaultDataDir() {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("PUSHGRAPH_DATA_DIR"); env && *env) return env;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share" / "pushgraph";
    if (fs::exists(installed / "shapes", ec)) return installed.string();
  }
#ifdef PUSHGRAPH_DATA_DIR
  return PUSHGRAPH_DATA_DIR;
#else
  return "data";
#endif
}

std::vector<double> ParseNumbers(const std::string& text, std::size_t count, const std::string& what) {
  try {
    return io::ParseNumberList(text, count, what);
  } catch (const io::IoError& e) {
    throw CliError(e.what());  // a flag's value: exit status 2, like every usage error
  }
}

geometry::Pose2 ParsePose(const std::string& text, const std::string& what) {
  const std::vector<double> v = ParseNumbers(text, 3, what + " (X,Y,THETA)");
  return {v[0], v[1], v[2]};
}

std::string FormatDouble(double value) {
  // The same text as printf's %.17g, several times faster (std::to_chars, no locale).
  char buffer[40];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value + 0.0, std::chars_format::general, 17);  // + 0.0 prints -0 as 0
  return std::string(buffer, result.ptr);
}

namespace {

// Two names of one file: equivalent() when both exist, else the same normalized absolute path.
bool SameFile(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) {
    const bool same = fs::equivalent(a, b, ec);
    if (!ec) return same;
  }
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return ca.lexically_normal() == cb.lexically_normal();
}

}  // namespace

void CheckOutputsAreNew(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs) {
  namespace fs = std::filesystem;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const NamedPath& out = outputs[i];
    if (out.path.empty()) continue;
    // Where it goes, before the work: a missing folder was said only after a 7.8 s estimate.
    std::error_code ec;
    if (fs::is_directory(out.path, ec))
      throw CliError(out.what + " " + out.path + " is a folder: give a file name in it");
    const fs::path folder = fs::path(out.path).has_parent_path() ? fs::path(out.path).parent_path() : fs::path(".");
    if (!fs::is_directory(folder, ec))
      throw CliError(out.what + " " + out.path + ": its folder " + folder.string() +
                     (ec && ec != std::errc::no_such_file_or_directory ? " cannot be read (" + ec.message() + ")"
                                                                       : " does not exist (create it first)"));
    // A symbolic link (/dev/stdout) is written through to what it names, which the writer finds.
    const bool link = fs::is_symlink(fs::symlink_status(out.path, ec));
    const fs::file_status target = fs::status(out.path, ec);
    const bool written_into = link || fs::is_character_file(target) || fs::is_fifo(target) || fs::is_socket(target);
    if (!written_into && ::access(folder.c_str(), W_OK | X_OK) != 0)
      throw CliError(out.what + " " + out.path + ": its folder " + folder.string() + " is not writable (" +
                     std::strerror(errno) + ")");
    for (const NamedPath& in : inputs) {
      if (!in.path.empty() && SameFile(out.path, in.path))
        throw CliError(out.what + " " + out.path + " is the input " + in.what + " " + in.path +
                       ": writing it would destroy the input; choose another output file");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (!outputs[j].path.empty() && SameFile(out.path, outputs[j].path))
        throw CliError(out.what + " " + out.path + " is also the output " + outputs[j].what +
                       ": one would overwrite the other; choose two files");
    }
  }
}

std::string DumpJson(const nlohmann::json& value, int indent) {
  // nlohmann prints the shortest round-trip representation, which is exact.
  // Paths in it need not be UTF-8 (a Latin-1 file name): such bytes become U+FFFD, not an error.
  return value.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::vector<std::string> JoinNegativeValues(const std::vector<std::string>& args,
                                            const std::vector<std::string>& value_options) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    const bool takes_value =
        std::find(value_options.begin(), value_options.end(), arg) != value_options.end();
    if (takes_value && i + 1 < args.size()) {
      const std::string& next = args[i + 1];
      const bool negative_number =
          next.size() >= 2 && next[0] == '-' && (std::isdigit(static_cast<unsigned char>(next[1])) || next[1] == '.');
      if (negative_number) {
        out.push_back(arg + "=" + next);
        ++i;
        continue;
      }
    }
    out.push_back(arg);
  }
  return out;
}

CLI::Option* AddSeedOption(CLI::App* app, std::uint64_t* seed, const std::string& help) {
  return app
      ->add_option_function<std::string>(
          "--seed",
          [seed](const std::string& text) {
            std::uint64_t value = 0;
            const char* end = text.data() + text.size();
            const auto [ptr, ec] = std::from_chars(text.data(), end, value);
            if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || ec != std::errc() || ptr != end)
              throw CLI::ValidationError("--seed", "'" + text + "' is not an integer from 0 to 18446744073709551615");
            *seed = value;
          },
          help)
      ->type_name("UINT")
      ->default_str(std::to_string(*seed));
}

void AddAlignShapeOption(CLI::App* sub, std::string* value) {
  sub->add_option("--align-shape", *value,
                  "Shape registration: auto (check the shape against the data, align it when it does not fit), "
                  "on (always align), off (never; the check still warns). Default: the config's align_shape, auto")
      ->check(CLI::IsMember({"auto", "on", "off"}));
}

graph::EstimatorConfig::AlignShape ParseAlignShape(const std::string& value) {
  using A = graph::EstimatorConfig::AlignShape;
  if (value == "on") return A::kOn;
  if (value == "off") return A::kOff;
  if (value == "auto") return A::kAuto;
  throw CliError("--align-shape: expected auto, on or off, got " + value);
}

CLI::Validator FiniteNumber(double min, bool inclusive, const std::string& rule, double max) {
  return CLI::Validator(
      [min, inclusive, rule, max](std::string& text) -> std::string {
        std::size_t used = 0;
        double v = 0.0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        const bool number = used > 0 && used == text.size();
        if (!number || !std::isfinite(v) || (inclusive ? !(v >= min) : !(v > min)) || v > max) {
          return "must be a finite number " + rule + ", got " + text;
        }
        return std::string();
      },
      rule);
}

CLI::Validator MassValue() {
  return FiniteNumber(0.0, false, "in (0, 1e6] (kg)", limit_surface::kMaxMass);
}

CLI::Validator FrictionValue(bool zero_allowed) {
  return FiniteNumber(0.0, zero_allowed, zero_allowed ? "in [0, 10]" : "in (0, 10]", limit_surface::kMaxFriction);
}

namespace {

// A mesh read as `pushgraph footprint MESH` would (up z, metres, the file's own frame), said on
// stderr, since another axis or scale needs that command. A finger mesh that is a prism along x
// or y only (a probe's cylinder lying along y, as the MIT tip.obj) is meant by its cross-section:
// seen along z it would be its side view (footprint reports the prism axes after its union, so
// such a file is read twice).
geometry::Shape LoadMeshArgument(const std::string& path, const std::string& what, std::vector<std::string>* warnings,
                                 MeshReadings* other_readings) {
  // Messages name the path given (a piped input is read from a temporary copy).
  const std::string shown = WithGivenInputPaths(path);
  io::FootprintOptions options;
  io::FootprintReport report;
  geometry::Shape shape;
  try {
    shape = io::MeshFootprint(path, options, &report);
  } catch (const io::IoError&) {
    // A flat drawing has one reading only: across the plane it is drawn in (its outline drawn in
    // the x-z plane was refused with "--up y reads it", a flag estimate does not have).
    if (!report.flat_axis || *report.flat_axis == options.up) throw;
    options.up = *report.flat_axis;
    report = {};
    shape = io::MeshFootprint(path, options, &report);
  }
  // Objects keep z: a can lying along x is pushed by its 100 x 60 mm side, not its round end.
  const bool finger = what.find("finger") != std::string::npos;
  const auto& prisms = report.prism_axes;
  if (finger && prisms.size() == 1 && prisms[0] != io::UpAxis::kZ) {
    options.up = prisms[0];
    report = {};
    shape = io::MeshFootprint(path, options, &report);
  }
  // An object that is a prism along x or y: its cross-sections, for the recording to choose from.
  if (!finger && other_readings) {
    for (const io::UpAxis axis : prisms) {
      if (axis == options.up) continue;
      io::FootprintOptions across = options;
      across.up = axis;
      other_readings->shapes.push_back(io::MeshFootprint(path, across));
      other_readings->up.push_back(axis == io::UpAxis::kX ? "x" : axis == io::UpAxis::kY ? "y" : "z");
    }
  }
  const char* up = options.up == io::UpAxis::kX ? "x" : options.up == io::UpAxis::kY ? "y" : "z";
  int holes = 0;
  for (const geometry::Polygon& p : shape.polygons()) holes += static_cast<int>(p.holes.size());
  const geometry::Box2 box = shape.bounds();
  std::fprintf(stderr,
               "pushgraph: %s %s: the mesh's footprint along %s%s, in its own frame and units (%zu polygon(s), %d "
               "hole(s), %.4g x %.4g m); another up axis, scale or frame: pushgraph footprint %s --up/--scale/"
               "--transform -o SHAPE.json\n",
               what.c_str(), shown.c_str(), up,
               options.up == io::UpAxis::kZ ? ""
               : report.flat_axis           ? " (an outline drawn flat across it)"
                                            : " (a prism along it: its cross-section)",
               shape.polygons().size(), holes, box.max.x() - box.min.x(),
               box.max.y() - box.min.y(), shown.c_str());
  for (std::string w : report.warnings) {
    // footprint's own flags (--object names the shape file here, and there is no --up): the command.
    for (const std::string flag : {"--object NAME", "--up x", "--up y", "--up z"}) {
      if (const std::size_t at = w.find(flag); at != std::string::npos)
        w.replace(at, flag.size(), "pushgraph footprint " + shown + " " + flag + " -o SHAPE.json");
    }
    if (other_readings && !other_readings->shapes.empty() && w.find("its side view") != std::string::npos) {
      other_readings->side_view = w;  // the caller's recording decides whether it is one
      continue;
    }
    std::fprintf(stderr, "pushgraph: warning: %s %s: %s\n", what.c_str(), shown.c_str(), w.c_str());
    if (warnings) warnings->push_back(what + " " + shown + ": " + w);
  }
  if (finger) {
    // A tessellated cylinder is the disk it approximates (geometry::TessellatedDisk; the
    // estimator does the same for any finger shape unless tessellated_finger_as_disk is false).
    if (const std::optional<geometry::TessellatedDiskFit> fit = geometry::TessellatedDisk(shape)) {
      const geometry::Vec2 centre = fit->disk.polygons()[0].outer[0];
      std::fprintf(stderr,
                   "pushgraph: %s %s: its footprint is a regular %zu-gon, a tessellated cylinder: used as the disk "
                   "of radius %.4g mm at (%.3f, %.3f) mm it approximates (a polygonal finger solves 6 to 13x "
                   "slower; to keep the polygon: pushgraph footprint %s%s -o SHAPE.json, and "
                   "\"tessellated_finger_as_disk\": false in --config)\n",
                   what.c_str(), shown.c_str(), fit->corners, 1e3 * fit->disk.radius(),
                   1e3 * centre.x(), 1e3 * centre.y(), shown.c_str(),
                   options.up == io::UpAxis::kZ ? "" : (std::string(" --up ") + up).c_str());
      return fit->disk;
    }
  }
  return shape;
}

// A length in the file's own units, as printed in messages.
std::string FormatSize(double size) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", size);
  return text;
}

}  // namespace

namespace {

// The copies of piped inputs (ReadOnceInput), removed at exit.
struct PipedInputs {
  std::filesystem::path dir;
  std::vector<std::pair<std::string, std::string>> copies;  // temporary path, given path
  ~PipedInputs() {
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
};
PipedInputs& Piped() {
  static PipedInputs piped;
  return piped;
}

// The same paths for a signal handler, which may only call async-signal-safe functions (unlink,
// rmdir, raise): an interrupted or terminated run (Ctrl-C in a long estimate) left its copies
// in /tmp. A path is written before the count that publishes it. SIGKILL cannot be caught.
constexpr int kMaxSignalPaths = 16;
char signal_files[kMaxSignalPaths][4096];
char signal_dir[4096];
volatile std::sig_atomic_t signal_file_count = 0;

extern "C" void RemovePipedCopiesAndDie(int sig) {
  for (int i = 0; i < signal_file_count; ++i) ::unlink(signal_files[i]);
  if (signal_dir[0] != '\0') ::rmdir(signal_dir);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

// Copies `path` into `slot` when it fits (with its terminating zero).
bool CopyForSignal(const std::string& path, char* slot) {
  if (path.size() >= sizeof signal_dir) return false;
  std::memcpy(slot, path.c_str(), path.size() + 1);
  return true;
}

// Once, when the folder is made: the handler for the signals that end a run, where the user
// has not set them aside (nohup ignores SIGHUP: it stays ignored).
void CleanUpOnSignals(const std::string& dir) {
  if (!CopyForSignal(dir, signal_dir)) return;
  for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE}) {
    struct sigaction current {};
    if (::sigaction(sig, nullptr, &current) != 0 || current.sa_handler != SIG_DFL) continue;
    struct sigaction action {};
    action.sa_handler = RemovePipedCopiesAndDie;
    sigemptyset(&action.sa_mask);
    ::sigaction(sig, &action, nullptr);
  }
}

}  // namespace

CLI::Validator ReadOnceInput() {
  return CLI::Validator(
      [](std::string& path) -> std::string {
        namespace fs = std::filesystem;
        std::error_code ec;
        const fs::file_status st = fs::status(path, ec);
        if (ec || fs::is_regular_file(st) || fs::is_directory(st) || !fs::exists(st)) return "";  // the readers say what is wrong
        struct stat input_stat {};
        const bool stated = ::stat(path.c_str(), &input_stat) == 0;
        // A device is no input, but for this command's standard input at a terminal (/dev/zero
        // was read, or copied, until memory or /tmp filled).
        if (fs::is_character_file(st) || fs::is_block_file(st)) {
          struct stat in_stat {};
          const bool is_stdin = stated && ::fstat(STDIN_FILENO, &in_stat) == 0 && in_stat.st_dev == input_stat.st_dev &&
                                in_stat.st_ino == input_stat.st_ino;
          return is_stdin ? "" : path + " is a device, not an input file";
        }
        if (!fs::is_fifo(st) && !fs::is_socket(st)) return "";
        // This command's own output or error stream is no input (--config /dev/stdout into a pipe
        // waited forever for its own output).
        if (stated) {
          for (const int fd : {STDOUT_FILENO, STDERR_FILENO}) {
            struct stat out_stat {};
            if (::fstat(fd, &out_stat) == 0 && out_stat.st_dev == input_stat.st_dev && out_stat.st_ino == input_stat.st_ino)
              return path + " is this command's own " + (fd == STDOUT_FILENO ? "standard output" : "standard error") +
                     ", not an input";
          }
        }
        std::ifstream in(path, std::ios::binary);
        if (!in) return "";
        PipedInputs& piped = Piped();
        if (piped.dir.empty()) {
          // mkdtemp replaces the six X's with a unique name and creates the folder (mode 0700).
          std::string templ = (fs::temp_directory_path(ec) / "pushgraph-input-XXXXXX").string();
          if (ec || ::mkdtemp(templ.data()) == nullptr) return "cannot copy the piped input " + path + " to a temporary file";
          piped.dir = templ;
          CleanUpOnSignals(templ);
        }
        const fs::path copy = piped.dir / (std::to_string(piped.copies.size()) + "-" + fs::path(path).filename().string());
        if (signal_file_count < kMaxSignalPaths && CopyForSignal(copy.string(), signal_files[signal_file_count])) {
          signal_file_count = signal_file_count + 1;
        }
        std::ofstream out(copy, std::ios::binary);
        // At most 4 GiB: no input of this tool is larger, and an endless producer must not fill /tmp.
        constexpr std::uint64_t kMaxPipedBytes = std::uint64_t{4} << 30;
        std::vector<char> buffer(1 << 16);
        std::uint64_t total = 0;
        while (in.read(buffer.data(), static_cast<std::streamsize>(buffer.size())) || in.gcount() > 0) {
          out.write(buffer.data(), in.gcount());
          total += static_cast<std::uint64_t>(in.gcount());
          if (total > kMaxPipedBytes) {
            out.close();
            std::error_code remove_ec;
            fs::remove(copy, remove_ec);
            return "the piped input " + path + " goes on beyond 4 GiB: no input of pushgraph is that large";
          }
        }
        out.close();
        if (!out) return "cannot copy the piped input " + path + " to " + copy.string();
        piped.copies.emplace_back(copy.string(), path);
        path = copy.string();
        return "";
      },
      "", "ReadOnceInput");
}

std::string WithGivenInputPaths(std::string text) {
  for (const auto& [copy, given] : Piped().copies) {
    for (std::size_t at = text.find(copy); at != std::string::npos; at = text.find(copy, at + given.size())) text.replace(at, copy.size(), given);
  }
  return text;
}

void WarnShapeUnits(const geometry::Shape& shape, const std::string& what, const std::string& path) {
  // Messages name the path given (a piped input is read from a temporary copy).
  const std::string shown = WithGivenInputPaths(path);
  if (const auto units = io::ShapeUnitsWarning(shape, 1.0, "pushgraph footprint " + shown + " --scale "))
    std::fprintf(stderr, "pushgraph: warning: %s %s: %s\n", what.c_str(), shown.c_str(), units->c_str());
}

geometry::Shape LoadShapeArgument(const std::string& path, const std::string& what, std::vector<std::string>* warnings,
                                  MeshReadings* other_readings) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  try {
    // Meshes: OBJ, and what CAD tools export besides (STL, PLY, OFF); everything else is shape JSON.
    if (extension == ".obj" || extension == ".stl" || extension == ".ply" || extension == ".off")
      return LoadMeshArgument(path, what, warnings, other_readings);
    return geometry::LoadShapeJson(path);
  } catch (const std::exception& e) {
    std::string hint;
    if (extension != ".json" && std::string(e.what()).find("malformed JSON") != std::string::npos)
      hint = " (shape files are JSON from pushgraph footprint; meshes named .obj, .stl, .ply or .off are read directly)";
    throw CliError(what + " " + path + ": " + e.what() + hint);
  }
}

std::string ChooseObjectReading(const std::string& path, const MeshReadings& readings, const graph::EstimatorConfig& config,
                                push::Trajectory* trajectory, std::vector<std::string>* warnings) {
  // Messages name the path given (a piped input is read from a temporary copy).
  const std::string shown = WithGivenInputPaths(path);
  if (readings.shapes.empty()) return "";
  auto say = [&](const std::string& text) {
    std::fprintf(stderr, "pushgraph: warning: --object %s: %s\n", shown.c_str(), text.c_str());
    if (warnings) warnings->push_back("--object " + shown + ": " + text);
  };
  if (config.align_shape == graph::EstimatorConfig::AlignShape::kOff) {
    if (!readings.side_view.empty()) say(readings.side_view);
    return "";
  }
  std::vector<geometry::Shape> candidates{trajectory->object.shape};
  candidates.insert(candidates.end(), readings.shapes.begin(), readings.shapes.end());
  std::vector<std::string> names{"along z"};
  for (const std::string& axis : readings.up) names.push_back("along " + axis);
  const graph::ShapeReadingChoice choice =
      graph::ChooseShapeReading(*trajectory, candidates, graph::RegistrationOptionsFor(config), names);
  const std::string& reason = choice.reason;
  if (choice.index > 0) {
    const std::string& up = readings.up[choice.index - 1];
    trajectory->object.shape = candidates[choice.index];
    const geometry::Box2 box = trajectory->object.shape.bounds();
    say("the mesh is a prism along " + up + " (a y-up export, or an object lying on its side), and the recording's "
        "contacts fit its cross-section along " + up + ", not its footprint along z (its side view): estimated with the "
        "cross-section (" + FormatSize(box.max.x() - box.min.x()) + " x " + FormatSize(box.max.y() - box.min.y()) +
        " in the file's units; " + reason + "); pushgraph footprint " + shown + " --up " + up + " -o SHAPE.json saves it");
    return up;
  }
  if (!readings.side_view.empty() && !(choice.checked[0] && choice.checks[0].fits))
    say(readings.side_view + (reason.empty() ? "" : " (the contacts fit no reading clearly better: " + reason + ")"));
  return "";
}

}  // namespace pushgraph::cli
