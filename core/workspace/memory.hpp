// femdyn's one memory-limit convention (docs/robustness.md, "Memory"). Work whose memory grows
// with the input (n x n matrices, samples, table rows, printed output) is estimated before it is
// allocated and refused beyond a limit: what the caller was given (`--max-memory GB`,
// `max_memory=` in GB) or else half of the memory available (MemAvailable in /proc/meminfo;
// unlimited where it cannot be read). A refusal is one line: what needs how much, the limit,
// and how to proceed.
#pragma once
#include <stdexcept>
#include <string>

namespace femdyn {

struct Model;

// Refused up front: what() is the one line memory_refusal() gives.
class MemoryRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bytes of a dense rows x cols matrix of doubles.
inline double dense_bytes(double rows, double cols) { return 8 * rows * cols; }

// "812 kB", "4.4 MB", "1.23 GB"; "unlimited" for infinity.
std::string format_bytes(double bytes);

// Half of /proc/meminfo's MemAvailable (B), and at most half the address-space limit
// (RLIMIT_AS, ulimit -v) when one is set; infinity where neither is known.
double default_memory_limit();

// The process's own default, replacing half the available memory when > 0 (Python's
// femdyn.set_max_memory); 0 restores it.
void set_default_memory_limit(double bytes);

// The limit in force: `given` bytes if > 0, else the process's default if set, else
// default_memory_limit().
double memory_limit(double given = 0);

// The limit that would admit `bytes`, with a 10 % margin, in GB with one decimal: "4.9"; and
// as the command-line option, "--max-memory 4.9".
std::string max_memory_gb(double bytes);
std::string max_memory_option(double bytes);

// "" when `bytes` fit within the limit (`given` bytes, 0: the default), else one line:
// "<what> needs 4.4 GB of memory, beyond the memory limit of 2.1 GB (half the available
// memory): <how>".
std::string memory_refusal(const std::string& what, double bytes, double given,
                           const std::string& how);

// Throws MemoryRefused with memory_refusal()'s line when `bytes` exceed the limit.
void require_memory(const std::string& what, double bytes, double given, const std::string& how);

// The memory one Workspace holds once it has formed and factorised M^s (evaluate,
// forward_dynamics on the Cholesky route): M^s, its factor, T and M T on the Transform route,
// the tree's workspace under a nonlinear coupling, and a small amount per body.
double evaluation_bytes(const Model& model);

// The last line of defence: a std::bad_alloc that no estimate foresaw, as one line.
// "out of memory while <doing>: the work needed more memory than the process could get (…)".
std::string out_of_memory_text(const std::string& doing);

}  // namespace femdyn
