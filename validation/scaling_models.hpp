// Generated mechanisms of any size for measuring and testing how loading and compiling grow
// with the number of bodies (femdyn_bench's load benchmarks, docs/performance.md; the hardening
// tests). Each body carries one element, a 1 kg lumped point at a named node, so the JSON
// reader, the node level and the correlation table all see n of everything.
#pragma once
#include <string>

namespace femdyn::scaling {

// The model as femdyn JSON text (written directly, not through a JSON library, so that making
// a 200,000-body document costs little next to reading it):
//   chain: body i hangs from body i − 1 on a prismatic joint along x, y, z in turn, 0.1 m
//          apart (a chain of revolute joints that long is singular to double precision);
//   tree:  body i hangs from body (i − 1) / 2, a binary tree, on a revolute joint about
//          x, y, z in turn, links of 0.1 m along z.
inline std::string model_json(int bodies, bool tree) {
  static const char* axes[] = {"[1, 0, 0]", "[0, 1, 0]", "[0, 0, 1]"};
  std::string text = R"({"name": ")" + std::string(tree ? "tree" : "chain") +
                     R"(", "gravity": [0, 0, -9.81], "bodies": [)";
  text.reserve(text.size() + 220 * static_cast<std::size_t>(bodies));
  for (int i = 0; i < bodies; ++i) {
    const int parent = tree ? (i - 1) / 2 : i - 1;
    text += (i ? ",\n" : "\n");
    text += R"({"name": "b)" + std::to_string(i) + R"(", "parent": ")" +
            (i == 0 ? std::string("world") : "b" + std::to_string(parent)) +
            R"(", "joint": {"type": ")" + (tree ? "revolute" : "prismatic") + R"(", "axis": )" +
            axes[i % 3] +
            R"(, "origin": {"xyz": [0, 0, 0.1]}}, "nodes": {"p": [0.05, 0, 0.05]}, )"
            R"("elements": [{"type": "lumped_point", "node": "p", "mass": 1}]})";
  }
  return text + "\n]}\n";
}

}  // namespace femdyn::scaling
