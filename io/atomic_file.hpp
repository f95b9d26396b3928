// AtomicFile: an output file that appears whole or not at all. It is written to a temporary
// file beside the target (same directory, so the rename is atomic) and renamed into place by
// commit(); until then the target keeps its old content. An AtomicFile destroyed without
// commit() (an error, an exception, an interruption) removes its temporary file. An existing
// target is replaced only if `replace` is set (the commands' --force).
#pragma once
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace femdyn {

class AtomicFile {
 public:
  // Throws std::runtime_error("PATH: exists (use --force to replace it)") or
  // ("PATH: cannot write …") before anything is written.
  AtomicFile(std::string path, bool replace);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return out_; }
  // Flushes, checks that every write succeeded (a full disk is an error, not "wrote"), and
  // renames the temporary file onto the target. Throws std::runtime_error naming the path.
  void commit();
  void discard();  // removes the temporary file now
  const std::string& path() const { return path_; }
  const std::string& temporary() const { return tmp_; }
  // The bytes free on the output's disk when `bytes` would not fit there, else 0 (also when the
  // free space cannot be read): the one check of every writer that knows its size up front.
  double shortfall(double bytes) const;

 private:
  std::string path_, tmp_;
  std::ofstream out_;
  bool open_ = false;
};

// An input of a run: its path and what it is in a message ("the model file itself").
using RunInput = std::pair<std::string, std::string>;

// What `out` would destroy: the label of the first input it is (the same file through symlinks
// and relative paths, whether or not --force is given), or "". Every command and the Python
// module ask it before writing: --force replaces an older output, never an input of the run.
std::string input_at(const std::string& out, const std::vector<RunInput>& inputs);

}  // namespace femdyn
