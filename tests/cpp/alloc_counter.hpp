// Counts heap allocations of the whole test executable, C and C++ alike.
//
// The executable defines malloc/calloc/realloc/free/aligned_alloc/
// posix_memalign/memalign and every replaceable operator new/delete; the
// dynamic linker resolves the calls of every shared library (libsundials_cvode
// included) to these definitions first, so allocations inside SUNDIALS are
// seen as well as those of the C++ code.  They forward to glibc's
// __libc_malloc & co.
//
// Include this header in exactly ONE translation unit of a test executable
// (it defines non-inline functions).  Usage:
//
//   sh_test::AllocationCounter counter;   // starts counting
//   ... code that must not allocate ...
//   CHECK(counter.count() == 0);
//
// Counting is global (all threads) while at least one counter is alive.
//
// Under AddressSanitizer (scripts/run.sh sanitize) the sanitizer owns malloc:
// interposing it too crashes at start-up, so the interposers are left out,
// sh_test::kCountingAllocations is false, count() and frees() stay 0, and the
// tests skip the checks that need real counts (a line on stdout says so).
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#define SH_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SH_TEST_SANITIZED 1
#endif
#endif

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
void* __libc_memalign(std::size_t, std::size_t);
}

namespace sh_test {
#ifdef SH_TEST_SANITIZED
inline constexpr bool kCountingAllocations = false;
#else
inline constexpr bool kCountingAllocations = true;
#endif
namespace alloc_detail {
inline std::atomic<int>& armed() {
  static std::atomic<int> a{0};
  return a;
}
inline std::atomic<long>& allocations() {
  static std::atomic<long> n{0};
  return n;
}
inline std::atomic<long>& frees() {
  static std::atomic<long> n{0};
  return n;
}
inline void note_alloc() noexcept {
  if (armed().load(std::memory_order_relaxed) > 0) allocations().fetch_add(1, std::memory_order_relaxed);
}
inline void note_free(void* p) noexcept {
  if (p && armed().load(std::memory_order_relaxed) > 0) frees().fetch_add(1, std::memory_order_relaxed);
}
}  // namespace alloc_detail

//! Counts allocations (malloc, calloc, realloc, aligned forms, operator new)
//! and frees made while it is alive.
class AllocationCounter {
 public:
  AllocationCounter() noexcept
      : a0_(alloc_detail::allocations().load()), f0_(alloc_detail::frees().load()) {
    alloc_detail::armed().fetch_add(1);
  }
  ~AllocationCounter() { alloc_detail::armed().fetch_sub(1); }
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;

  long count() const noexcept { return alloc_detail::allocations().load() - a0_; }  //!< allocations so far
  long frees() const noexcept { return alloc_detail::frees().load() - f0_; }        //!< frees so far
  void restart() noexcept {
    a0_ = alloc_detail::allocations().load();
    f0_ = alloc_detail::frees().load();
  }

 private:
  long a0_, f0_;
};

}  // namespace sh_test

#ifdef SH_TEST_SANITIZED
#include <cstdio>
namespace sh_test::alloc_detail {
inline const bool announced = (std::puts("alloc_counter: sanitizer build, allocation counts skipped"), true);
}
#else
// ---- C allocation functions (interposed) -----------------------------------
extern "C" {
void* malloc(std::size_t n) {
  sh_test::alloc_detail::note_alloc();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t s) {
  sh_test::alloc_detail::note_alloc();
  return __libc_calloc(n, s);
}
void* realloc(void* p, std::size_t n) {
  sh_test::alloc_detail::note_alloc();
  return __libc_realloc(p, n);
}
void free(void* p) {
  sh_test::alloc_detail::note_free(p);
  __libc_free(p);
}
void* memalign(std::size_t al, std::size_t n) {
  sh_test::alloc_detail::note_alloc();
  return __libc_memalign(al, n);
}
void* aligned_alloc(std::size_t al, std::size_t n) {
  sh_test::alloc_detail::note_alloc();
  return __libc_memalign(al, n);
}
int posix_memalign(void** out, std::size_t al, std::size_t n) {
  sh_test::alloc_detail::note_alloc();
  void* p = __libc_memalign(al, n);
  if (!p) return 12;  // ENOMEM
  *out = p;
  return 0;
}
}

// ---- C++ replaceable allocation functions ------------------------------------
namespace sh_test {
namespace alloc_detail {
inline void* new_impl(std::size_t n) {
  note_alloc();
  void* p = __libc_malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  return p;
}
inline void* new_aligned_impl(std::size_t n, std::size_t al) {
  note_alloc();
  void* p = __libc_memalign(al, n ? n : 1);
  if (!p) throw std::bad_alloc();
  return p;
}
}  // namespace alloc_detail
}  // namespace sh_test

void* operator new(std::size_t n) { return sh_test::alloc_detail::new_impl(n); }
void* operator new[](std::size_t n) { return sh_test::alloc_detail::new_impl(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  sh_test::alloc_detail::note_alloc();
  return __libc_malloc(n ? n : 1);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  sh_test::alloc_detail::note_alloc();
  return __libc_malloc(n ? n : 1);
}
void* operator new(std::size_t n, std::align_val_t al) {
  return sh_test::alloc_detail::new_aligned_impl(n, static_cast<std::size_t>(al));
}
void* operator new[](std::size_t n, std::align_val_t al) {
  return sh_test::alloc_detail::new_aligned_impl(n, static_cast<std::size_t>(al));
}
void operator delete(void* p) noexcept { free(p); }
void operator delete[](void* p) noexcept { free(p); }
void operator delete(void* p, std::size_t) noexcept { free(p); }
void operator delete[](void* p, std::size_t) noexcept { free(p); }
void operator delete(void* p, std::align_val_t) noexcept { free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { free(p); }
#endif  // SH_TEST_SANITIZED
