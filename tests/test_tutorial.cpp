// docs/tutorial.md never goes stale: its JSON files are written to a scratch directory, every
// command of its sh blocks is run there (femdyn on the PATH, models/ linked), and its C++
// example is the file the build compiles.
#include <array>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/helpers.hpp"

namespace fs = std::filesystem;
using femdyn::test::read_file;  // (its own: a unity build must not lend it)

namespace {

struct Block {
  std::string info;  // what follows ``` (e.g. "json file=x.json", "sh", "sh fails")
  std::string text;
};

std::vector<Block> blocks(const std::string& markdown) {
  std::vector<Block> out;
  std::istringstream in(markdown);
  std::string line;
  Block* open = nullptr;
  while (std::getline(in, line)) {
    if (line.rfind("```", 0) == 0) {
      if (open) {
        open = nullptr;
      } else {
        out.push_back({line.substr(3), ""});
        open = &out.back();
      }
    } else if (open) {
      open->text += line + "\n";
    }
  }
  return out;
}

std::pair<int, std::string> sh(const std::string& dir, const std::string& command) {
  const std::string bin = fs::path(FEMDYN_BINARY).parent_path().string();
  std::ofstream(fs::path(dir) / "command.sh") << command << "\n";
  const std::string full = "cd '" + dir + "' && PATH='" + bin + "':\"$PATH\" sh command.sh 2>&1";
  FILE* p = popen(full.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (p && std::fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int status = p ? pclose(p) : -1;
  return {WEXITSTATUS(status), out};
}

}  // namespace

TEST_CASE("every command of docs/tutorial.md runs as the tutorial says", "[docs][tutorial]") {
  const fs::path source = FEMDYN_SOURCE_DIR;
  const auto all = blocks(read_file(source / "docs/tutorial.md"));
  const fs::path dir = fs::temp_directory_path() / "femdyn_tutorial";
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::create_directory_symlink(source / "models", dir / "models");

  int files = 0, commands = 0;
  for (const Block& b : all) {
    if (b.info.rfind("json file=", 0) == 0) {
      std::ofstream(dir / b.info.substr(10)) << b.text;
      ++files;
    } else if (b.info.rfind("cpp file=", 0) == 0) {
      INFO(b.info);
      CHECK(b.text == read_file(source / b.info.substr(9)));
    } else if (b.info == "sh" || b.info == "sh fails") {
      std::istringstream lines(b.text);
      std::string command;
      while (std::getline(lines, command)) {
        if (command.empty()) continue;
        const auto [code, out] = sh(dir.string(), command);
        INFO(command << "\n" << out);
        if (b.info == "sh") {
          CHECK(code == 0);
        } else {
          CHECK(code != 0);
          CHECK(std::count(out.begin(), out.end(), '\n') == 1);  // one line
        }
        ++commands;
      }
    }
  }
  CHECK(files >= 2);
  CHECK(commands >= 15);
}
