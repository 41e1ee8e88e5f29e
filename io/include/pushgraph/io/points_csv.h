#pragma once
// Points files: CSV with the header `x,y` and one point per line (blank lines skipped), as read by
// `pushgraph distance`. Errors name the file and line.
//
//   std::vector<geometry::Vec2> points = io::ReadPointsCsv("points.csv");
#include <pushgraph/geometry/types.h>

#include <cstddef>
#include <string>
#include <vector>

namespace pushgraph::io {

/// Reads a points file. Throws IoError (file:line and what is wrong).
std::vector<geometry::Vec2> ReadPointsCsv(const std::string& path);

/// The same from text; `source_name` stands for the file in messages.
std::vector<geometry::Vec2> ParsePointsCsv(const std::string& text, const std::string& source_name = "<string>");

/// `count` comma-separated finite numbers (decimal or hexadecimal, spaces around them allowed).
/// Throws IoError starting with `what`.
std::vector<double> ParseNumberList(const std::string& text, std::size_t count, const std::string& what);

}  // namespace pushgraph::io
