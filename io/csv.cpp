#include "io/csv.hpp"

#include <algorithm>

#include "core/model/errors.hpp"

namespace femdyn {
namespace {

bool blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

// The quoted field that starts at line[i] == '"': its text, with i moved past the closing quote.
std::string quoted_field(std::string_view line, std::size_t& i, const std::string& where,
                         std::size_t column) {
  std::string out;
  for (++i; i < line.size(); ++i) {
    if (line[i] != '"') {
      out += line[i];
      continue;
    }
    if (i + 1 < line.size() && line[i + 1] == '"') {
      out += '"';
      ++i;
      continue;
    }
    ++i;  // the closing quote
    return out;
  }
  throw ModelError(
      where, "column " + std::to_string(column) + ": a quoted field has no closing \" on its line");
}

}  // namespace

std::string csv_field(std::string_view s) {
  const bool quote = s.find_first_of(",\"\n\r") != std::string_view::npos ||
                     (!s.empty() && (blank(s.front()) || blank(s.back())));
  if (!quote) return std::string(s);
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::vector<std::string> csv_fields(std::string_view line, const std::string& where) {
  std::vector<std::string> fields;
  std::size_t i = 0;
  while (true) {
    const std::size_t column = fields.size() + 1;
    while (i < line.size() && blank(line[i])) ++i;
    if (i < line.size() && line[i] == '"') {
      fields.push_back(quoted_field(line, i, where, column));
      while (i < line.size() && blank(line[i])) ++i;
      if (i < line.size() && line[i] != ',')
        throw ModelError(where, "column " + std::to_string(column) +
                                    ": text after the closing \" of a quoted field");
    } else {
      const std::size_t comma = std::min(line.find(',', i), line.size());
      fields.emplace_back(trimmed(line.substr(i, comma - i)));
      i = comma;
    }
    if (i >= line.size()) return fields;
    ++i;  // the comma
  }
}

}  // namespace femdyn
