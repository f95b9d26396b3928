// Rows of a batch spread over threads: thread t takes a contiguous block of rows and a Workspace
// of its own (a Workspace is per-thread scratch; the Model is immutable and shared).
#pragma once
#include <algorithm>
#include <exception>
#include <string>
#include <thread>
#include <vector>

#include "core/workspace/workspace.hpp"
#include "python/arrays.hpp"

namespace femdyn::python {

// The threads a batch of k rows uses: `requested` (0: one per core), at most one per row and
// kMaxBatchThreads. A negative request is a ValueError.
inline constexpr int kMaxBatchThreads = 256;
inline int batch_threads(Eigen::Index k, int requested) {
  if (requested < 0 || requested > kMaxBatchThreads)
    throw pybind11::value_error("threads: expected an integer in [0, " +
                                std::to_string(kMaxBatchThreads) + "], got " +
                                std::to_string(requested));
  const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int t = requested > 0 ? requested : hw;
  return static_cast<int>(std::max<Eigen::Index>(1, std::min<Eigen::Index>(t, k)));
}

// Calls row(ws, scratch, i) for i in [0, k) on `threads` threads, each with a Workspace and a
// `make()` of its own (per-thread buffers beside the Workspace, e.g. a DerivativeWorkspace). An
// exception in a thread stops that thread's block; the one of the lowest block is rethrown after
// every thread has joined.
template <class Make, class Row>
void for_each_row_with(const Model& model, Eigen::Index k, int threads, const Make& make,
                       const Row& row) {
  std::vector<std::exception_ptr> errors(threads);
  const auto block = [&](int t) {
    try {
      Workspace ws(model);
      auto scratch = make();
      const Eigen::Index begin = k * t / threads, end = k * (t + 1) / threads;
      for (Eigen::Index i = begin; i < end; ++i) row(ws, scratch, i);
    } catch (...) {
      errors[t] = std::current_exception();
    }
  };
  std::vector<std::jthread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(block, t);
  block(0);
  pool.clear();  // joins
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

// Calls row(ws, i) for i in [0, k) on `threads` threads (for_each_row_with, no scratch).
template <class Row>
void for_each_row(const Model& model, Eigen::Index k, int threads, const Row& row) {
  for_each_row_with(
      model, k, threads, [] { return 0; }, [&](Workspace& ws, int, Eigen::Index i) { row(ws, i); });
}

}  // namespace femdyn::python
