#include "validation/alloc_counter.hpp"

#include <cstddef>

namespace {
thread_local bool g_counting = false;
thread_local long g_count = 0;
}  // namespace

#ifndef FEMDYN_SANITIZED
// The interposers: glibc's own entry points do the work.
extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);

extern "C" void* malloc(std::size_t n) {
  if (g_counting) ++g_count;
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t n, std::size_t size) {
  if (g_counting) ++g_count;
  return __libc_calloc(n, size);
}
extern "C" void* realloc(void* p, std::size_t n) {
  if (g_counting) ++g_count;
  return __libc_realloc(p, n);
}
#endif

namespace femdyn::alloc_counter {

void start() {
  g_count = 0;
  g_counting = true;
}

long stop() {
  g_counting = false;
  return g_count;
}

}  // namespace femdyn::alloc_counter
