// Couplings as the JSON format writes them (io/coupling_json.hpp).
#include "io/coupling_json.hpp"

#include <algorithm>
#include <cmath>

#include "core/model/names.hpp"

namespace femdyn {
namespace {

// A row of numbers (a polynomial term, a spline point).
std::vector<double> numbers(const Json& row, const std::string& where) {
  if (!row.is_array()) throw ModelError(where, "expected an array of numbers");
  std::vector<double> v;
  for (std::size_t i = 0; i < row.size(); ++i)
    v.push_back(json_number(row[i], where + "/" + std::to_string(i)));
  return v;
}

std::shared_ptr<const CouplingFunction> read_polynomial(const Params& p, int arity) {
  // [[c, p_1, …, p_k], …]: c Π θ_i^{p_i}
  const Json& terms = p.json().at("polynomial");
  if (!terms.is_array() || terms.empty())
    p.fail("polynomial", "expected a non-empty array of [coefficient, power per joint]");
  std::vector<PolynomialCoupling::Term> list;
  for (std::size_t t = 0; t < terms.size(); ++t) {
    const std::string where = p.path("polynomial") + "/" + std::to_string(t);
    const std::vector<double> v = numbers(terms[t], where);
    if (static_cast<int>(v.size()) != arity + 1)
      throw ModelError(where, "expected [coefficient, " + std::to_string(arity) +
                                  " power(s)]: one power per followed joint");
    PolynomialCoupling::Term term{v[0], {}};
    check_magnitude(v[0], where + "/0", "coefficient");
    for (int k = 1; k <= arity; ++k) {
      if (!(v[k] >= 0 && v[k] <= 16 && v[k] == std::floor(v[k])))
        throw ModelError(where + "/" + std::to_string(k), "a power is an integer from 0 to 16");
      term.powers.push_back(static_cast<int>(v[k]));
    }
    list.push_back(std::move(term));
  }
  return std::make_shared<PolynomialCoupling>(arity, std::move(list));
}

std::shared_ptr<const CouplingFunction> read_spline(const Params& p) {
  // [[θ_in, θ_out], …], θ_in strictly increasing
  const Json& pts = p.json().at("spline");
  if (!pts.is_array() || pts.size() < 2)
    p.fail("spline", "expected at least 2 points [θ_in, θ_out]");
  std::vector<double> x, y;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const std::string where = p.path("spline") + "/" + std::to_string(i);
    const std::vector<double> v = numbers(pts[i], where);
    if (v.size() != 2) throw ModelError(where, "expected a point [θ_in, θ_out]");
    check_magnitude(v[0], where + "/0", "θ_in");
    check_magnitude(v[1], where + "/1", "θ_out");
    if (!x.empty() && !(v[0] > x.back()))
      throw ModelError(where + "/0", "θ_in must increase strictly from point to point");
    x.push_back(v[0]);
    y.push_back(v[1]);
  }
  return std::make_shared<SplineCoupling>(std::move(x), std::move(y));
}

std::shared_ptr<const CouplingFunction> read_four_bar(const Params& p) {
  const Params f = p.child("four_bar");
  f.allow_only({"ground", "input", "coupler", "output", "branch", "input_offset", "input_sign",
                "output_offset", "output_sign"});
  FourBarCoupling::Geometry g;
  g.ground = f.positive("ground");
  g.input = f.positive("input");
  g.coupler = f.positive("coupler");
  g.output = f.positive("output");
  const auto sign = [&](const char* key) {
    const double v = f.number_or(key, 1.0);
    if (v != 1 && v != -1) f.fail(key, "expected 1 or -1");
    return v;
  };
  g.branch = static_cast<int>(sign("branch"));
  g.input_sign = sign("input_sign");
  g.output_sign = sign("output_sign");
  g.input_offset = f.number_or("input_offset", 0.0);
  if (f.has("output_offset")) {
    g.output_offset = f.number("output_offset");
  } else {  // θ_out = 0 where θ_in = 0: ψ0 = ψ(φ0)
    const auto psi0 = FourBarCoupling::output_angle_at_zero(g);
    if (!psi0)
      f.fail("input_offset",
             "the linkage cannot assemble at θ_in = 0, so θ_out = 0 there cannot be the default: "
             "give output_offset");
    g.output_offset = *psi0;
  }
  check_magnitude(g.input_offset, f.path("input_offset"), "input_offset");
  check_magnitude(g.output_offset, f.path("output_offset"), "output_offset");
  for (double len : {g.ground, g.input, g.coupler, g.output})
    check_magnitude(len, f.where(), "link length");
  return std::make_shared<FourBarCoupling>(g);
}

// A nonlinear law: "polynomial", "spline" or "four_bar" (docs/model-format.md#couplings).
std::shared_ptr<const CouplingFunction> read_law(const Params& p, int arity) {
  if (p.has("polynomial")) return read_polynomial(p, arity);
  if (arity != 1) p.fail("follows", "a spline or four-bar law follows exactly one joint");
  if (p.has("spline")) return read_spline(p);
  return read_four_bar(p);
}

}  // namespace

// "follows": f with "ratio": k, or "follows": [{"joint": f1, "ratio": k1}, …] (a linear
// coupling's, or a gear constraint's, terms).
std::vector<std::pair<std::string, double>> read_linear_terms(const Params& p) {
  std::vector<std::pair<std::string, double>> terms;
  const Json& f = p.json().contains("follows") ? p.json().at("follows") : Json();
  if (f.is_string()) {
    terms.emplace_back(f.get<std::string>(), p.number_or("ratio", 1.0));
  } else if (f.is_array()) {
    if (p.has("ratio")) p.fail("ratio", "give ratios inside \"follows\" when it is a list");
    for (std::size_t i = 0; i < f.size(); ++i) {
      const Params t(f[i], p.path("follows") + "/" + std::to_string(i));
      t.allow_only({"joint", "ratio"});
      terms.emplace_back(t.string("joint"), t.number("ratio"));
    }
  } else {
    p.fail("follows", "expected a joint name or a list of {joint, ratio}");
  }
  return terms;
}

CouplingSpec read_coupling(const Params& p) {
  // {"joint": j, "follows": f, "ratio": k, "offset": o}
  // or {"joint": j, "follows": [{"joint": f1, "ratio": k1}, …], "offset": o}
  // or {"joint": j, "follows": f or [f1, f2, …], "polynomial" | "spline" | "four_bar": …}
  p.allow_only({"joint", "follows", "ratio", "offset", "polynomial", "spline", "four_bar"});
  CouplingSpec c;
  c.where = p.where();
  c.joint = p.string("joint");
  const Json& f = p.json().contains("follows") ? p.json().at("follows") : Json();
  int laws = 0;
  for (const char* key : {"polynomial", "spline", "four_bar"}) laws += p.has(key) ? 1 : 0;
  if (laws > 1) p.fail("follows", "give one law: polynomial, spline or four_bar");
  if (laws == 1) {
    for (const char* key : {"ratio", "offset"})
      if (p.has(key)) p.fail(key, "belongs to a linear coupling, not to a law");
    if (f.is_string()) {
      c.follows.push_back(f.get<std::string>());
    } else if (f.is_array() && !f.empty()) {
      for (std::size_t i = 0; i < f.size(); ++i) {
        if (!f[i].is_string())
          throw ModelError(p.path("follows") + "/" + std::to_string(i), "expected a joint name");
        c.follows.push_back(f[i].get<std::string>());
      }
    } else {
      p.fail("follows", "expected a joint name or a non-empty list of joint names");
    }
    c.law = read_law(p, static_cast<int>(c.follows.size()));
    return c;
  }
  c.offset = p.number_or("offset", 0.0);
  c.terms = read_linear_terms(p);
  return c;
}

}  // namespace femdyn
