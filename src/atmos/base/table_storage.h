// atmos: host storage of large lookup tables.
//
// A spectral table model's tables run to hundreds of MB (bruneton's 40-channel
// scattering and single-Mie tables: 335 MB), and a random query touches 32
// texels spread over all of it. With 4 KiB pages nearly every one of those
// reads also misses the TLB; on Linux, storage of 8 MiB and more is therefore
// aligned to 2 MiB and advised for transparent huge pages (madvise
// MADV_HUGEPAGE) before it is first touched. The values stored are unchanged;
// only the pages that hold them differ. ATMOS_HUGE_PAGES=0 in the environment
// turns the advice off (for side-by-side benchmarks); where the kernel does not
// offer huge pages the advice is ignored.
#pragma once

#include <cstddef>
#include <new>

namespace atmos {

// Storage of at least `bytes` bytes, 64-byte aligned (2 MiB aligned and advised
// for huge pages when large); throws std::bad_alloc.
void* AllocateTableStorage(size_t bytes);
void FreeTableStorage(void* p) noexcept;

// std::allocator's interface over AllocateTableStorage.
template <typename T>
struct TableAllocator {
    using value_type = T;
    TableAllocator() = default;
    template <typename U>
    TableAllocator(const TableAllocator<U>&) noexcept {}
    T* allocate(size_t n) {
        if (n > static_cast<size_t>(-1) / sizeof(T)) throw std::bad_alloc();
        return static_cast<T*>(AllocateTableStorage(n * sizeof(T)));
    }
    void deallocate(T* p, size_t) noexcept { FreeTableStorage(p); }
    template <typename U>
    bool operator==(const TableAllocator<U>&) const noexcept {
        return true;
    }
    template <typename U>
    bool operator!=(const TableAllocator<U>&) const noexcept {
        return false;
    }
};

}  // namespace atmos
