#include "io/params.hpp"

#include <cmath>

#include "core/model/names.hpp"

namespace femdyn {

double json_number(const Json& v, const std::string& where) {
  if (!v.is_number())
    throw ModelError(where, "expected a number, got " + std::string(v.type_name()));
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw ModelError(where, "is NaN or Inf");
  return x;
}

Vec3 json_vec3(const Json& v, const std::string& where) {
  if (!v.is_array() || v.size() != 3) throw ModelError(where, "expected an array of 3 numbers");
  return {json_number(v[0], where + "/0"), json_number(v[1], where + "/1"),
          json_number(v[2], where + "/2")};
}

Params::Params(const Json& object, std::string where, std::string body,
               const std::map<std::string, Vec3>* nodes,
               const std::map<std::string, Vec3>* other_nodes)
    : j_(object),
      where_(std::move(where)),
      body_(std::move(body)),
      nodes_(nodes),
      other_nodes_(other_nodes) {
  if (!j_.is_object()) throw ModelError(where_, "expected an object");
}

const Json& Params::at(const char* key) const {
  if (!j_.contains(key)) fail(key, "is missing");
  return j_.at(key);
}

void Params::fail(const char* key, const std::string& what) const {
  throw ModelError(path(key), what);
}

Params Params::child(const char* key) const {
  return Params(at(key), path(key), body_, nodes_, other_nodes_);
}

double Params::number(const char* key) const { return json_number(at(key), path(key)); }

double Params::number_or(const char* key, double fallback) const {
  return has(key) ? number(key) : fallback;
}

double Params::positive(const char* key) const {
  const double x = number(key);
  if (!(x > 0)) fail(key, "must be positive, got " + format_number(x));
  return x;
}

double Params::non_negative(const char* key) const {
  const double x = number(key);
  if (x < 0) fail(key, "must not be negative, got " + format_number(x));
  return x;
}

std::string Params::string(const char* key) const {
  const Json& v = at(key);
  if (!v.is_string()) fail(key, "expected a string");
  return v.get<std::string>();
}

bool Params::boolean_or(const char* key, bool fallback) const {
  if (!has(key)) return fallback;
  const Json& v = at(key);
  if (!v.is_boolean()) fail(key, "expected true or false");
  return v.get<bool>();
}

Vec3 Params::vec3(const char* key) const { return json_vec3(at(key), path(key)); }

Vec3 Params::vec3_or(const char* key, const Vec3& fallback) const {
  return has(key) ? vec3(key) : fallback;
}

Mat3 Params::inertia(const char* key) const {
  const Json& v = at(key);
  const std::string w = path(key);
  Mat3 I;
  if (v.is_array()) {
    if (v.size() != 3)
      throw ModelError(w, "expected a 3x3 array or {ixx, iyy, izz, ixy, ixz, iyz}");
    for (int r = 0; r < 3; ++r) {
      const Vec3 row = json_vec3(v[r], w + "/" + std::to_string(r));
      I.row(r) = row.transpose();
    }
    return I;
  }
  if (!v.is_object()) throw ModelError(w, "expected a 3x3 array or {ixx, iyy, izz, ixy, ixz, iyz}");
  Params p(v, w);
  p.allow_only({"ixx", "iyy", "izz", "ixy", "ixz", "iyz"});
  const double ixy = p.number_or("ixy", 0), ixz = p.number_or("ixz", 0),
               iyz = p.number_or("iyz", 0);
  // Read before the comma initializer: a ModelError thrown inside it would leave it unfinished
  // (an Eigen assertion in builds with assertions).
  const double ixx = p.number("ixx"), iyy = p.number("iyy"), izz = p.number("izz");
  I << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
  return I;
}

NodeRef Params::node_from(const Json& v, const std::string& where) const {
  if (v.is_string()) {
    const std::string name = v.get<std::string>();
    // The body's own node by that name, else "other_body/node": a node of another body (its
    // frame), labelled as such.
    const auto find = [&](const std::map<std::string, Vec3>* table) -> const Vec3* {
      if (!table) return nullptr;
      const auto it = table->find(name);
      return it == table->end() ? nullptr : &it->second;
    };
    const Vec3* at = find(nodes_);
    if (!at) at = find(other_nodes_);
    if (!at)
      throw ModelError(where,
                       "unknown node " + quoted_text(name) + " (not in the body's \"nodes\")");
    return {*at, name.find('/') == std::string::npos ? body_ + "/" + name : name};
  }
  const Vec3 p = json_vec3(v, where);
  char buf[96];
  std::snprintf(buf, sizeof buf, "/(%g,%g,%g)", p.x(), p.y(), p.z());
  return {p, body_ + buf};
}

NodeRef Params::node(const char* key) const { return node_from(at(key), path(key)); }

NodeRef Params::node_at(const char* key, std::size_t index) const {
  const Json& v = at(key);
  if (!v.is_array()) fail(key, "expected an array of nodes");
  if (index >= v.size()) fail(key, "expected at least " + std::to_string(index + 1) + " nodes");
  return node_from(v[index], path(key) + "/" + std::to_string(index));
}

void Params::allow_only(std::initializer_list<const char*> keys) const {
  allow_only(keys, [](std::string_view) { return false; });
}

void Params::allow_only(std::initializer_list<const char*> keys,
                        bool (*also)(std::string_view)) const {
  for (auto it = j_.begin(); it != j_.end(); ++it) {
    bool ok = also(it.key());
    for (const char* k : keys) ok = ok || it.key() == k;
    if (!ok)
      throw ModelError(where_ + "/" + truncated(it.key()), "unknown key " + quoted_text(it.key()));
  }
}

}  // namespace femdyn
