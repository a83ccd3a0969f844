// async_log.hpp -- the daemon's log (stderr) for threads that must never wait:
// the physics loop and the OSC server post lines to a bounded lock-free queue
// and a thread of the log's own writes them. Nothing a reader of stderr does (a
// pipe nobody drains, a terminal on hold) reaches the posting threads: a full
// queue drops the line (counted), a stderr that is not ready for writing loses
// the line (counted), identical lines in a row are written once with their
// repeat count, and at most kLinesPerSecond lines a second are written, the
// rest counted. docs/osc.md, "The daemon's log".
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <string>
#include <thread>

namespace ictus
{

class AsyncLog
{
  public:
    // A posted line: at most kLineBytes - 1 bytes (longer ones are cut).
    static constexpr std::size_t kLineBytes = 256;
    // Lines waiting to be written; posts beyond them are dropped (counted).
    static constexpr std::size_t kQueueLines = 256;
    // Lines written a second, at most (a burst of as many): the rest are
    // counted and reported by one line a second. With that report and one
    // for lines repeated, at most kLinesPerSecond + 2 lines a second reach
    // stderr, each under kLineBytes + 80 bytes.
    static constexpr int kLinesPerSecond = 10;

    // Writes to `fd` (stderr by default); starts the writer thread.
    explicit AsyncLog(int fd = 2);
    ~AsyncLog(); // stop()
    AsyncLog(const AsyncLog &) = delete;
    AsyncLog &operator=(const AsyncLog &) = delete;

    // Any thread: lock-free, never blocks. False when the queue is full
    // (the line is dropped and counted).
    bool post(const char *line);
    // Writes what is queued (stderr given at most 0.2 s), a last line with
    // the counts when any line was lost, and joins the writer. Idempotent.
    void stop();

    struct Counters {
        unsigned long posted = 0;
        unsigned long written = 0;    // lines that reached the descriptor (reports included)
        unsigned long dropped = 0;    // the queue was full
        unsigned long repeated = 0;   // identical to the line before: in a repeat count
        unsigned long suppressed = 0; // over the rate
        unsigned long unwritten = 0;  // the descriptor was not ready (a pipe nobody reads)
    };
    Counters counters() const;

  private:
    struct Cell {
        std::atomic<std::size_t> sequence{0};
        char text[kLineBytes];
    };
    bool pop(char *out);
    void loop();
    void drain(bool final);
    void take(const char *line, double now_s);
    void report(double now_s, bool final);
    bool write_line(const std::string &line);

    int fd_;
    std::array<Cell, kQueueLines> cells_;
    alignas(64) std::atomic<std::size_t> enqueue_{0};
    alignas(64) std::size_t dequeue_ = 0; // the writer's
    std::atomic<bool> running_{true};
    std::atomic<unsigned long> posted_{0}, dropped_{0};
    // The writer's state (read by counters() through the atomics below).
    std::string last_;
    bool last_shown_ = false;
    bool waited_ = false; // stop() has given the descriptor its 0.2 s
    unsigned long pending_repeats_ = 0, pending_suppressed_ = 0;
    double tokens_ = kLinesPerSecond, tokens_at_s_ = 0.0, report_at_s_ = 0.0;
    std::atomic<unsigned long> written_{0}, repeated_{0}, suppressed_{0}, unwritten_{0};
    std::thread thread_;
};

} // namespace ictus
