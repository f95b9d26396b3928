// The URDF reader's own pieces, shared by its files (io/urdf_loader.cpp reads the tree and the
// joints, io/urdf_bodies.cpp the links' mass as rigid bodies). Not an interface of femdyn.
#pragma once
#include <tinyxml2.h>

#include <map>
#include <string>
#include <vector>

#include "core/model/errors.hpp"
#include "core/spatial/math.hpp"
#include "io/params.hpp"
#include "io/urdf_loader.hpp"

namespace femdyn::urdf_reading {

using tinyxml2::XMLElement;

struct Ctx {
  std::string source;
  // The model's length scale L (m): the largest joint or inertial offset, 1 m without any. An
  // inertia's round-off is judged against m L² (export noise of −2.4e-35 on a point mass is not
  // a negative moment).
  double length = 1;
  [[noreturn]] void fail(const std::string& what_element, const std::string& problem) const {
    throw ModelError(source, what_element + ": " + problem);
  }
};

// An attribute as a number (NaN, Inf and trailing text refused, naming `who`), or `fallback`.
double number_attr(const Ctx& c, const XMLElement* e, const char* attr, double fallback,
                   const std::string& who, bool required = false);
// An attribute as 3 numbers, or `fallback`.
Vec3 vec_attr(const Ctx& c, const XMLElement* e, const char* attr, const Vec3& fallback,
              const std::string& who);

struct Origin {
  Vec3 xyz = Vec3::Zero(), rpy = Vec3::Zero();
};
// The <origin> child of `parent` (zeros without one).
Origin origin_of(const Ctx& c, const XMLElement* parent, const std::string& who);

struct JointInfo {
  const XMLElement* e;
  std::string name, parent, child;
};

// Each link's element (io/urdf_bodies.cpp): links welded by fixed joints checked and, where a
// link alone is not physical, merged as one rigid body; `notes` gets what was merged, dropped or
// balanced.
std::map<std::string, Json> link_elements(const Ctx& c,
                                          const std::map<std::string, const XMLElement*>& links,
                                          const std::vector<std::string>& link_order,
                                          const std::vector<JointInfo>& joints,
                                          const std::string& root, const UrdfOptions& options,
                                          std::vector<std::string>& notes);

}  // namespace femdyn::urdf_reading
