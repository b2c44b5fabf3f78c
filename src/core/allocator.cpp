#include "core/allocator.hpp"

#include <limits>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace shroudsim::core {

void configure_allocator() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_MAX, 0);                                      // no block of its own mapping
  mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());  // freed memory is kept
  mallopt(M_ARENA_MAX, 1);                                     // one heap for all threads
#endif
}

}  // namespace shroudsim::core
