// Shared by the fuzz targets (json_model.cpp, urdf.cpp, vector.cpp, csv.cpp): what counts as a
// bug.
//   Expected: femdyn::ModelError or another std::runtime_error whose message is one line of
//   printable text (core/model/message.hpp printable_text), or a failed Status.
//   A bug (abort(), so libFuzzer keeps the input): a crash or sanitizer report, a hang (libFuzzer
//   -timeout), an exception of any other type, an error message (what()) that holds a control
//   character (C0 including a line break, DEL, C1) or a byte that is not UTF-8, and — with the
//   NaN check on — NaN or Inf in M^s, h, Q or q̈ while forward_dynamics() returned ok and every
//   number of the input was finite.
#pragma once
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <typeinfo>

#include "core/model/message.hpp"
#include "core/model/model.hpp"
#include "io/params.hpp"

namespace femdyn::fuzz {

// Models with more bodies are skipped before compile(): the fuzzer's time goes to many small
// inputs, not to a few big ones (libFuzzer's -max_len bounds the text itself).
constexpr std::size_t kMaxBodies = 200;

// The NaN check's switch: FEMDYN_FUZZ_NAN_CHECK=0|1 in the environment, else the build's
// default (CMake option FEMDYN_FUZZ_NAN_CHECK, ON). Turn it off only while a known NaN for
// overflowing but finite input is being fixed (docs/robustness.md#fuzzing).
bool nan_check();

[[noreturn]] void bug(const std::string& what);

// FEMDYN_FUZZ_VERBOSE=1: each input's outcome on stderr (expected errors, Status), for replays.
void note(const std::string& what);

std::uint64_t hash(const std::uint8_t* data, std::size_t size);  // FNV-1a

bool all_finite(const Json& j);  // every number in the document is finite

// A message that would write a control character to the terminal (or a second line) is a bug.
void check_message(const char* stage, const std::string& what);

// Runs fn(); ModelError and std::runtime_error are expected and return false, if their message
// is printable (check_message); any other exception is a bug. True if fn() returned normally.
template <class F>
bool expected_errors_only(const char* stage, F&& fn) {
  try {
    fn();
    return true;
  } catch (const std::runtime_error& e) {  // ModelError, CliError, other one-line errors
    check_message(stage, e.what());
    note(std::string(stage) + ": expected error: " + e.what());
    return false;
  } catch (const std::exception& e) {
    bug(std::string(stage) + ": unexpected exception " + typeid(e).name() + ": " + e.what());
  } catch (...) {
    bug(std::string(stage) + ": unexpected exception of a non-std type");
  }
}

// One evaluation: forward_dynamics() and evaluate() at a small state derived from `seed`
// (q in ±0.5, q̇ and τ in ±1), with the NaN check when `inputs_finite`.
void evaluate_once(const Model& model, std::uint64_t seed, bool inputs_finite);

}  // namespace femdyn::fuzz
