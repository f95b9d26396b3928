// Heap allocations counted per thread, for the tests and the benchmark that hold femdyn's hot
// path to "no allocation" (tests/test_hot_path.cpp, validation/benchmark.cpp). Linking
// alloc_counter.cpp into an executable interposes glibc's malloc, calloc and realloc; nothing
// else changes. Under sanitizers (FEMDYN_SANITIZED) malloc is the sanitizer's, nothing is
// interposed and kAvailable is false.
#pragma once

namespace femdyn::alloc_counter {

#ifdef FEMDYN_SANITIZED
inline constexpr bool kAvailable = false;
#else
inline constexpr bool kAvailable = true;
#endif

void start();  // count this thread's allocations from now (the count restarts at 0)
long stop();   // stop counting; the allocations since start()

}  // namespace femdyn::alloc_counter
