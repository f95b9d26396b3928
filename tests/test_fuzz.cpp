// Mutated models never crash and never leak a non-ModelError: every bundled model, thousands of
// seeded mutations (keys deleted, values replaced by other types, numbers made extreme).
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>

#include "compile/compile.hpp"
#include "core/model/errors.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;
using nlohmann::json;

namespace {

// All JSON pointers into j.
void pointers(const json& j, const json::json_pointer& at, std::vector<json::json_pointer>& out) {
  out.push_back(at);
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it) pointers(it.value(), at / it.key(), out);
  else if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i) pointers(j[i], at / i, out);
}

json replacement(std::mt19937& rng) {
  switch (rng() % 10) {
    case 0:
      return nullptr;
    case 1:
      return "text";
    case 2:
      return json::array();
    case 3:
      return json::object();
    case 4:
      return -1.0;
    case 5:
      return 0;
    case 6:
      return 1e300;
    case 7:
      return json::array({1, 2});
    case 8:
      return json::array({0.0, 0.0, 0.0});
    default:
      return true;
  }
}

}  // namespace

TEST_CASE("mutated models load or fail with a ModelError, never anything else", "[fuzz]") {
  for (const std::string& name : bundled_models()) {
    std::ifstream f(model_path(name));
    const json original = json::parse(f);
    std::vector<json::json_pointer> ptrs;
    pointers(original, json::json_pointer(), ptrs);
    std::mt19937 rng(99);
    int errors = 0, loaded = 0;
    for (int k = 0; k < 400; ++k) {
      json j = original;
      const auto& p = ptrs[1 + rng() % (ptrs.size() - 1)];
      if (rng() % 3 == 0) {
        j.at(p.parent_pointer()).is_object() ? (void)j.at(p.parent_pointer()).erase(p.back())
                                             : (void)(j.at(p) = replacement(rng));
      } else {
        j.at(p) = replacement(rng);
      }
      INFO(name << " mutation at " << p.to_string());
      try {
        const Model m = compile(parse_spec(j.dump(), "fuzz.json"));
        Workspace ws(m);
        evaluate(m, ws, neutral_posture(m), VecX::Ones(m.n()), VecX());
        ++loaded;
      } catch (const ModelError& e) {
        ++errors;
        CHECK(std::string(e.what()).rfind("fuzz.json", 0) == 0);
        CHECK(std::string(e.what()).find('\n') == std::string::npos);
      } catch (const std::exception& e) {
        FAIL_CHECK("leaked a non-ModelError: " << e.what());
      }
    }
    CHECK(errors > 0);
    CHECK(loaded + errors == 400);
    INFO(name << ": " << loaded << " mutations loaded, " << errors << " rejected");
  }
}
