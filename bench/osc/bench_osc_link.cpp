// bench_osc_link -- the sender side of the strike path: what posting a strike
// costs the physics thread, and how long a strike takes from post_strike() to
// a UDP receiver on loopback (timetag "immediately", so no scheduling), p50 /
// p99 / max. Also the strike detector's cost per step. Prints its figures.
#include "ictus/net/osc_sender.hpp"
#include "ictus/net/osc_server.hpp"
#include "ictus/sim/strike_detector.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

using clock_type = std::chrono::steady_clock;

static double percentile(std::vector<double> v, double p)
{
    std::sort(v.begin(), v.end());
    return v[static_cast<size_t>(p * (v.size() - 1))];
}

int main(int argc, char **argv)
{
    const int strikes = argc > 1 ? std::atoi(argv[1]) : 2000;
    // Receiver: a plain UDP socket on a free loopback port.
    const int fd = socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    bind(fd, reinterpret_cast<sockaddr *>(&sa), sizeof sa);
    socklen_t len = sizeof sa;
    getsockname(fd, reinterpret_cast<sockaddr *>(&sa), &len);
    ictus::OscSenderOptions o;
    o.target_url = "osc.udp://127.0.0.1:" + std::to_string(ntohs(sa.sin_port));
    o.lookahead_s = 0.0;
    ictus::OscSender sender(o);

    std::vector<double> post_ns, latency_us;
    ictus::StrikeEvent e;
    unsigned char buf[2048];
    for (int i = 0; i < strikes; ++i) {
        e.seq = i;
        const auto t0 = clock_type::now();
        sender.post_strike(e);
        const auto t1 = clock_type::now();
        pollfd p{fd, POLLIN, 0};
        if (poll(&p, 1, 1000) <= 0 || recv(fd, buf, sizeof buf, 0) <= 0) {
            std::fprintf(stderr, "bench_osc_link: strike %d not received\n", i);
            return 1;
        }
        const auto t2 = clock_type::now();
        post_ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
        latency_us.push_back(std::chrono::duration<double, std::micro>(t2 - t0).count());
        std::this_thread::sleep_for(
            std::chrono::milliseconds(1)); // one strike per physics step at most
    }
    std::printf(
        "post_strike (physics thread): p50 %.0f ns, p99 %.0f ns, max %.0f ns (%d strikes)\n",
        percentile(post_ns, 0.5), percentile(post_ns, 0.99), percentile(post_ns, 1.0), strikes);
    std::printf("post -> UDP receiver on loopback: p50 %.1f us, p99 %.1f us, max %.1f us\n",
                percentile(latency_us, 0.5), percentile(latency_us, 0.99),
                percentile(latency_us, 1.0));

    // Detector cost: two tips per step, one dipping into the membrane every 100 steps.
    ictus::StrikeDetector det;
    ictus::TipSample s;
    long n_strikes = 0;
    const long steps = 1000000;
    const auto d0 = clock_type::now();
    for (long n = 0; n < steps; ++n) {
        s.time_s = n * 1e-3;
        const double phase = (n % 100) / 100.0;
        s.center_m =
            det.membrane().center_m + Eigen::Vector3d(0.02, 0.007 + 0.05 * (phase - 0.05), 0.0);
        s.velocity_mps = Eigen::Vector3d(0, 5.0, 0);
        for (int hand = 0; hand < 2; ++hand)
            n_strikes += det.update(hand, s, e);
    }
    const double per_step_ns =
        std::chrono::duration<double, std::nano>(clock_type::now() - d0).count() / steps;
    std::printf("strike detector: %.0f ns per physics step (two tips), %ld strikes\n", per_step_ns,
                n_strikes);
    close(fd);
    return 0;
}
