// JSON model text read safely (io/json_text.hpp).
#include "io/json_text.hpp"

#include <cctype>

#include "core/model/errors.hpp"
#include "core/model/limits.hpp"

namespace femdyn {
namespace {

std::string line_col(const std::string& text, std::size_t byte) {
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}

// What one linear pass over a JSON text tells before it is parsed: whether it nests deeper
// than kMaxNesting, and how many items its top-level "bodies" array holds. nlohmann's parser
// with a callback (the earlier depth check) rescans the enclosing array at every object it
// closes, which is quadratic in long arrays of objects; this scan and a plain parse are linear.
struct JsonOutline {
  bool too_deep = false;
  std::size_t bodies = 0;  // items of the top-level "bodies" array (0: none, or not an array)
};

// The index just past the string whose opening quote is text[i], escapes respected.
std::size_t past_string(const std::string& text, std::size_t i) {
  for (++i; i < text.size(); ++i) {
    if (text[i] == '\\')
      ++i;  // (the escaped character, a quote included)
    else if (text[i] == '"')
      return i + 1;
  }
  return text.size();
}

JsonOutline outline(const std::string& text) {
  JsonOutline out;
  int depth = 0;            // containers open
  bool bodies_key = false;  // at depth 1, the last token was the string "bodies" (or its ':')
  bool in_bodies = false;   // inside the top-level "bodies" array (a later one replaces it)
  bool counted = false;     // its current item is counted (until the next ',')
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    if (in_bodies && depth == 2 && c != ']') {
      if (c != ',' && !counted) ++out.bodies;  // an item begins
      counted = c != ',';
    }
    if (c == '"') {
      const std::size_t end = past_string(text, i);
      if (depth == 1) bodies_key = text.compare(i, end - i, "\"bodies\"") == 0;
      i = end;
      continue;
    }
    if (c == '[' || c == '{') {
      if (++depth > kMaxNesting) return {.too_deep = true};
      if (depth == 2 && c == '[' && bodies_key) {
        in_bodies = true;
        counted = false;
        out.bodies = 0;
      }
    } else if (c == ']' || c == '}') {
      if (--depth == 1) in_bodies = false;
    }
    if (c != ':') bodies_key = false;  // the key is "bodies" only when ':' follows it
    ++i;
  }
  return out;
}

}  // namespace

// The text as JSON, its nesting and body count bounded first; malformed JSON named by line and
// column.
Json parse_json(const std::string& text, const std::string& source) {
  // The nesting depth and the number of bodies are bounded (core/model/limits.hpp) by one pass over
  // the text, before a deep or huge document can cost anything.
  const JsonOutline shape = outline(text);
  if (shape.too_deep)
    throw ModelError(source, "JSON nested deeper than " + std::to_string(kMaxNesting) +
                                 " levels (femdyn's limit)");
  if (shape.bodies > static_cast<std::size_t>(kMaxBodies))
    throw ModelError(source + ": /bodies", too_many_bodies_text(shape.bodies));
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::parse_error& e) {
    std::string what = e.what();
    const auto colon = what.rfind(": ");
    throw ModelError(source, "malformed JSON at " + line_col(text, e.byte == 0 ? 0 : e.byte - 1) +
                                 (colon == std::string::npos ? "" : ": " + what.substr(colon + 2)));
  } catch (const Json::exception& e) {  // e.g. number overflow (1e999)
    std::string what = e.what();
    const auto bracket = what.find("] ");
    throw ModelError(source, "malformed JSON: " +
                                 (bracket == std::string::npos ? what : what.substr(bracket + 2)));
  }
  return root;
}

}  // namespace femdyn
