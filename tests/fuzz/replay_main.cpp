// The fuzz targets without libFuzzer (ctest, ordinary builds): every input named on the command
// line goes to LLVMFuzzerTestOneInput once. An argument is a file, a directory (its files,
// sorted, not recursive, names starting with '.' skipped) or DIR/*SUFFIX (those files of DIR).
// A bug aborts (tests/fuzz/common.hpp); otherwise prints the count and exits 0.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  std::vector<fs::path> inputs;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i], suffix;
    if (const auto star = arg.rfind("/*"); star != std::string::npos) {
      suffix = arg.substr(star + 2);
      arg = arg.substr(0, star);
    }
    if (fs::is_regular_file(arg)) {
      inputs.push_back(arg);
      continue;
    }
    if (!fs::is_directory(arg)) {
      std::fprintf(stderr, "fuzz replay: %s: no such file or directory\n", argv[i]);
      return 2;
    }
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(arg)) {
      const std::string name = e.path().filename().string();
      if (!e.is_regular_file() || name.front() == '.') continue;
      if (name.size() < suffix.size() ||
          name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
        continue;
      files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    inputs.insert(inputs.end(), files.begin(), files.end());
  }
  for (const fs::path& p : inputs) {
    std::ifstream f(p, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    if (!f && !f.eof()) {
      std::fprintf(stderr, "fuzz replay: cannot read %s\n", p.c_str());
      return 2;
    }
    std::fprintf(stderr, "fuzz replay: %s\n", p.c_str());
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("fuzz replay: %zu inputs, no bug\n", inputs.size());
  return 0;
}
