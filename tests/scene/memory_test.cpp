// tests/scene/memory_test.cpp: the resident set as the process measures it, and the freed heap
// between renderers: returned to the system without a budget, kept (and reused without faulting its
// pages in again) while a budget leaves room.
#include "scene/memory.h"

#include <malloc.h>
#include <sys/prctl.h>
#include <sys/resource.h>

#include <algorithm>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace shadowlab::scene {
namespace {

long minorFaults() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_minflt;
}

// Writes every page of [p, p + n): volatile, as a compiler drops a memset before a free().
void* touch(void* p, std::size_t n) {
    volatile char* bytes = static_cast<char*>(p);
    for (std::size_t i = 0; i < n; i += 4096) bytes[i] = 1;
    return p;
}

TEST(Memory, TheResidentSetGrowsByWhatIsTouched) {
    const std::uint64_t before = residentBytes();
    ASSERT_GT(before, 0u);
    std::vector<char> block(64 * kMiB);
    touch(block.data(), block.size());
    const std::uint64_t after = residentBytes();
    EXPECT_GE(after, before + 60 * kMiB);
    // Room above the block for its page tables, malloc's own pages and, under AddressSanitizer, the
    // shadow of the block (an eighth of it, 8 MiB): a count in the wrong unit would be far off.
    EXPECT_LE(after, before + 80 * kMiB);
}

// Sets an environment variable for a scope, and restores it.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        ::setenv(name, value, 1);
    }
    ~ScopedEnv() {
        if (old_)
            ::setenv(name_, old_->c_str(), 1);
        else
            ::unsetenv(name_);
    }

private:
    const char* name_;
    std::optional<std::string> old_;
};

TEST(Memory, TheFreedHeapIsReturnedUnlessABudgetLeavesRoomForTheNextRenderer) {
    // (The budget is capped at what the machine offers: a loaded CI machine must not decide.)
    const ScopedEnv limit("SHADOWLAB_MEMORY_LIMIT_MB", "1000000");
    EXPECT_TRUE(releaseFreedHeap());  // no budget: always
    {
        const FreedHeapBudget roomy(residentBytes() + 1024 * kMiB, 256 * kMiB);
        EXPECT_FALSE(releaseFreedHeap());
        {
            // The resident set plus a whole renderer would pass the inner estimate.
            const FreedHeapBudget tight(residentBytes() + 256 * kMiB, 512 * kMiB);
            EXPECT_TRUE(releaseFreedHeap());
        }
        EXPECT_FALSE(releaseFreedHeap());  // the outer budget again
    }
    EXPECT_TRUE(releaseFreedHeap());  // the budget's end ends it
    {
        // Never above what the machine offers beside what the process holds.
        const ScopedEnv small("SHADOWLAB_MEMORY_LIMIT_MB", "1");
        const FreedHeapBudget capped(residentBytes() + 1024 * kMiB, 64 * kMiB);
        EXPECT_TRUE(releaseFreedHeap());
    }
}

// What the budget is for: the heap a renderer freed serves the next without its pages faulting in
// again, where malloc_trim makes every page fault anew.
TEST(Memory, AKeptHeapIsReusedWithoutFaultingItsPagesInAgain) {
#ifdef __SANITIZE_ADDRESS__
    GTEST_SKIP() << "AddressSanitizer's allocator is not glibc's";
#endif
    // Pages of 4 KiB (transparent huge pages would fault 2 MiB at a time) and blocks from the heap
    // whatever GLIBC_TUNABLES says.
    ::prctl(PR_SET_THP_DISABLE, 1, 0, 0, 0);
    ::mallopt(M_MMAP_THRESHOLD, 1 << 20);
    const ScopedEnv limit("SHADOWLAB_MEMORY_LIMIT_MB", "1000000");
    constexpr std::size_t kBlock = 64 * 1024;  // under malloc's mmap threshold: from the heap
    constexpr std::size_t kBlocks = 512;       // 32 MiB
    constexpr long kPages = long(kBlocks * kBlock / 4096);
    // Allocates and touches the blocks, frees them but the highest (which keeps them off the heap's
    // top, which free() would give back by itself), releases, and counts the faults of doing it again.
    auto refaults = [&](bool budget) {
        std::vector<void*> blocks(kBlocks);
        for (void*& b : blocks) b = touch(std::malloc(kBlock), kBlock);
        std::swap(*std::max_element(blocks.begin(), blocks.end()), blocks.back());
        void* const fence = blocks.back();
        blocks.pop_back();
        for (void* b : blocks) std::free(b);
        {
            std::optional<FreedHeapBudget> roomy;
            if (budget) roomy.emplace(residentBytes() + 1024 * kMiB, 0);
            EXPECT_EQ(releaseFreedHeap(), !budget);
        }
        const long before = minorFaults();
        for (void*& b : blocks) b = touch(std::malloc(kBlock), kBlock);
        const long faults = minorFaults() - before;
        for (void* b : blocks) std::free(b);
        std::free(fence);
        return faults;
    };
    const long trimmed = refaults(false);
    const long kept = refaults(true);
    EXPECT_GT(trimmed, kPages / 2);  // each page in again
    EXPECT_LT(kept, kPages / 16);
}

}  // namespace
}  // namespace shadowlab::scene
