// An MJCF file as MuJoCo's compiler reads it, for io/mjcf_loader.cpp: <include>s expanded in
// place (each file once, relative to the main file's folder), attributes resolved through
// <default> classes (an element's own class, else the nearest childclass above it, else "main";
// a class inherits from the classes it is nested in), and <compiler>'s settings. Errors name the
// file the element is in, the element and its line: "arm.xml: <joint name='elbow'> (line 12):
// range: expected 2 numbers". Not an interface of femdyn.
#pragma once
#include <tinyxml2.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/spatial/math.hpp"

namespace femdyn::mjcf {

using tinyxml2::XMLElement;

struct Compiler {
  bool degrees = true;  // angle="degree", MJCF's default: euler, axisangle, hinge range, ref
  std::string eulerseq = "xyz";
  enum class FromGeom { automatic, always, never };
  FromGeom inertia_from_geom = FromGeom::automatic;  // inertiafromgeom auto|true|false
  int group_lo = 0, group_hi = 5;                    // inertiagrouprange
  double boundmass = 0, boundinertia = 0, settotalmass = -1;
  bool balanceinertia = false;
  bool autolimits = true;
  bool exact_mesh_inertia = false;  // exactmeshinertia: signed volumes (else MuJoCo's legacy |V|)
  bool every_mesh_exact = false;    // MjcfOptions::exact_mesh_inertia: over a mesh's own inertia
  std::string meshdir;  // where mesh files are (meshdir, else assetdir, else the file's folder)
};

class Document {
 public:
  explicit Document(const std::string& path);
  ~Document();

  const XMLElement& root() const { return *root_; }
  const Compiler& compiler() const { return compiler_; }
  void make_every_mesh_exact() { compiler_.every_mesh_exact = true; }
  const std::string& path() const { return path_; }
  // The children of `e` named `tag` (every child for nullptr), <include>s expanded in place.
  std::vector<const XMLElement*> children(const XMLElement& e, const char* tag = nullptr) const;
  // The top-level sections named `tag` (<worldbody>, <equality>, …) of every included file.
  std::vector<const XMLElement*> sections(const char* tag) const;

  // `name` of `e` as compiled: its own, else its class's default (`cls`, from class_of).
  const char* attr(const XMLElement& e, const char* name, const std::string& cls) const;
  // e's class: its own `class`, else `inherited` (the nearest childclass above), else "main".
  std::string class_of(const XMLElement& e, const std::string& inherited) const;
  // The childclass in force below e (a body or frame): its own (checked), else `inherited`.
  std::string childclass_of(const XMLElement& e, const std::string& inherited) const;

  // The attribute as numbers (finite, exactly `count` of them; any count for -1), or empty when
  // absent. Refused in one line naming the element otherwise.
  std::vector<double> numbers(const XMLElement& e, const char* name, const std::string& cls,
                              int count) const;
  double number(const XMLElement& e, const char* name, const std::string& cls,
                double fallback) const;
  Vec3 vec3(const XMLElement& e, const char* name, const std::string& cls,
            const Vec3& fallback) const;
  // "true"/"false" (MJCF's booleans), or fallback.
  bool flag(const XMLElement& e, const char* name, const std::string& cls, bool fallback) const;

  // "<joint name='elbow'> (line 12)", for messages.
  std::string who(const XMLElement& e) const;
  // The file `e` is in (the main file or an included one).
  const std::string& file_of(const XMLElement& e) const;
  [[noreturn]] void fail(const XMLElement& e, const std::string& problem) const;

 private:
  void load(const std::string& file, int depth);
  void read_defaults(const XMLElement& d, const std::string& parent, int depth);
  void read_compiler(const XMLElement& c);

  std::string path_;
  std::vector<std::unique_ptr<tinyxml2::XMLDocument>> docs_;
  std::map<const tinyxml2::XMLDocument*, std::string> file_;
  std::map<std::string, const tinyxml2::XMLDocument*> included_;  // file -> its document
  const XMLElement* root_ = nullptr;
  // class -> (its <default> elements, its parent class); "main" has no parent and may have
  // several (each file's top-level <default>; a later one's attributes win).
  std::map<std::string, std::pair<std::vector<const XMLElement*>, std::string>> classes_;
  Compiler compiler_;
};

}  // namespace femdyn::mjcf
