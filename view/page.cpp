#include "view/page.hpp"

#include <filesystem>
#include <stdexcept>

#include "io/input_file.hpp"
#include "io/mjcf_loader.hpp"
#include "io/output.hpp"
#include "io/urdf_loader.hpp"
#include "models/model_files.hpp"
#include "view/assets.hpp"
#include "view/scene.hpp"

namespace femdyn::view {
namespace {

// The template with `<!--femdyn:NAME-->` replaced by `text` (the placeholder appears once).
void fill(std::string& page, const std::string& name, std::string_view text) {
  const std::string mark = "<!--femdyn:" + name + "-->";
  const std::size_t at = page.find(mark);
  if (at == std::string::npos) throw std::logic_error("web/view.html has no " + mark);
  page.replace(at, mark.size(), text);
}

// JSON inside <script>, compact, invalid UTF-8 replaced: '<' only occurs in strings, where
// \u003c reads back the same and no name can end the script early ("</script>") or open a
// comment ("<!--").
std::string script_safe_json(const Json& doc) {
  const std::string text = doc.dump(-1, ' ', false, Json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    if (c == '<')
      out += "\\u003c";
    else
      out += c;
  }
  return out;
}

// Text inside an HTML element: & < > escaped.
std::string html_text(const std::string& s) {
  std::string out;
  for (const char c : s) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else
      out += c;
  }
  return out;
}

}  // namespace

std::string page_html(const Json& scene) {
  std::string page(page_template());
  fill(page, "title", html_text("femdyn view: " + scene.at("model").get<std::string>()));
  fill(page, "three", three_js());
  fill(page, "scene", script_safe_json(scene));
  fill(page, "script", page_script());
  return page;
}

void write_page(const std::string& path, const Json& scene, bool replace) {
  write_file_atomic(path, page_html(scene), replace);
}

void write_model_page(const std::string& path, const Model& model, const std::string& model_path,
                      const Motion& motion, bool replace) {
  // The robot file's visuals, also where a JSON file refers to it (the same robot, drawn alike).
  const std::string robot = robot_file_of(model_path);
  const std::vector<Visual> visuals = is_urdf_path(robot)
                                          ? urdf_visuals(read_input_file(robot), robot)
                                      : is_mjcf_path(robot) ? read_mjcf(robot).visuals
                                                            : std::vector<Visual>{};
  const std::string name = std::filesystem::path(model_path).filename().string();
  write_page(path, scene_json(model, motion, visuals, name.empty() ? model.name : name), replace);
}

}  // namespace femdyn::view
