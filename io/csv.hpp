// CSV as femdyn writes and reads it (RFC 4180). A field that holds a comma, a double quote, a
// line break, or blanks at either end (which readers drop) is written between double quotes,
// with each double quote in it doubled; every other field as it is. So a coordinate named "a,b"
// stays one column: `t,"q_a,b",…`. The readers (--tau-csv, io/actuation_table; the trajectory,
// io/trajectory_csv) take quoted and unquoted fields. A line break inside quotes is not read:
// femdyn's names cannot hold one (core/model/names.hpp).
#pragma once
#include <string>
#include <string_view>
#include <vector>

namespace femdyn {

// s as one CSV field, quoted if it needs to be.
std::string csv_field(std::string_view s);

// The fields of one CSV line (without its line break), unquoted; blanks (space, tab, CR)
// around a field are dropped. A malformed quote throws ModelError(where, …) naming the column.
std::vector<std::string> csv_fields(std::string_view line, const std::string& where);

}  // namespace femdyn
