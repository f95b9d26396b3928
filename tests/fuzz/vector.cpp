// Fuzz target: the command line's number lists (cli/commands.cpp parse_numbers: --q, --qd,
// --tau, --gravity, …). Expected: the values, or a CliError. A bug besides crashes and other
// exceptions: a value that is NaN or Inf, or a count other than the number of commas + 1.
#include <algorithm>
#include <cmath>

#include "cli/commands.hpp"
#include "tests/fuzz/common.hpp"

using namespace femdyn;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<double> v;
  if (!fuzz::expected_errors_only("parse_numbers", [&] { v = cli::parse_numbers("q", text); }))
    return 0;
  const auto commas = static_cast<std::size_t>(std::count(text.begin(), text.end(), ','));
  if (v.size() != commas + 1)
    fuzz::bug("parse_numbers returned " + std::to_string(v.size()) + " values for " +
              std::to_string(commas + 1) + " items");
  for (double x : v)
    if (!std::isfinite(x)) fuzz::bug("parse_numbers returned NaN or Inf");
  return 0;
}
