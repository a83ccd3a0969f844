// A counting global operator new, so that tests can assert that a code path makes no heap
// allocation outside Eigen (Eigen's own allocations are caught by EIGEN_RUNTIME_NO_MALLOC,
// see CMakeLists.txt). Every unaligned new/delete form is replaced, so that none pairs with
// the sanitizer's own (ASan reports new/free mismatches). Kept apart from Catch's TU, where
// gcc would flag the malloc/free pair.
#include <atomic>
#include <cstdlib>
#include <new>

std::atomic<long> g_operator_new_calls{0};

static void *counted_malloc(std::size_t size) noexcept
{
    g_operator_new_calls.fetch_add(1, std::memory_order_relaxed);
    return std::malloc(size ? size : 1);
}

void *operator new(std::size_t size)
{
    if (void *p = counted_malloc(size))
        return p;
    throw std::bad_alloc();
}
void *operator new[](std::size_t size)
{
    if (void *p = counted_malloc(size))
        return p;
    throw std::bad_alloc();
}
void *operator new(std::size_t size, const std::nothrow_t &) noexcept
{
    return counted_malloc(size);
}
void *operator new[](std::size_t size, const std::nothrow_t &) noexcept
{
    return counted_malloc(size);
}
void operator delete(void *p) noexcept
{
    std::free(p);
}
void operator delete[](void *p) noexcept
{
    std::free(p);
}
void operator delete(void *p, std::size_t) noexcept
{
    std::free(p);
}
void operator delete[](void *p, std::size_t) noexcept
{
    std::free(p);
}
void operator delete(void *p, const std::nothrow_t &) noexcept
{
    std::free(p);
}
void operator delete[](void *p, const std::nothrow_t &) noexcept
{
    std::free(p);
}
