// A counting global operator new, so that tests can assert that a code path makes no heap
// allocation outside Eigen (Eigen's own allocations are caught by EIGEN_RUNTIME_NO_MALLOC,
// see CMakeLists.txt). Kept apart from Catch's TU, where gcc would flag the malloc/free pair.
#include <atomic>
#include <cstdlib>
#include <new>

std::atomic<long> g_operator_new_calls{0};

void *operator new(std::size_t size)
{
    g_operator_new_calls.fetch_add(1, std::memory_order_relaxed);
    if (void *p = std::malloc(size ? size : 1))
        return p;
    throw std::bad_alloc();
}
void operator delete(void *p) noexcept
{
    std::free(p);
}
void operator delete(void *p, std::size_t) noexcept
{
    std::free(p);
}
