// atmos: host storage of large lookup tables (base/table_storage.h).
#include "base/table_storage.h"

#include <cstdlib>
#include <cstring>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace atmos {
namespace {

constexpr size_t kHugePage = size_t{2} << 20;
constexpr size_t kHugeThreshold = size_t{8} << 20;

bool HugePagesEnabled() {
    static const bool enabled = [] {
        const char* v = std::getenv("ATMOS_HUGE_PAGES");
        return !(v && std::strcmp(v, "0") == 0);
    }();
    return enabled;
}

// Whether storage of `bytes` bytes is advised for huge pages.
bool UsesHugePages(size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    return bytes >= kHugeThreshold && HugePagesEnabled();
#else
    (void)bytes;
    return false;
#endif
}

}  // namespace

void* AllocateTableStorage(size_t bytes) {
    if (bytes == 0) bytes = 1;
    void* p = nullptr;
    if (UsesHugePages(bytes)) {
        const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
        if (posix_memalign(&p, kHugePage, rounded) != 0) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        // Advice only: a kernel without transparent huge pages refuses it,
        // and the storage works as it is.
        (void)madvise(p, rounded, MADV_HUGEPAGE);
#endif
        return p;
    }
    if (posix_memalign(&p, 64, bytes) != 0) throw std::bad_alloc();
    return p;
}

void FreeTableStorage(void* p) noexcept { std::free(p); }

}  // namespace atmos
