// Fuzz target: a femdyn JSON model file's text, loaded as `femdyn equations MODEL` loads it
// (parse_spec: JSON, plugins, the model document), compiled, and evaluated once.
#include <optional>

#include "compile/compile.hpp"
#include "core/model/errors.hpp"
#include "models/model_files.hpp"
#include "tests/fuzz/common.hpp"

using namespace femdyn;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::optional<Model> model;
  bool finite = true;
  // A plugin's own size parameter (random_tree "bodies", up to 10000) is skipped before the
  // expansion, which alone takes seconds under the sanitizers at that size.
  const Json doc = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_object() && doc.contains("params") && doc["params"].is_object() &&
      doc["params"].contains("bodies") && doc["params"]["bodies"].is_number() &&
      doc["params"]["bodies"].get<double>() > fuzz::kMaxBodies) {
    fuzz::note("skipped: plugin with too many bodies");
    return 0;
  }
  fuzz::expected_errors_only("json_model load", [&] {
    MechanismSpec spec = parse_spec(text, "fuzz.json");
    if (spec.bodies.size() > fuzz::kMaxBodies) return fuzz::note("skipped: too many bodies");
    finite = fuzz::all_finite(doc);  // parse_spec accepted the text: doc is the document
    model.emplace(compile(std::move(spec)));
  });
  if (model)
    fuzz::expected_errors_only("json_model evaluation", [&] {
      fuzz::evaluate_once(*model, fuzz::hash(data, size), finite);
    });
  return 0;
}
