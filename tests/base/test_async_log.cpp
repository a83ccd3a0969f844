// base: AsyncLog, the daemon's log for threads that must never wait
// (async_log.hpp): posting never blocks, whatever the descriptor does; the
// lines written stay within the rate; repeats are collapsed and every loss is
// counted. The descriptor is a pipe the test reads, or one nobody reads.
#include "ictus/base/async_log.hpp"

#include <catch2/catch.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

using namespace ictus;
using Clock = std::chrono::steady_clock;

namespace
{
std::string read_all(int fd)
{
    std::string text;
    char buf[4096];
    for (;;) {
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n <= 0)
            return text;
        text.append(buf, static_cast<size_t>(n));
    }
}
} // namespace

TEST_CASE("async log: posts never wait on a pipe nobody reads, and the losses are counted",
          "[base][log]")
{
    int p[2];
    REQUIRE(::pipe(p) == 0);
    {
        AsyncLog log(p[1]);
        // 10^5 different lines in a burst: far more than the pipe (64 KiB)
        // or the queue (256) hold. Each post returns at once.
        double slowest_s = 0.0;
        for (int i = 0; i < 100000; ++i) {
            const auto t0 = Clock::now();
            log.post(("line " + std::to_string(i)).c_str());
            slowest_s =
                std::max(slowest_s, std::chrono::duration<double>(Clock::now() - t0).count());
        }
        const auto t0 = Clock::now();
        log.stop(); // the pipe unread: gives it 0.2 s, then returns
        const double stop_s = std::chrono::duration<double>(Clock::now() - t0).count();
        const AsyncLog::Counters c = log.counters();
        CHECK(c.posted + c.dropped == 100000);
        CHECK(c.dropped > 0);
        // A post is a copy into a queue cell: nowhere near the 20 ms the
        // writer sleeps between its rounds (a post that waited for it would).
        CHECK(slowest_s < 0.02);
        CHECK(stop_s < 2.0);
    }
    ::close(p[1]);
    ::close(p[0]);
}

TEST_CASE("async log: at most kLinesPerSecond lines a second, repeats collapsed", "[base][log]")
{
    int p[2];
    REQUIRE(::pipe(p) == 0);
    ::fcntl(p[0], F_SETFL, O_NONBLOCK);
    std::string text;
    const auto t0 = Clock::now();
    {
        AsyncLog log(p[1]);
        // 2 s: the same refusal 2000 times, then 300 different lines, paced so
        // that the queue (256) never fills.
        for (int i = 0; i < 2000; ++i) {
            log.post("ictusd run: /ictus/drum/radius: busy");
            if (i % 100 == 0)
                std::this_thread::sleep_for(std::chrono::milliseconds(25));
            text += read_all(p[0]);
        }
        for (int i = 0; i < 300; ++i) {
            log.post(("distinct " + std::to_string(i)).c_str());
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
            text += read_all(p[0]);
        }
        log.stop();
        text += read_all(p[0]);
        const AsyncLog::Counters c = log.counters();
        CHECK(c.dropped == 0);
        CHECK(c.unwritten == 0);
        CHECK(c.posted == 2300);
        CHECK(c.repeated == 1999);
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    size_t lines = 0, busy = 0;
    for (size_t at = 0; (at = text.find('\n', at)) != std::string::npos; ++at)
        ++lines;
    for (size_t at = 0; (at = text.find("busy\n", at)) != std::string::npos; ++at)
        ++busy;
    INFO(text);
    CHECK(busy == 1); // written once, its repeats counted
    CHECK(text.find("repeated") != std::string::npos);
    CHECK(text.find("not shown") != std::string::npos);
    // The rate: a burst of kLinesPerSecond, then kLinesPerSecond a second,
    // and at most two reports a second.
    const double bound = (AsyncLog::kLinesPerSecond + 2) * (seconds + 1.0) + 2;
    INFO(lines << " lines in " << seconds << " s, bound " << bound);
    CHECK(lines <= bound);
    CHECK(lines >= static_cast<size_t>(AsyncLog::kLinesPerSecond));
    ::close(p[0]);
    ::close(p[1]);
}
