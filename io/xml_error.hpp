// The one-line problem of an XML text tinyxml2 could not parse (URDF and MJCF readers).
#pragma once
#include <tinyxml2.h>

#include <string>

namespace femdyn {

inline std::string xml_error_text(const tinyxml2::XMLDocument& doc) {
  const std::string line = std::to_string(doc.ErrorLineNum());
  if (doc.ErrorID() == tinyxml2::XML_ELEMENT_DEPTH_EXCEEDED)  // tinyxml2's fixed limit
    return "elements nested deeper than " + std::to_string(TINYXML2_MAX_ELEMENT_DEPTH) +
           " at line " + line +
           " (the XML reader's limit, which MuJoCo's shares: a chain of bodies that long must "
           "be split, or written as a URDF, whose links do not nest)";
  return "malformed XML at line " + line + ": " + doc.ErrorName();
}

}  // namespace femdyn
