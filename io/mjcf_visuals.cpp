// What MJCF bodies look like (mjcf_reading.hpp: add_visuals), for `femdyn view`.
#include <cstring>
#include <filesystem>

#include "core/model/errors.hpp"
#include "io/mjcf_reading.hpp"

namespace femdyn::mjcf {
namespace {

// A geom's colour: its rgba, else its material's (MuJoCo's default grey is left to the page).
std::optional<Eigen::Vector4d> colour(const Document& doc, const XMLElement& geom,
                                      const std::string& cls) {
  std::vector<double> rgba = doc.numbers(geom, "rgba", cls, 4);
  if (rgba.empty())
    if (const char* name = doc.attr(geom, "material", cls))
      for (const XMLElement* asset : doc.sections("asset"))
        for (const XMLElement* m : doc.children(*asset, "material"))
          if (m->Attribute("name", name)) rgba = doc.numbers(*m, "rgba", doc.class_of(*m, ""), 4);
  if (rgba.empty()) return std::nullopt;
  return Eigen::Vector4d(rgba[0], rgba[1], rgba[2], rgba[3]);
}

}  // namespace

void add_visuals(const Document& doc, const XMLElement& body, const std::string& childclass,
                 const std::string& link, const Pose& frame, std::vector<Visual>& out) {
  for (const XMLElement* geom : doc.children(body, "geom")) try {
      const std::string cls = doc.class_of(*geom, childclass);
      if (doc.number(*geom, "group", cls, 0) > 2) continue;  // hidden in MuJoCo's viewer
      const char* type = doc.attr(*geom, "type", cls);
      if (type && (!std::strcmp(type, "plane") || !std::strcmp(type, "hfield"))) continue;
      Visual v;
      v.link = link;
      v.rgba = colour(doc, *geom, cls);
      Pose pose;
      if (type && !std::strcmp(type, "mesh")) {
        const MeshFile f = mesh_file_of(doc, *geom, cls);
        v.shape = "mesh";
        v.size = f.scale;
        v.mesh = f.source;
        if (f.file.empty()) {
          v.mesh_issue = "an inline mesh, which the page does not draw";
        } else {
          std::error_code ec;
          if (std::filesystem::is_regular_file(f.file, ec))
            v.mesh_path = f.file;
          else
            v.mesh_issue = "not found";
        }
        pose = pose_of(doc, *geom, cls);
      } else {
        const GeomShape g = geom_shape(doc, *geom, cls);
        pose = g.pose;
        v.shape = g.type;
        if (g.type == "box") v.size = 2 * g.size;  // full edges
        if (g.type == "capsule" || g.type == "cylinder") v.size = Vec3(g.size[0], 2 * g.size[1], 0);
        if (g.type == "sphere" || g.type == "ellipsoid") v.size = g.size;
      }
      const Pose placed = frame * pose;
      v.xyz = placed.p;
      v.R = placed.R;
      out.push_back(std::move(v));
    } catch (const Error& e) {  // listed by the page as not drawn; it breaks no load
      out.push_back(unread_visual(link, e.what()));
    }
}

}  // namespace femdyn::mjcf
