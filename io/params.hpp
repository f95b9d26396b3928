// Params: one JSON object with its location, as element factories and model plugins see it.
// Every accessor checks type and finiteness and throws ModelError naming the JSON path.
#pragma once
#include <initializer_list>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "core/model/errors.hpp"
#include "core/spatial/math.hpp"

namespace femdyn {

using Json = nlohmann::json;

// A node an element refers to: by name from its body's "nodes" table, as "body/node" from
// another body's (in that body's frame; the label says which body), or inline [x, y, z].
struct NodeRef {
  Vec3 position;
  std::string label;
};

class Params {
 public:
  // where: "file: /json/pointer"; nodes: the body's named nodes (may be null); other_nodes:
  // the nodes of every body as "body/node" (may be null), looked up after the body's own.
  Params(const Json& object, std::string where, std::string body = "",
         const std::map<std::string, Vec3>* nodes = nullptr,
         const std::map<std::string, Vec3>* other_nodes = nullptr);

  bool has(const char* key) const { return j_.contains(key); }
  std::string path(const char* key) const { return where_ + "/" + key; }
  const std::string& where() const { return where_; }
  const Json& json() const { return j_; }

  Params child(const char* key) const;  // a required nested object
  double number(const char* key) const;
  double number_or(const char* key, double fallback) const;
  double positive(const char* key) const;      // > 0
  double non_negative(const char* key) const;  // >= 0
  std::string string(const char* key) const;
  bool boolean_or(const char* key, bool fallback) const;
  Vec3 vec3(const char* key) const;
  Vec3 vec3_or(const char* key, const Vec3& fallback) const;
  // [[ixx,ixy,ixz],[ixy,iyy,iyz],[ixz,iyz,izz]] or {"ixx":…, "iyy":…, "izz":…, "ixy":…, …}
  Mat3 inertia(const char* key) const;
  NodeRef node(const char* key) const;
  NodeRef node_at(const char* key, std::size_t index) const;  // key holds an array of nodes

  // Rejects keys not in the list (catches typos such as "mas").
  void allow_only(std::initializer_list<const char*> keys) const;
  // The same, also allowing every key `also` accepts (a joint type's own numbers).
  void allow_only(std::initializer_list<const char*> keys, bool (*also)(std::string_view)) const;
  [[noreturn]] void fail(const char* key, const std::string& what) const;

 private:
  const Json& at(const char* key) const;
  NodeRef node_from(const Json& v, const std::string& where) const;

  const Json& j_;
  std::string where_;
  std::string body_;
  const std::map<std::string, Vec3>* nodes_;
  const std::map<std::string, Vec3>* other_nodes_;
};

// Helpers shared by the loaders.
double json_number(const Json& v, const std::string& where);
Vec3 json_vec3(const Json& v, const std::string& where);
// [x, y, z], the model format's vector, for plugins and importers that write models.
inline Json vec3_json(const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); }

}  // namespace femdyn
