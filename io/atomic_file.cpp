#include "io/atomic_file.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "core/model/errors.hpp"

namespace femdyn {

double AtomicFile::shortfall(double bytes) const {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::space_info space = fs::space(fs::absolute(tmp_, ec).parent_path(), ec);
  if (ec || bytes <= static_cast<double>(space.available)) return 0;
  return static_cast<double>(space.available);
}

AtomicFile::AtomicFile(std::string path, bool replace) : path_(std::move(path)) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (path_.empty()) throw Error("the output path is empty");
  // A C++ or Python caller may pass one; the system would see only the part before it.
  if (path_.find('\0') != std::string::npos)
    throw Error(path_ + ": the path contains a NUL character");
  if (fs::is_directory(path_, ec)) throw Error(path_ + ": is a directory");
  // A device, FIFO or socket is never renamed over (as root, /dev/full would be replaced).
  const fs::file_status st = fs::status(path_, ec);
  if (fs::exists(st) && !fs::is_regular_file(st))
    throw Error(path_ + ": is not a regular file (femdyn writes regular files only)");
  if (!replace && fs::exists(fs::symlink_status(path_, ec)))
    throw Error(path_ + ": exists (use --force to replace it)");
  const fs::path target(path_);
  tmp_ = (target.parent_path() /
          ("." + target.filename().string() + ".tmp-" + std::to_string(::getpid())))
             .string();
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_) throw Error(path_ + ": cannot write (directory missing or not writable)");
  open_ = true;
}

AtomicFile::~AtomicFile() { discard(); }

void AtomicFile::discard() {
  if (!open_) return;
  out_.close();
  std::remove(tmp_.c_str());
  open_ = false;
}

void AtomicFile::commit() {
  out_.flush();
  const bool written = static_cast<bool>(out_);
  out_.close();
  if (!written || out_.fail()) {
    discard();
    throw Error(path_ + ": write failed (disk full?); nothing was written");
  }
  std::error_code ec;
  std::filesystem::rename(tmp_, path_, ec);
  if (ec) {
    discard();
    throw Error(path_ + ": cannot rename into place: " + ec.message());
  }
  open_ = false;
}

std::string input_at(const std::string& out, const std::vector<RunInput>& inputs) {
  std::error_code ec;
  for (const auto& [path, label] : inputs)
    if (!path.empty() && std::filesystem::equivalent(out, path, ec)) return label;
  return "";
}

}  // namespace femdyn
