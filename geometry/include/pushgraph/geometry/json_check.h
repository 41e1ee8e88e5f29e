#pragma once
// Strict JSON: a key given twice in one object is an error in every pushgraph file (shape,
// trajectory, estimator and evaluation configs, MIT JSON recordings). JSON parsers keep the last
// value silently, so `{"mass": 0.5, ..., "mass": 5}` would be read as a different object than the
// one its author checked.
//
//   const std::string where = geometry::FindDuplicateJsonKey(text);
//   if (!where.empty()) throw MyError(path + ": " + where);
#include <string>

namespace pushgraph::geometry {

/// The first key repeated within one object, as `duplicate key "mass" in /object` (the JSON
/// pointer of the object holding it), or "" when there is none. Text that is not valid JSON
/// gives "" (the caller's parser reports the syntax error).
std::string FindDuplicateJsonKey(const std::string& text);

/// A JSON parser's syntax error `what`, with what it most likely means added where the parser's
/// own words do not say: NaN or Infinity written as numbers (JSON has neither; Python's json.dump
/// writes them), which the parser calls an "invalid literal". Given the parsed `text`, a number
/// beyond a double's range ("number overflow parsing '1e999'", which carries no place) is given
/// its line and column.
std::string JsonSyntaxErrorText(const std::string& what, const std::string& text = "");

}  // namespace pushgraph::geometry
