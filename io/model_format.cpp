#include "io/model_format.hpp"

#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace femdyn {

ModelFormat model_format(const std::string& path) {
  std::string lower = path;
  for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  const auto ends = [&](const std::string& ext) {
    return lower.size() >= ext.size() &&
           lower.compare(lower.size() - ext.size(), ext.size(), ext) == 0;
  };
  if (ends(".urdf") || ends(".xacro")) return ModelFormat::urdf;
  if (ends(".json")) return ModelFormat::json;
  if (ends(".mjcf")) return ModelFormat::mjcf;
  // By content: the first element's name, past <?xml …?>, <!-- … --> and blanks.
  std::error_code error;  // (a FIFO or device is never opened: opening one may block)
  if (!std::filesystem::is_regular_file(path, error)) return ModelFormat::json;
  std::ifstream in(path, std::ios::binary);
  if (!in) return ModelFormat::json;
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::size_t at = 0;
  while (at < head.size()) {
    at = head.find_first_not_of(" \t\r\n", at);
    if (at == std::string::npos || head[at] != '<') return ModelFormat::json;
    std::string end;  // of a declaration or comment skipped
    if (head.compare(at, 5, "<?xml") == 0) {
      end = "?>";
    } else if (head.compare(at, 4, "<!--") == 0) {
      end = "-->";
    } else {
      const auto opens = [&](const char* tag) {
        const std::size_t n = std::strlen(tag);
        return head.compare(at, n, tag) == 0 &&
               (at + n == head.size() || !std::isalnum(static_cast<unsigned char>(head[at + n])));
      };
      if (opens("<mujoco")) return ModelFormat::mjcf;
      return opens("<robot") ? ModelFormat::urdf : ModelFormat::json;
    }
    at = head.find(end, at);
    if (at == std::string::npos) return ModelFormat::json;
    at += end.size();
  }
  return ModelFormat::json;
}

}  // namespace femdyn
