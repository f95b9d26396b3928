// The page's assets, embedded at build time by view/embed.cmake from web/: three.js (its module
// files and OrbitControls turned into one classic script), the page template and its script.
#pragma once
#include <string_view>

namespace femdyn::view {

std::string_view three_js();
std::string_view page_template();  // web/view.html
std::string_view page_script();    // web/view.js

}  // namespace femdyn::view
