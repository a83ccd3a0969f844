// The daemon's log for threads that must never wait (async_log.hpp). The queue
// is D. Vyukov's bounded multi-producer queue (a sequence number per cell): a
// producer claims a cell with one compare-and-swap and never waits for the
// writer; here the one consumer is the writer thread.
#include "ictus/base/async_log.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

namespace ictus
{

namespace
{
double seconds_now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}
} // namespace

AsyncLog::AsyncLog(int fd) : fd_(fd)
{
    for (std::size_t i = 0; i < kQueueLines; ++i)
        cells_[i].sequence.store(i, std::memory_order_relaxed);
    tokens_at_s_ = report_at_s_ = seconds_now();
    thread_ = std::thread([this] { loop(); });
}

AsyncLog::~AsyncLog()
{
    stop();
}

bool AsyncLog::post(const char *line)
{
    std::size_t pos = enqueue_.load(std::memory_order_relaxed);
    for (;;) {
        Cell &cell = cells_[pos & (kQueueLines - 1)];
        const std::size_t seq = cell.sequence.load(std::memory_order_acquire);
        const auto diff = static_cast<std::ptrdiff_t>(seq) - static_cast<std::ptrdiff_t>(pos);
        if (diff == 0) {
            if (enqueue_.compare_exchange_weak(pos, pos + 1, std::memory_order_relaxed)) {
                std::strncpy(cell.text, line, kLineBytes - 1);
                cell.text[kLineBytes - 1] = '\0';
                cell.sequence.store(pos + 1, std::memory_order_release);
                posted_.fetch_add(1, std::memory_order_relaxed);
                return true;
            }
        } else if (diff < 0) {
            dropped_.fetch_add(1, std::memory_order_relaxed);
            return false; // full
        } else {
            pos = enqueue_.load(std::memory_order_relaxed);
        }
    }
}

bool AsyncLog::pop(char *out)
{
    Cell &cell = cells_[dequeue_ & (kQueueLines - 1)];
    if (cell.sequence.load(std::memory_order_acquire) != dequeue_ + 1)
        return false;
    std::memcpy(out, cell.text, kLineBytes);
    cell.sequence.store(dequeue_ + kQueueLines, std::memory_order_release);
    ++dequeue_;
    return true;
}

void AsyncLog::stop()
{
    running_.store(false);
    if (thread_.joinable())
        thread_.join();
}

AsyncLog::Counters AsyncLog::counters() const
{
    Counters c;
    c.posted = posted_.load();
    c.dropped = dropped_.load();
    c.written = written_.load();
    c.repeated = repeated_.load();
    c.suppressed = suppressed_.load();
    c.unwritten = unwritten_.load();
    return c;
}

void AsyncLog::loop()
{
    while (running_.load()) {
        drain(false);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    drain(true);
}

void AsyncLog::drain(bool final)
{
    char line[kLineBytes];
    while (pop(line))
        take(line, seconds_now());
    report(seconds_now(), final);
    if (final && dropped_.load() + unwritten_.load() > 0)
        write_line("ictusd: log: " + std::to_string(dropped_.load()) +
                   " lines dropped (queue full), " + std::to_string(unwritten_.load()) +
                   " unwritten (stderr not read)\n");
}

// A line from the queue: counted in a repeat, over the rate, or written.
void AsyncLog::take(const char *line, double now_s)
{
    if (line == last_) {
        // Written once: counted in its repeat count; not shown: with the rest.
        if (last_shown_)
            ++pending_repeats_;
        else
            ++pending_suppressed_;
        repeated_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
    if (pending_repeats_)
        report(now_s, true); // the repeats belong to the line before this one
    last_ = line;
    tokens_ = std::min<double>(kLinesPerSecond, tokens_ + kLinesPerSecond * (now_s - tokens_at_s_));
    tokens_at_s_ = now_s;
    last_shown_ = tokens_ >= 1.0;
    if (!last_shown_) {
        ++pending_suppressed_;
        suppressed_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
    tokens_ -= 1.0;
    write_line(std::string(line) + "\n");
}

// Once a second (`now`: at once): the repeats of the last line written, and
// the lines over the rate.
void AsyncLog::report(double now_s, bool now)
{
    if (!now && now_s - report_at_s_ < 1.0)
        return;
    report_at_s_ = now_s;
    if (pending_repeats_) {
        write_line("ictusd: (the line above repeated " + std::to_string(pending_repeats_) +
                   " more times)\n");
        pending_repeats_ = 0;
    }
    if (pending_suppressed_) {
        write_line("ictusd: log: " + std::to_string(pending_suppressed_) +
                   " lines not shown (more than " + std::to_string(kLinesPerSecond) +
                   " a second)\n");
        pending_suppressed_ = 0;
    }
}

// One write(2), only when the descriptor takes it without waiting (a pipe with
// room, a file, a terminal not on hold); else the line is lost, counted. At
// the end the descriptor is given 0.2 s, once.
bool AsyncLog::write_line(const std::string &line)
{
    pollfd p{fd_, POLLOUT, 0};
    const int wait_ms = running_.load() || waited_ ? 0 : 200;
    if (poll(&p, 1, wait_ms) != 1 || !(p.revents & POLLOUT)) {
        waited_ = waited_ || wait_ms > 0; // 0.2 s once, not once a line
        unwritten_.fetch_add(1, std::memory_order_relaxed);
        return false;
    }
    // Lines are under PIPE_BUF (4096 bytes): a pipe with room takes one whole.
    const ssize_t n = ::write(fd_, line.data(), line.size());
    if (n != static_cast<ssize_t>(line.size())) {
        unwritten_.fetch_add(1, std::memory_order_relaxed);
        return false;
    }
    written_.fetch_add(1, std::memory_order_relaxed);
    return true;
}

} // namespace ictus
