// The page `femdyn view` writes: one HTML file with three.js, the page's script and the scene
// (view/scene.hpp) inline, so that it opens offline from anywhere, without a server.
#pragma once
#include <string>

#include "core/model/model.hpp"
#include "io/params.hpp"
#include "view/motion.hpp"

namespace femdyn::view {

// The page of a scene: web/view.html with its placeholders filled.
std::string page_html(const Json& scene);

// Writes it atomically (io/atomic_file.hpp): never half a file; an existing file is replaced
// only with `replace` (--force). Errors are femdyn::Error naming the path.
void write_page(const std::string& path, const Json& scene, bool replace);

// The page of `model`, read from `model_path` (a URDF's or MJCF's visuals are drawn; the page names
// the file without its directory), showing `motion`: what `femdyn view` and Model.view write.
void write_model_page(const std::string& path, const Model& model, const std::string& model_path,
                      const Motion& motion, bool replace);

}  // namespace femdyn::view
