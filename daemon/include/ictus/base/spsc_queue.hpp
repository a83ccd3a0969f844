// spsc_queue.hpp -- a fixed-capacity, lock-free, single-producer /
// single-consumer ring: how the physics thread hands strikes and poses to the
// network threads, and how the OSC thread hands commands to the physics thread
// (STYLE.md: threads talk through queues; the physics loop never waits). A push
// onto a full queue fails at once and is counted: the producer never blocks.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>

namespace ictus
{

template <typename T, std::size_t Capacity> class SpscQueue
{
    static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0,
                  "capacity must be a power of two");

  public:
    // Producer only. False (and the item dropped, counted) when full.
    bool push(const T &item)
    {
        const std::size_t head = head_.load(std::memory_order_relaxed);
        if (head - tail_.load(std::memory_order_acquire) >= Capacity) {
            dropped_.fetch_add(1, std::memory_order_relaxed);
            return false;
        }
        slots_[head & (Capacity - 1)] = item;
        head_.store(head + 1, std::memory_order_release);
        return true;
    }
    // Consumer only. False when empty.
    bool pop(T &item)
    {
        const std::size_t tail = tail_.load(std::memory_order_relaxed);
        if (tail == head_.load(std::memory_order_acquire))
            return false;
        item = slots_[tail & (Capacity - 1)];
        tail_.store(tail + 1, std::memory_order_release);
        return true;
    }
    std::size_t size() const
    {
        return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
    }
    static constexpr std::size_t capacity() { return Capacity; }
    unsigned long dropped() const { return dropped_.load(std::memory_order_relaxed); }

  private:
    // Head and tail on their own cache lines: the two threads write one each.
    alignas(64) std::atomic<std::size_t> head_{0};
    alignas(64) std::atomic<std::size_t> tail_{0};
    alignas(64) std::atomic<unsigned long> dropped_{0};
    std::array<T, Capacity> slots_{};
};

} // namespace ictus
