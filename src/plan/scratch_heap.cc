// The interposed C heap (frenetic/plan/scratch_heap.h). The region is reserved once (mmap, no swap
// reserved: only the pages a slot touches take memory) and cut in kSlots slots; a slot is a
// thread's while the thread lives. A block is a 16-byte header holding its size, then the
// bytes, 16-aligned as glibc's. A block's slot is known from its address, so it may be freed on
// any thread; the slot is wound back, at the next scope's start or end, once none is live.
#include "frenetic/plan/scratch_heap.h"

#include <dlfcn.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace frenetic::plan::heap {

std::atomic<bool> g_count_allocations{false};
std::atomic<std::int64_t> g_allocations{0};

namespace {

struct Slot {
  std::atomic<std::int64_t> live{0};  // blocks handed out and not yet freed
  std::size_t used = 0;               // bytes handed out since it was last wound back (owner only)
  std::int64_t served = 0;            // blocks handed out since its thread took it (owner only)
  std::atomic<bool> taken{false};
};

Slot g_slots[kSlots];
// Set once (by the first scope of any thread), before any block of it exists; read by every
// free().
std::atomic<char*> g_region{nullptr};
constexpr std::size_t kRegionBytes = kSlotBytes * kSlots;

// The thread's slot (-1: none yet, -2: none to be had) and how deep its scopes are; plain
// thread-locals of the executable (no constructor, no allocation).
thread_local int t_slot = -1;
thread_local int t_depth = 0;

// Gives the slot back when its thread ends (its blocks may outlive it: a slot with live blocks
// is not wound back until they are freed, by whoever takes it next).
struct SlotRelease {
  ~SlotRelease() {
    if (t_slot >= 0) g_slots[t_slot].taken.store(false, std::memory_order_release);
    t_slot = -2;
  }
};

void ClaimSlot() {
  static char* const region = [] {
    void* p = mmap(nullptr, kRegionBytes, PROT_READ | PROT_WRITE,
                   MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    return p == MAP_FAILED ? nullptr : static_cast<char*>(p);
  }();
  g_region.store(region, std::memory_order_relaxed);
  t_slot = -2;
  if (region == nullptr) return;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_slots[i].taken.compare_exchange_strong(expected, true, std::memory_order_acquire)) {
      thread_local SlotRelease release;  // registered once a thread, before the slot is used
      (void)release;
      g_slots[i].served = 0;
      t_slot = i;
      return;
    }
  }
}

void WindBack() {
  Slot& s = g_slots[t_slot];
  if (s.live.load(std::memory_order_acquire) == 0) s.used = 0;
}

}  // namespace

ScratchScope::ScratchScope() {
  if (!kInterposed) return;
  if (t_depth++ > 0) return;
  if (t_slot == -1) ClaimSlot();
  if (t_slot >= 0) WindBack();
}

ScratchScope::~ScratchScope() {
  if (!kInterposed) return;
  if (--t_depth == 0 && t_slot >= 0) WindBack();
}

ScratchPause::ScratchPause() : saved_(t_depth) { t_depth = 0; }
ScratchPause::~ScratchPause() { t_depth = saved_; }

SlotUse ThreadSlotUse() {
  if (t_slot < 0) return {};
  const Slot& s = g_slots[t_slot];
  return {s.used, s.live.load(std::memory_order_acquire), s.served};
}

}  // namespace frenetic::plan::heap

#if FRENETIC_HEAP_INTERPOSED
namespace frenetic::plan::heap {
namespace {

// The interposer's own helpers (compiled only with it).
constexpr std::size_t kHeader = 16;  // bytes before each block: its size

bool InRegion(const void* p) {
  const char* c = static_cast<const char*>(p);
  const char* region = g_region.load(std::memory_order_relaxed);
  return region != nullptr && c >= region && c < region + kRegionBytes;
}

// The bytes a block of `size` takes after its header (its usable size).
std::size_t Rounded(std::size_t size) { return (size + 15) / 16 * 16; }

// A block of the thread's slot, or nullptr (no scope, no slot, or full).
void* FromSlot(std::size_t size) {
  if (t_depth <= 0 || t_slot < 0) return nullptr;
  Slot& s = g_slots[t_slot];
  const std::size_t rounded = Rounded(size);
  if (size > kSlotBytes || rounded + kHeader > kSlotBytes - s.used) return nullptr;
  char* block = g_region.load(std::memory_order_relaxed) +
                static_cast<std::size_t>(t_slot) * kSlotBytes + s.used;
  s.used += rounded + kHeader;
  ++s.served;
  s.live.fetch_add(1, std::memory_order_relaxed);
  std::memcpy(block, &size, sizeof(size));
  return block + kHeader;
}

std::size_t BlockSize(const void* p) {
  std::size_t size = 0;
  std::memcpy(&size, static_cast<const char*>(p) - kHeader, sizeof(size));
  return size;
}

void FreeBlock(const void* p) {
  const char* region = g_region.load(std::memory_order_relaxed);
  const auto slot = static_cast<std::size_t>(static_cast<const char*>(p) - region) / kSlotBytes;
  g_slots[slot].live.fetch_sub(1, std::memory_order_release);
}

void Count() {
  if (g_count_allocations.load(std::memory_order_relaxed)) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace
}  // namespace frenetic::plan::heap

namespace fh = frenetic::plan::heap;

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t n, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);
void __libc_free(void* p);

void* malloc(std::size_t size) noexcept {
  if (void* p = fh::FromSlot(size)) return p;
  fh::Count();
  return __libc_malloc(size);
}

void* calloc(std::size_t n, std::size_t size) noexcept {
  if (size == 0 || n <= static_cast<std::size_t>(-1) / size) {
    if (void* p = fh::FromSlot(n * size)) return std::memset(p, 0, n * size);
  }
  fh::Count();
  return __libc_calloc(n, size);
}

void* realloc(void* p, std::size_t size) noexcept {
  if (p != nullptr && fh::InRegion(p)) {
    if (size == 0) {  // glibc's: p freed, null returned
      fh::FreeBlock(p);
      return nullptr;
    }
    void* q = fh::FromSlot(size);
    if (q == nullptr) {
      fh::Count();
      q = __libc_malloc(size);
      if (q == nullptr) return nullptr;  // p stays valid, as realloc's contract says
    }
    std::memcpy(q, p, std::min(size, fh::BlockSize(p)));
    fh::FreeBlock(p);
    return q;
  }
  if (p == nullptr) {
    if (void* q = fh::FromSlot(size)) return q;
  }
  fh::Count();
  return __libc_realloc(p, size);
}

// The aligned allocations are glibc's, counted.
void* __libc_memalign(std::size_t alignment, std::size_t size);
void* __libc_valloc(std::size_t size);
void* __libc_pvalloc(std::size_t size);

void* memalign(std::size_t alignment, std::size_t size) noexcept {
  fh::Count();
  return __libc_memalign(alignment, size);
}

void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  fh::Count();
  return __libc_memalign(alignment, size);
}

int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
  if (alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0 || alignment == 0) {
    return EINVAL;
  }
  fh::Count();
  void* p = __libc_memalign(alignment, size);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}

void* valloc(std::size_t size) noexcept {
  fh::Count();
  return __libc_valloc(size);
}

void* pvalloc(std::size_t size) noexcept {
  fh::Count();
  return __libc_pvalloc(size);
}

// A region block's usable size is its size rounded up to 16; any other is glibc's (its own
// malloc_usable_size, found once past this executable's).
std::size_t malloc_usable_size(void* p) noexcept {
  if (p != nullptr && fh::InRegion(p)) return fh::Rounded(fh::BlockSize(p));
  using Usable = std::size_t (*)(void*);
  static const Usable glibc = reinterpret_cast<Usable>(dlsym(RTLD_NEXT, "malloc_usable_size"));
  return glibc != nullptr ? glibc(p) : 0;
}

void free(void* p) noexcept {
  if (p != nullptr && fh::InRegion(p)) {
    fh::FreeBlock(p);
    return;
  }
  __libc_free(p);
}
}  // extern "C"
#endif
