// Points CSV files and comma-separated number lists (header points_csv.h).
#include <pushgraph/io/points_csv.h>
#include <pushgraph/geometry/types.h>

#include <pushgraph/io/errors.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string_view>

namespace pushgraph::io {
namespace {

std::string Trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  return s.substr(begin, s.find_last_not_of(" \t\r") - begin + 1);
}

// std::from_chars on the whole item (after leading spaces), with the leading '+' that std::stod
// accepts; false where it does not parse the whole item (std::stod then decides, so hexadecimal
// input keeps working).
bool ParseFast(const std::string& item, double* value) {
  const char* begin = item.data();
  const char* end = begin + item.size();
  while (begin < end && std::isspace(static_cast<unsigned char>(*begin))) ++begin;
  if (begin < end && *begin == '+') {
    ++begin;
    if (begin < end && (*begin == '-' || *begin == '+')) return false;  // "+-1" is not a number
  }
  if (begin == end || std::isspace(static_cast<unsigned char>(*begin))) return false;
  const auto [ptr, ec] = std::from_chars(begin, end, *value);
  return ec == std::errc() && ptr == end;
}

}  // namespace

std::vector<double> ParseNumberList(const std::string& text, std::size_t count, const std::string& what) {
  std::vector<double> values;
  // Split on commas as std::getline would (no item after a trailing comma; none for "").
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    // Spaces around an item are the writer's layout ("0.01 , 0.02"), not part of the number.
    const std::string item = Trim(text.substr(start, comma - start));
    start = comma + 1;
    std::size_t used = item.size();
    double value = 0.0;
    if (!ParseFast(item, &value)) {
      try {
        value = std::stod(item, &used);
      } catch (const std::out_of_range&) {
        throw IoError(what + ": '" + item + "' is outside the range of a double (about 1e-308 to 1e308)");
      } catch (const std::exception&) {
        used = 0;
      }
    }
    if (used == 0 || used != item.size()) {
      throw IoError(what + ": '" + item + "' is not a number (expected " + std::to_string(count) +
                    " comma-separated numbers, got '" + text + "')");
    }
    if (!std::isfinite(value)) throw IoError(what + ": '" + item + "' is not finite");
    values.push_back(value);
  }
  if (!text.empty() && text.back() == ',') values.push_back(NAN);  // forces the count error below
  if (values.size() != count) {
    throw IoError(what + ": expected " + std::to_string(count) + " comma-separated numbers, got '" + text + "'");
  }
  return values;
}

std::vector<geometry::Vec2> ParsePointsCsv(const std::string& text, const std::string& source_name) {
  // A UTF-8 byte order mark (spreadsheet exports write one) is not part of the header.
  constexpr std::string_view kBom = "\xEF\xBB\xBF";
  std::istringstream in(text.compare(0, kBom.size(), kBom) == 0 ? text.substr(kBom.size()) : text);
  std::string line;
  int line_number = 0;
  std::vector<geometry::Vec2> points;
  bool header_seen = false;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string item = Trim(line);
    if (item.empty()) continue;
    const std::string where = source_name + ":" + std::to_string(line_number);
    if (item.find('\0') != std::string::npos) throw IoError(where + ": NUL byte (not a text file)");
    if (!header_seen) {
      std::string compact;
      for (char c : item)
        if (c != ' ' && c != '\t') compact += c;
      if (compact != "x,y") throw IoError(where + ": expected the header 'x,y', got '" + item + "'");
      header_seen = true;
      continue;
    }
    std::vector<double> v;
    try {
      v = ParseNumberList(item, 2, "point");
    } catch (const IoError& e) {
      throw IoError(where + ": " + e.what());
    }
    // The queries' own limit, checked here where the line is known.
    if (std::abs(v[0]) > geometry::kMaxQueryCoordinate || std::abs(v[1]) > geometry::kMaxQueryCoordinate) {
      std::ostringstream text;
      text << std::setprecision(17) << where << ": point (" << v[0] << ", " << v[1] << ") is outside the supported range +-"
           << geometry::kMaxQueryCoordinate << " (docs/geometry.md, Limits)";
      throw IoError(text.str());
    }
    points.emplace_back(v[0], v[1]);
  }
  if (!header_seen) throw IoError(source_name + ": empty file (expected the header 'x,y')");
  return points;
}

std::vector<geometry::Vec2> ReadPointsCsv(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError(path + ": is a directory, not a points file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open file");
  std::ostringstream text;
  text << in.rdbuf();
  return ParsePointsCsv(text.str(), path);
}

}  // namespace pushgraph::io
