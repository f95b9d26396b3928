// Fuzz target: a URDF file's text. urdf_to_model() converts it (the finite-input check and the
// body limit look at that document); then, if it converted, the text goes the way a .urdf
// MODEL file goes (load_model: conversion, parse_model_json, compile, and the renaming of
// errors to the URDF's joints and links), and the model is evaluated once.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>

#include "core/model/errors.hpp"
#include "io/urdf_loader.hpp"
#include "models/model_files.hpp"
#include "tests/fuzz/common.hpp"

using namespace femdyn;

namespace {

// load_model() reads a file: one scratch file per process, rewritten for every input.
const std::string& scratch_path() {
  static const std::string path = [] {
    const char* dir = std::getenv("TMPDIR");
    std::string p = std::string(dir && *dir ? dir : "/tmp") + "/femdyn-fuzz-" +
                    std::to_string(getpid()) + ".urdf";
    std::atexit([] { std::remove(scratch_path().c_str()); });
    return p;
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::optional<Model> model;
  bool finite = true;
  fuzz::expected_errors_only("urdf load", [&] {
    const UrdfResult r = urdf_to_model(text, "fuzz.urdf");
    if (r.model.contains("bodies") && r.model["bodies"].size() > fuzz::kMaxBodies)
      return fuzz::note("skipped: too many bodies");
    finite = fuzz::all_finite(r.model);
    {
      std::ofstream f(scratch_path(), std::ios::binary | std::ios::trunc);
      f.write(text.data(), static_cast<std::streamsize>(text.size()));
      if (!f) fuzz::bug("cannot write " + scratch_path());
    }
    model.emplace(load_model(scratch_path()));
  });
  if (model)
    fuzz::expected_errors_only(
        "urdf evaluation", [&] { fuzz::evaluate_once(*model, fuzz::hash(data, size), finite); });
  return 0;
}
