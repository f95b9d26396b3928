// Robot files as femdyn JSON documents (io/robot_reference.hpp): a URDF or MJCF given directly
// or by reference from a JSON file, and its errors named by the robot file's own elements.
#include "io/robot_reference.hpp"

#include <cctype>
#include <filesystem>

#include "core/model/errors.hpp"
#include "core/model/names.hpp"
#include "io/input_file.hpp"
#include "io/json_text.hpp"
#include "io/mjcf_loader.hpp"
#include "io/model_format.hpp"
#include "io/urdf_loader.hpp"

namespace femdyn {

void apply_overrides(const Json& root, const Params& p, Json& doc) {
  for (const char* key : {"name", "description", "gravity"})
    if (root.contains(key)) doc[key] = root[key];
  for (const char* list : {"loads", "frames", "constraints", "springs"})
    if (root.contains(list)) {
      if (!root[list].is_array()) p.fail(list, "expected an array");
      if (!doc.contains(list)) doc[list] = Json::array();
      for (const Json& l : root[list]) doc[list].push_back(l);
    }
}

Params plugin_form(const Json& root, const std::string& source) {
  Params p(root, source + ": ");
  p.allow_only({"model", "params", "name", "description", "gravity", "loads", "frames",
                "constraints", "springs", "$schema"});
  return p;
}

// Errors found after conversion name the robot file's link (MJCF: body) and joint, not the
// generated JSON path: "robot.urdf: /bodies/3/joint: …" becomes "robot.urdf: joint 'elbow'
// (link 'forearm'): …".
[[noreturn]] void rethrow_for_robot_file(const ModelError& e, const Json& doc,
                                         const std::string& path) {
  const std::string link = is_mjcf_path(path) ? "body" : "link";
  const std::string mimic = is_mjcf_path(path) ? "' <equality>" : "' <mimic>";
  std::string msg = e.what();
  // "/bodies/N…" names a joint and its child link; "/couplings/N…" a joint's <mimic>.
  for (const std::string section : {"bodies", "couplings"}) {
    const std::string prefix = path + ": /" + section + "/";
    if (msg.rfind(prefix, 0) != 0) continue;
    std::size_t i = prefix.size(), end = i;
    while (end < msg.size() && std::isdigit(static_cast<unsigned char>(msg[end]))) ++end;
    const std::size_t rest = msg.find(": ", end);
    if (end == i || rest == std::string::npos) break;
    const Json& item = doc[section][std::stoul(msg.substr(i, end - i))];
    const std::string who = section == "bodies"
                                ? "joint '" + item["joint"]["name"].get<std::string>() + "' (" +
                                      link + " '" + item["name"].get<std::string>() + "')"
                                : "joint '" + item["joint"].get<std::string>() + mimic;
    msg = path + ": " + who + msg.substr(rest);
  }
  throw ModelError("", msg);
}

namespace {

Json urdf_document(const std::string& urdf, UrdfOptions urdf_options, const LoadOptions& options) {
  UrdfResult r = read_urdf(urdf, urdf_options);
  if (options.warn)
    for (const std::string& w : r.warnings) options.warn(w);
  return std::move(r.model);
}

Json mjcf_document(const std::string& mjcf, MjcfOptions mjcf_options, const LoadOptions& options) {
  MjcfResult r = read_mjcf(mjcf, mjcf_options);
  if (options.warn)
    for (const std::string& w : r.warnings) options.warn(w);
  return std::move(r.model);
}

}  // namespace

// A URDF or MJCF file as femdyn JSON. --floating-base is for URDF: MJCF floats a body by its own
// free joint.
Json robot_document(const std::string& path, const LoadOptions& options) {
  if (is_urdf_path(path))
    return urdf_document(
        path, {.floating_base = options.floating_base, .balance_inertia = options.balance_inertia},
        options);
  if (options.floating_base)
    throw ModelError(path,
                     "--floating-base is for URDF models: an MJCF model floats a body by its "
                     "own <freejoint/>");
  return mjcf_document(path,
                       {.balance_inertia = options.balance_inertia,
                        .exact_mesh_inertia = options.exact_mesh_inertia},
                       options);
}

namespace {

// A reference's "file" as a path: relative to the JSON file `path` that names it, or absolute.
std::filesystem::path beside(const std::string& path, const std::string& file) {
  const std::filesystem::path f(file);
  return f.is_relative() ? std::filesystem::path(path).parent_path() / f : f;
}

// The robot file a reference's "file" names (relative to the JSON file `path`), of the kind
// `is_kind` says, read by `read` into femdyn JSON with the reference's own name, description,
// gravity and loads on top; a problem in it reported at /params/file. Also its path.
template <class Read>
std::pair<Json, std::string> referenced(const std::string& path, const Json& root, const Params& p,
                                        const Params& params, bool (*is_kind)(const std::string&),
                                        const char* expected, const Read& read) {
  const std::filesystem::path file = beside(path, params.string("file"));
  if (!is_kind(file.string())) params.fail("file", expected);
  Json doc;
  try {
    doc = read(file.string());
  } catch (const Error& e) {
    params.fail("file", e.what());
  }
  apply_overrides(root, p, doc);
  return {std::move(doc), file.string()};
}

// {"model": "mjcf", "params": {"file", "balance_inertia"}}: the MJCF file it names.
std::pair<Json, std::string> mjcf_reference(const std::string& path, const Json& root,
                                            const Params& p, const Params& params,
                                            const LoadOptions& options) {
  params.allow_only({"file", "balance_inertia"});
  const bool balance = options.balance_inertia || params.boolean_or("balance_inertia", false);
  return referenced(path, root, p, params, is_mjcf_path, "expected an MJCF file (<mujoco>)",
                    [&](const std::string& file) {
                      return mjcf_document(file, {.balance_inertia = balance}, options);
                    });
}

}  // namespace

// A JSON file {"model": "urdf", …}: the URDF it names as femdyn JSON (with the file's own name,
// description, gravity and loads), and that URDF's path for messages; nullopt for any other file.
std::optional<std::pair<Json, std::string>> robot_reference(const std::string& path,
                                                            const Json& root,
                                                            const LoadOptions& options) {
  if (!root.is_object() || !root.contains("model") ||
      (root["model"] != kUrdfReference && root["model"] != kMjcfReference))
    return std::nullopt;
  const Params p = plugin_form(root, path);
  const Params params = p.child("params");
  if (root["model"] == kMjcfReference) return mjcf_reference(path, root, p, params, options);
  params.allow_only({"file", "root_joint", "balance_inertia"});
  const std::string root_joint = params.has("root_joint") ? params.string("root_joint") : "fixed";
  if (root_joint != "fixed" && root_joint != "free")
    params.fail("root_joint", "expected \"fixed\" or \"free\", got " + quoted_text(root_joint));
  const bool balance = options.balance_inertia || params.boolean_or("balance_inertia", false);
  return referenced(
      path, root, p, params, is_urdf_path, "expected a *.urdf file", [&](const std::string& file) {
        return urdf_document(
            file, {.floating_base = root_joint == "free", .balance_inertia = balance}, options);
      });
}

// --balance-inertia repairs what an exporter wrote; a JSON model's inertias are the author's own,
// refused with the element named, to be corrected there.
void refuse_balance_on_json(const std::string& path, const LoadOptions& options) {
  if (options.balance_inertia)
    throw ModelError(path,
                     "--balance-inertia is for URDF models (and URDF references, \"params\": "
                     "{\"balance_inertia\": true}): a JSON model's inertias are its own, to be "
                     "corrected where a refusal names them");
}

std::string robot_file_of(const std::string& path) {
  if (is_urdf_path(path) || is_mjcf_path(path)) return path;
  Json root;
  try {
    root = parse_json(read_input_file(path), path);
  } catch (const Error&) {
    return "";  // (not JSON either: no robot file)
  }
  if (!root.is_object() || !root.contains("model") || !root.contains("params")) return "";
  const Json& model = root["model"];
  const Json& params = root["params"];
  if (model != kUrdfReference && model != kMjcfReference) return "";
  if (!params.is_object() || !params.contains("file") || !params["file"].is_string()) return "";
  return beside(path, params["file"].get<std::string>()).string();
}

std::vector<std::pair<std::string, std::string>> model_inputs(const std::string& path) {
  std::vector<std::pair<std::string, std::string>> inputs = {{path, "the model file itself"}};
  if (const std::string robot = robot_file_of(path); !robot.empty() && robot != path)
    inputs.emplace_back(robot, "the robot file the model refers to (" + robot + ")");
  return inputs;
}

}  // namespace femdyn
