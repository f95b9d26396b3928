#include "io/urdf_reading.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "core/model/names.hpp"

namespace femdyn::urdf_reading {

double number_attr(const Ctx& c, const XMLElement* e, const char* attr, double fallback,
                   const std::string& who, bool required) {
  const char* s = e ? e->Attribute(attr) : nullptr;
  if (!s) {
    if (required) c.fail(who, std::string("<") + (e ? e->Name() : "?") + "> has no " + attr);
    return fallback;
  }
  char* end = nullptr;
  const double x = std::strtod(s, &end);
  while (end && *end == ' ') ++end;
  if (end == s || (end && *end))
    c.fail(who, std::string(attr) + "=\"" + echo_text(s) + "\" is not a number");
  if (!std::isfinite(x)) c.fail(who, std::string(attr) + " is NaN or Inf");
  return x;
}

Vec3 vec_attr(const Ctx& c, const XMLElement* e, const char* attr, const Vec3& fallback,
              const std::string& who) {
  const char* s = e ? e->Attribute(attr) : nullptr;
  if (!s) return fallback;
  std::istringstream in(s);
  Vec3 v;
  std::string tok[3], extra;
  for (int i = 0; i < 3; ++i) {
    if (!(in >> tok[i]))
      c.fail(who, std::string(attr) + "=\"" + echo_text(s) + "\" needs 3 numbers");
    char* end = nullptr;
    v[i] = std::strtod(tok[i].c_str(), &end);
    if (*end) c.fail(who, std::string(attr) + "=\"" + echo_text(s) + "\" is not 3 numbers");
    if (!std::isfinite(v[i])) c.fail(who, std::string(attr) + " is NaN or Inf");
  }
  if (in >> extra)
    c.fail(who, std::string(attr) + "=\"" + echo_text(s) + "\" has more than 3 numbers");
  return v;
}

Origin origin_of(const Ctx& c, const XMLElement* parent, const std::string& who) {
  const XMLElement* o = parent ? parent->FirstChildElement("origin") : nullptr;
  return {vec_attr(c, o, "xyz", Vec3::Zero(), who), vec_attr(c, o, "rpy", Vec3::Zero(), who)};
}

}  // namespace femdyn::urdf_reading
