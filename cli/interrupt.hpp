// SIGINT and SIGTERM during a long command (simulate, track): a flag the run asks after its
// steps (and simulate inside them), the previous handlers restored when the guard goes. The
// command then exits 130, leaving no half output file.
#pragma once
#include <csignal>

namespace femdyn::cli {

extern volatile std::sig_atomic_t g_interrupted;

class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction old_int_ {
  }, old_term_{};
};

}  // namespace femdyn::cli
