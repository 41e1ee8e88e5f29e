// Duplicate keys by nlohmann_json's SAX interface: a stack of the open containers, each object
// with the keys seen so far.
#include <pushgraph/geometry/json_check.h>

#include <algorithm>
#include <cctype>

#include <nlohmann/json.hpp>

#include <set>
#include <string>
#include <vector>

namespace pushgraph::geometry {
namespace {

class DuplicateFinder : public nlohmann::json_sax<nlohmann::json> {
 public:
  std::string found;

  bool null() override { return Value(); }
  bool boolean(bool) override { return Value(); }
  bool number_integer(number_integer_t) override { return Value(); }
  bool number_unsigned(number_unsigned_t) override { return Value(); }
  bool number_float(number_float_t, const string_t&) override { return Value(); }
  bool string(string_t&) override { return Value(); }
  bool binary(binary_t&) override { return Value(); }
  bool start_object(std::size_t) override {
    Open(true);
    return true;
  }
  bool key(string_t& k) override {
    Container& c = stack_.back();
    if (!c.keys.insert(k).second) {
      found = "duplicate key \"" + k + "\" in " + (Pointer().empty() ? std::string("the top-level object") : Pointer());
      return false;  // stop: the first one is enough
    }
    c.current = k;
    return true;
  }
  bool end_object() override { return Close(); }
  bool start_array(std::size_t) override {
    Open(false);
    return true;
  }
  bool end_array() override { return Close(); }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override { return false; }

 private:
  struct Container {
    bool object = true;
    std::set<std::string> keys;
    std::string current;  // the key (object) or index (array) being read
    std::size_t index = 0;
  };
  // A value ends: in an array the next one has the next index.
  bool Value() {
    if (!stack_.empty() && !stack_.back().object) stack_.back().current = std::to_string(stack_.back().index++);
    return true;
  }
  void Open(bool object) {
    if (!stack_.empty() && !stack_.back().object) stack_.back().current = std::to_string(stack_.back().index++);
    Container c;
    c.object = object;
    stack_.push_back(std::move(c));
  }
  bool Close() {
    stack_.pop_back();
    return true;
  }
  // The JSON pointer of the innermost open object.
  std::string Pointer() const {
    std::string p;
    for (std::size_t i = 0; i + 1 < stack_.size(); ++i) p += "/" + stack_[i].current;
    return p;
  }
  std::vector<Container> stack_;
};

}  // namespace

std::string FindDuplicateJsonKey(const std::string& text) {
  DuplicateFinder finder;
  nlohmann::json::sax_parse(text, &finder, nlohmann::json::input_format_t::json, /*strict=*/false);
  return finder.found;
}

namespace {

// "number overflow parsing '1e999'": the token's first place in `text` where it stands alone, as
// " at line L, column C" ("" when not found).
std::string OverflowPlace(const std::string& what, const std::string& text) {
  const std::string key = "number overflow parsing '";
  const std::size_t at = what.find(key);
  if (at == std::string::npos || text.empty()) return "";
  const std::size_t begin = at + key.size(), end = what.find('\'', begin);
  if (end == std::string::npos || end == begin) return "";
  const std::string token = what.substr(begin, end - begin);
  auto part_of_number = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+'; };
  // Outside string literals only (a "comment": "1e999" before the number is text).
  bool in_string = false;
  for (std::size_t p = 0; p < text.size(); ++p) {
    if (in_string) {
      if (text[p] == '\\') ++p;
      else if (text[p] == '"') in_string = false;
      continue;
    }
    if (text[p] == '"') {
      in_string = true;
      continue;
    }
    if (text.compare(p, token.size(), token) != 0) continue;
    if ((p > 0 && part_of_number(text[p - 1])) || (p + token.size() < text.size() && part_of_number(text[p + token.size()]))) continue;
    const std::size_t line = 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(p), '\n'));
    const std::size_t line_start = p == 0 ? std::string::npos : text.rfind('\n', p - 1);
    const std::size_t column = line_start == std::string::npos ? p + 1 : p - line_start;
    return " at line " + std::to_string(line) + ", column " + std::to_string(column) +
           " (beyond a double's range, about 1e308)";
  }
  return "";
}

}  // namespace

std::string JsonSyntaxErrorText(const std::string& what, const std::string& text) {
  if (const std::string place = OverflowPlace(what, text); !place.empty()) return what + place;
  // "invalid literal" (NaN, Infinity), or "expected digit after '-'" (-Infinity).
  const bool literal = what.find("invalid literal") != std::string::npos || what.find("after '-'") != std::string::npos;
  const std::size_t last = what.find("last read: '");
  if (!literal || last == std::string::npos) return what;
  // The token the parser stopped in: the last read text's tail after a separator.
  std::string read = what.substr(last + 12);
  if (const std::size_t end = read.rfind('\''); end != std::string::npos) read.erase(end);
  const std::size_t start = read.find_last_of(" ,[:\t\n");
  const std::string token = start == std::string::npos ? read : read.substr(start + 1);
  const bool non_finite = !token.empty() && (token.find_first_of("NnIi") == 0 || token.rfind("-I", 0) == 0 ||
                                             token.rfind("-i", 0) == 0);
  if (!non_finite) return what;
  return what + " (NaN or Infinity written as a number? JSON has neither, and a non-finite sample is no measurement: "
                "leave that row out)";
}

}  // namespace pushgraph::geometry
