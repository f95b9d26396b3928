// Reading an input file (model, URDF, actuation table) safely: only a regular file is read (a
// FIFO, device, socket or directory is refused before anything blocks), and at most
// kMaxFileBytes (core/model/limits.hpp). Errors are ModelError naming the path.
#pragma once
#include <string>

namespace femdyn {

std::string read_input_file(const std::string& path);

}  // namespace femdyn
