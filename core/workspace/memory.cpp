#include "core/workspace/memory.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "core/model/model.hpp"
#include "core/spatial/math.hpp"

namespace femdyn {
namespace {

// A Workspace's per-body buffers (body states, composite and articulated inertias, element
// buffers), measured on chains of 1,000 to 10,000 bodies with margin.
constexpr double kWorkspaceBytesPerBody = 2e3;

}  // namespace

std::string format_bytes(double bytes) {
  if (!std::isfinite(bytes)) return "unlimited";
  if (bytes >= 1e9) return format_number(bytes / 1e9, "%.3g") + " GB";
  if (bytes >= 1e6) return format_number(bytes / 1e6, "%.3g") + " MB";
  return format_number(bytes / 1e3, "%.3g") + " kB";
}

namespace {

// Half the process's address-space limit (ulimit -v), infinity when none is set.
double half_address_space_limit() {
  if (rlimit r{}; getrlimit(RLIMIT_AS, &r) == 0 && r.rlim_cur != RLIM_INFINITY)
    return 0.5 * static_cast<double>(r.rlim_cur);
  return std::numeric_limits<double>::infinity();
}

// What the default limit is, for a refusal.
std::string default_limit_source() {
  return default_memory_limit() == half_address_space_limit() ? "half of ulimit -v"
                                                              : "half the available memory";
}

}  // namespace

double default_memory_limit() {
  // Half the available memory, and half the process's address-space limit (ulimit -v) when one
  // is set: beyond that an allocation would fail however much memory the machine has.
  double limit = std::numeric_limits<double>::infinity();
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line)) {  // "MemAvailable:   23705392 kB"
    double kib = 0;
    if (line.rfind("MemAvailable:", 0) == 0 && std::sscanf(line.c_str() + 13, "%lf", &kib) == 1) {
      limit = 0.5 * kib * 1024;
      break;
    }
  }
  return std::min(limit, half_address_space_limit());
}

namespace {
std::atomic<double> g_default_limit{0};
}  // namespace

void set_default_memory_limit(double bytes) { g_default_limit = bytes > 0 ? bytes : 0; }

double memory_limit(double given) {
  if (given > 0) return given;
  const double set = g_default_limit;
  return set > 0 ? set : default_memory_limit();
}

std::string max_memory_gb(double bytes) {
  return format_number(std::ceil(1.1 * bytes / 1e8) / 10, "%.1f");
}

std::string max_memory_option(double bytes) { return "--max-memory " + max_memory_gb(bytes); }

std::string memory_refusal(const std::string& what, double bytes, double given,
                           const std::string& how) {
  const double limit = memory_limit(given);
  if (bytes <= limit) return {};
  return what + " needs " + format_bytes(bytes) + " of memory, beyond the memory limit of " +
         format_bytes(limit) +
         (given > 0 || g_default_limit > 0 ? "" : " (" + default_limit_source() + ")") + ": " + how;
}

void require_memory(const std::string& what, double bytes, double given, const std::string& how) {
  if (std::string why = memory_refusal(what, bytes, given, how); !why.empty())
    throw MemoryRefused(why);
}

double evaluation_bytes(const Model& m) {
  const double n = m.n(), nb = static_cast<double>(m.bodies.size());
  double bytes = dense_bytes(n, n) + kWorkspaceBytesPerBody * nb;  // M^s
  if (m.mass_route == MassRoute::Transform)
    bytes += 2 * dense_bytes(m.n_u(), n) + 2 * dense_bytes(3 * nb, n);  // T, M T, Jω, Jv
  switch (m.mass_pattern.solver) {
    case SolverKind::Dense:  // LLT's n x n factor
      bytes += dense_bytes(n, n);
      break;
    case SolverKind::Sparse:  // CHOLMOD: a copy of M^s's lower half (value and row index) and
                              // its factor, at most the lower half again with the supernodes'
                              // padding
      bytes += 1.5 * dense_bytes(n, n);
      break;
    case SolverKind::Tree:  // fill-free: in place of M^s's pattern
      break;
  }
  if (m.coupling_level && m.tree)  // the tree's own workspace, G, and the reduced factor
    bytes += evaluation_bytes(*m.tree) + dense_bytes(m.n_theta(), n) + dense_bytes(n, n);
  return bytes;
}

std::string out_of_memory_text(const std::string& doing) {
  return "out of memory while " + doing +
         ": the work needed more memory than the process could get (its estimate was within "
         "the memory limit; free memory, or a smaller model or fewer samples)";
}

}  // namespace femdyn
