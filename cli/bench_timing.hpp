// How femdyn bench times a call (cli/bench.cpp): calibrated batches of calls over cycled states,
// the engines' batches in turn so that slow drifts of the machine hit them alike, and the
// median, min and max over the batches.
#pragma once
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace femdyn::cli {

using Clock = std::chrono::steady_clock;

// Keeps the compiler from dropping work whose result it could prove unused.
inline void keep(const void* p) { asm volatile("" : : "g"(p) : "memory"); }

// ns per call of `calls` calls of fn over the cycled states.
template <class Fn>
double batch_ns(Fn& fn, long calls, int K) {
  int k = 0;
  const Clock::time_point start = Clock::now();
  for (long i = 0; i < calls; ++i) {
    fn(k);
    if (++k == K) k = 0;
  }
  return std::chrono::duration<double, std::nano>(Clock::now() - start).count() /
         static_cast<double>(calls);
}

// Warm-up and calibration: every state once (buffers are sized by the first call), runs
// doubling in length until one lasts a tenth of a batch, which fixes the calls a batch makes,
// then one whole batch whose time is thrown away. Returns the calls a batch makes.
template <class Fn>
long calls_per_batch(Fn& fn, int K, double batch_time_ns) {
  for (int k = 0; k < K; ++k) fn(k);
  for (long calls = 1;; calls *= 2) {
    const double per_call = batch_ns(fn, calls, K);
    if (per_call * static_cast<double>(calls) >= batch_time_ns / 10 || calls >= (1L << 30)) {
      const long batch = std::max(1L, std::lround(batch_time_ns / std::max(per_call, 1e-3)));
      batch_ns(fn, batch, K);
      return batch;
    }
  }
}

struct Timing {
  double median = 0, min = 0, max = 0;  // ns per call, over the batches
};

inline Timing summarize(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t h = v.size() / 2;
  return {v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]), v.front(), v.back()};
}

struct Method {
  int batches = 15;
  double batch_time_ns = 20e6;
};

struct Row {
  std::string quantity;
  Timing femdyn;
  std::optional<Timing> simbody;  // none for the derivatives
  std::optional<Timing> mujoco;   // M, qdd and tau of a URDF robot, built with MuJoCo
};

// One quantity on both engines (and MuJoCo when `mujoco_call` is given): each calibrated, then
// `batches` rounds of a femdyn batch and a Simbody batch (and a MuJoCo batch), so slow drifts of
// the machine hit them alike.
template <class F, class S>
Row time_both(const std::string& quantity, F&& femdyn_call, S&& simbody_call, int K,
              const Method& method, std::function<void(int)> mujoco_call = {}) {
  const long nf = calls_per_batch(femdyn_call, K, method.batch_time_ns);
  const long ns = calls_per_batch(simbody_call, K, method.batch_time_ns);
  const long nm = mujoco_call ? calls_per_batch(mujoco_call, K, method.batch_time_ns) : 0;
  std::vector<double> f, s, mj;
  for (int b = 0; b < method.batches; ++b) {
    f.push_back(batch_ns(femdyn_call, nf, K));
    s.push_back(batch_ns(simbody_call, ns, K));
    if (mujoco_call) mj.push_back(batch_ns(mujoco_call, nm, K));
  }
  Row row{quantity, summarize(f), summarize(s), std::nullopt};
  if (mujoco_call) row.mujoco = summarize(mj);
  return row;
}

// One quantity on femdyn alone: calibrated, then `batches` batches.
template <class F>
Row time_femdyn(const std::string& quantity, F&& femdyn_call, int K, const Method& method) {
  const long nf = calls_per_batch(femdyn_call, K, method.batch_time_ns);
  std::vector<double> f;
  for (int b = 0; b < method.batches; ++b) f.push_back(batch_ns(femdyn_call, nf, K));
  return {quantity, summarize(f), std::nullopt, std::nullopt};
}

}  // namespace femdyn::cli
