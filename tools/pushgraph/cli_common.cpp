#include "cli_common.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

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
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size()) {
      throw CliError(what + ": '" + item + "' is not a number (expected " + std::to_string(count) +
                     " comma-separated numbers, got '" + text + "')");
    }
    if (!std::isfinite(value)) throw CliError(what + ": '" + item + "' is not finite");
    values.push_back(value);
  }
  if (!text.empty() && text.back() == ',') values.push_back(NAN);  // forces the count error below
  if (values.size() != count) {
    throw CliError(what + ": expected " + std::to_string(count) + " comma-separated numbers, got '" +
                   text + "'");
  }
  return values;
}

geometry::Pose2 ParsePose(const std::string& text, const std::string& what) {
  const std::vector<double> v = ParseNumbers(text, 3, what + " (X,Y,THETA)");
  return {v[0], v[1], v[2]};
}

std::string FormatDouble(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", value + 0.0);  // + 0.0 prints -0 as 0
  return buffer;
}

std::string DumpJson(const nlohmann::json& value, int indent) {
  // nlohmann prints the shortest round-trip representation, which is exact.
  return value.dump(indent);
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

CLI::Validator FiniteNumber(double min, bool inclusive, const std::string& rule) {
  return CLI::Validator(
      [min, inclusive, rule](std::string& text) -> std::string {
        std::size_t used = 0;
        double v = 0.0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        const bool number = used > 0 && used == text.size();
        if (!number || !std::isfinite(v) || (inclusive ? !(v >= min) : !(v > min))) {
          return "must be a finite number " + rule + ", got " + text;
        }
        return std::string();
      },
      rule);
}

}  // namespace pushgraph::cli
