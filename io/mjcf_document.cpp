#include "io/mjcf_document.hpp"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "core/model/errors.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"
#include "io/input_file.hpp"
#include "io/xml_error.hpp"

namespace femdyn::mjcf {

namespace fs = std::filesystem;

Document::Document(const std::string& path) : path_(path) {
  load(path, 0);
  root_ = docs_.front()->FirstChildElement("mujoco");
  for (const XMLElement* c : sections("compiler")) read_compiler(*c);
  const std::vector<const XMLElement*> defaults = sections("default");
  for (const XMLElement* d : defaults) read_defaults(*d, "", 0);
  if (!classes_.count("main")) classes_["main"] = {{}, ""};
  if (compiler_.meshdir.empty() || fs::path(compiler_.meshdir).is_relative())
    compiler_.meshdir = (fs::path(path).parent_path() / compiler_.meshdir).string();
}

Document::~Document() = default;

void Document::load(const std::string& file, int depth) {
  const std::string text = read_input_file(file);
  auto doc = std::make_unique<tinyxml2::XMLDocument>();
  if (doc->Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS)
    throw ModelError(file, xml_error_text(*doc));
  const XMLElement* top = doc->FirstChildElement("mujoco");
  if (!top) throw ModelError(file, "no <mujoco> element (an MJCF file, or a file it includes)");
  file_[doc.get()] = file;
  included_[fs::weakly_canonical(file).string()] = doc.get();
  docs_.push_back(std::move(doc));
  // Every <include> anywhere, loaded now (iteratively: a hostile file's depth is no recursion).
  std::vector<const XMLElement*> stack = {top};
  while (!stack.empty()) {
    const XMLElement* e = stack.back();
    stack.pop_back();
    for (const XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
      if (std::strcmp(c->Name(), "include") != 0) {
        stack.push_back(c);
        continue;
      }
      const char* name = c->Attribute("file");
      if (!name)
        throw ModelError(
            file, "<include> (line " + std::to_string(c->GetLineNum()) + "): no file attribute");
      fs::path target(name);
      if (target.is_relative()) target = fs::path(path_).parent_path() / target;
      const std::string key = fs::weakly_canonical(target).string();
      if (included_.count(key))
        throw ModelError(file, "<include file=" + quoted_text(name) + "> (line " +
                                   std::to_string(c->GetLineNum()) +
                                   "): the file is included twice (MJCF includes a file once)");
      if (depth >= kMaxNesting)
        throw ModelError(file, "<include> nested deeper than " + std::to_string(kMaxNesting));
      load(target.string(), depth + 1);
    }
  }
}

std::vector<const XMLElement*> Document::children(const XMLElement& e, const char* tag) const {
  std::vector<const XMLElement*> out;
  for (const XMLElement* c = e.FirstChildElement(); c; c = c->NextSiblingElement()) {
    if (std::strcmp(c->Name(), "include") == 0) {
      fs::path target(c->Attribute("file"));
      if (target.is_relative()) target = fs::path(path_).parent_path() / target;
      const tinyxml2::XMLDocument* doc = included_.at(fs::weakly_canonical(target).string());
      for (const XMLElement* i : children(*doc->FirstChildElement("mujoco"), tag)) out.push_back(i);
    } else if (!tag || std::strcmp(c->Name(), tag) == 0) {
      out.push_back(c);
    }
  }
  return out;
}

std::vector<const XMLElement*> Document::sections(const char* tag) const {
  return children(*root_, tag);
}

void Document::read_defaults(const XMLElement& d, const std::string& parent, int depth) {
  if (depth > kMaxNesting) fail(d, "<default> classes nested deeper than 64");
  const char* own = d.Attribute("class");
  const std::string name = own ? own : (parent.empty() ? "main" : "");
  if (name.empty()) fail(d, "a nested <default> needs a class name");
  if (parent.empty() && name == "main" && classes_.count("main")) {
    classes_["main"].first.push_back(&d);  // a second top-level <default> (an included file's)
  } else if (!classes_.emplace(name, std::pair{std::vector{&d}, parent}).second) {
    fail(d, "default class " + quoted_text(name) + " is defined twice");
  }
  for (const XMLElement* c : children(d, "default")) read_defaults(*c, name, depth + 1);
}

void Document::read_compiler(const XMLElement& c) {
  const std::string none;
  if (const char* angle = c.Attribute("angle")) {
    if (std::strcmp(angle, "degree") != 0 && std::strcmp(angle, "radian") != 0)
      fail(c, "angle: expected \"degree\" or \"radian\"");
    compiler_.degrees = std::strcmp(angle, "degree") == 0;
  }
  if (const char* seq = c.Attribute("eulerseq")) {
    compiler_.eulerseq = seq;
    if (compiler_.eulerseq.size() != 3 ||
        compiler_.eulerseq.find_first_not_of("xyzXYZ") != std::string::npos)
      fail(c, "eulerseq: expected 3 of x, y, z, X, Y, Z");
  }
  if (const char* from = c.Attribute("inertiafromgeom")) {
    const std::string f = from;
    if (f == "auto")
      compiler_.inertia_from_geom = Compiler::FromGeom::automatic;
    else if (f == "true")
      compiler_.inertia_from_geom = Compiler::FromGeom::always;
    else if (f == "false")
      compiler_.inertia_from_geom = Compiler::FromGeom::never;
    else
      fail(c, "inertiafromgeom: expected auto, true or false");
  }
  if (const std::vector<double> g = numbers(c, "inertiagrouprange", none, 2); !g.empty())
    compiler_.group_lo = static_cast<int>(g[0]), compiler_.group_hi = static_cast<int>(g[1]);
  compiler_.boundmass = number(c, "boundmass", none, compiler_.boundmass);
  compiler_.boundinertia = number(c, "boundinertia", none, compiler_.boundinertia);
  compiler_.settotalmass = number(c, "settotalmass", none, compiler_.settotalmass);
  compiler_.balanceinertia = flag(c, "balanceinertia", none, compiler_.balanceinertia);
  compiler_.autolimits = flag(c, "autolimits", none, compiler_.autolimits);
  compiler_.exact_mesh_inertia = flag(c, "exactmeshinertia", none, compiler_.exact_mesh_inertia);
  if (const char* coordinate = c.Attribute("coordinate");
      coordinate && std::strcmp(coordinate, "local") != 0)
    fail(c, "coordinate=\"global\" is refused (MuJoCo removed it; femdyn reads local frames)");
  if (const char* dir = c.Attribute("assetdir")) compiler_.meshdir = dir;
  if (const char* dir = c.Attribute("meshdir")) compiler_.meshdir = dir;
}

std::string Document::class_of(const XMLElement& e, const std::string& inherited) const {
  const char* own = e.Attribute("class");
  const std::string name = own ? own : (inherited.empty() ? "main" : inherited);
  if (!classes_.count(name)) fail(e, "class " + quoted_text(name) + " is not defined");
  return name;
}

std::string Document::childclass_of(const XMLElement& e, const std::string& inherited) const {
  const char* own = e.Attribute("childclass");
  if (!own) return inherited;
  if (!classes_.count(own)) fail(e, "childclass " + quoted_text(own) + " is not defined");
  return own;
}

const char* Document::attr(const XMLElement& e, const char* name, const std::string& cls) const {
  if (const char* own = e.Attribute(name)) return own;
  for (std::string c = cls; !c.empty();) {
    const auto it = classes_.find(c);
    if (it == classes_.end()) break;
    const std::vector<const XMLElement*>& sections = it->second.first;
    for (auto d = sections.rbegin(); d != sections.rend(); ++d)
      for (const XMLElement* x : children(**d, e.Name()))
        if (const char* v = x->Attribute(name)) return v;
    c = it->second.second;
  }
  return nullptr;
}

std::vector<double> Document::numbers(const XMLElement& e, const char* name, const std::string& cls,
                                      int count) const {
  const char* text = cls.empty() ? e.Attribute(name) : attr(e, name, cls);
  if (!text) return {};
  std::vector<double> out;
  const char* at = text;
  while (true) {
    while (*at == ' ' || *at == '\t' || *at == '\n' || *at == '\r') ++at;
    if (!*at) break;
    char* end = nullptr;
    const double x = std::strtod(at, &end);
    if (end == at || (*end && !std::strchr(" \t\r\n", *end)))
      fail(e, std::string(name) + "=" + quoted_text(text) + ": not a list of numbers");
    if (!std::isfinite(x)) fail(e, std::string(name) + ": NaN or Inf");
    if (std::abs(x) > kMaxMagnitude) fail(e, std::string(name) + ": " + out_of_range_text(x));
    out.push_back(x);
    at = end;
  }
  if (count >= 0 && static_cast<int>(out.size()) != count)
    fail(e, std::string(name) + ": expected " + std::to_string(count) + " number" +
                (count == 1 ? "" : "s") + ", got " + std::to_string(out.size()));
  return out;
}

double Document::number(const XMLElement& e, const char* name, const std::string& cls,
                        double fallback) const {
  const std::vector<double> x = numbers(e, name, cls, 1);
  return x.empty() ? fallback : x[0];
}

Vec3 Document::vec3(const XMLElement& e, const char* name, const std::string& cls,
                    const Vec3& fallback) const {
  const std::vector<double> x = numbers(e, name, cls, 3);
  return x.empty() ? fallback : Vec3(x[0], x[1], x[2]);
}

bool Document::flag(const XMLElement& e, const char* name, const std::string& cls,
                    bool fallback) const {
  const char* text = cls.empty() ? e.Attribute(name) : attr(e, name, cls);
  if (!text) return fallback;
  if (std::strcmp(text, "true") == 0) return true;
  if (std::strcmp(text, "false") == 0) return false;
  fail(e, std::string(name) + "=" + quoted_text(text) + ": expected true or false");
}

std::string Document::who(const XMLElement& e) const {
  const char* name = e.Attribute("name");
  return "<" + echo_text(e.Name()) + (name ? " name=" + quoted_text(name) : "") + "> (line " +
         std::to_string(e.GetLineNum()) + ")";
}

const std::string& Document::file_of(const XMLElement& e) const {
  return file_.at(e.GetDocument());
}

void Document::fail(const XMLElement& e, const std::string& problem) const {
  throw ModelError(file_of(e), who(e) + ": " + problem);
}

}  // namespace femdyn::mjcf
