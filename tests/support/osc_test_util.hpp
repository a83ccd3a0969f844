// Helpers for the OSC tests: real peers (liblo's oscdump and oscsend run as
// child processes), free UDP ports, raw sockets that send and receive OSC.
#pragma once

#include <lo/lo.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace osctest
{

// liblo's argument pointers are only 4-byte aligned, while lo_arg (a union
// with 64-bit members) asks for 8: read the bytes, never the union member.
inline float lo_arg_float(const lo_arg *a)
{
    float f;
    std::memcpy(&f, a, sizeof f);
    return f;
}
inline int32_t lo_arg_int(const lo_arg *a)
{
    int32_t i;
    std::memcpy(&i, a, sizeof i);
    return i;
}
inline const char *lo_arg_string(const lo_arg *a)
{
    return reinterpret_cast<const char *>(a);
}

// Ports the tests listen on are drawn from below the kernel's ephemeral range
// (net.ipv4.ip_local_port_range), where the kernel never hands one to another
// process's unbound socket, and each is reserved by a lock file held until this
// process exits, so that tests running side by side never draw the same one.
// python/ictus_tools/pdrun.py draws from the same range with the same locks.
inline std::pair<int, int> port_candidates()
{
    int low = 32768, high = 60999;
    if (FILE *f = std::fopen("/proc/sys/net/ipv4/ip_local_port_range", "r")) {
        if (std::fscanf(f, "%d %d", &low, &high) != 2) {
            low = 32768;
            high = 60999;
        }
        std::fclose(f);
    }
    if (low - 20000 >= 2000)
        return {20000, low - 1};
    if (65535 - high >= 2000)
        return {high + 1, 65535};
    return {std::max(1024, low), high};
}

inline bool port_bindable(int port, int kind)
{
    const int fd = socket(AF_INET, kind | SOCK_CLOEXEC, 0);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    sa.sin_port = htons(static_cast<uint16_t>(port));
    const bool ok = bind(fd, reinterpret_cast<sockaddr *>(&sa), sizeof sa) == 0;
    close(fd);
    return ok;
}

// The lock file's descriptor, or -1 (errno set) when this user cannot open it: another
// user's lock file is read-only to us, and flock works on a read-only descriptor.
inline int open_port_lock(const std::string &path)
{
    const int fd = open(path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0666);
    if (fd >= 0) {
        fchmod(fd, 0666); // every user's tests may lock it (the umask took bits off)
        return fd;
    }
    if (errno != EACCES && errno != EPERM)
        return -1;
    return open(path.c_str(), O_RDONLY | O_CLOEXEC);
}

// A UDP port on 127.0.0.1 that is free and reserved for this process (above).
inline int free_udp_port()
{
    const char *tmp = std::getenv("TMPDIR");
    const std::string dir = std::string(tmp && *tmp ? tmp : "/tmp") + "/ictus-test-ports";
    std::error_code made;
    // TMPDIR itself may not exist yet (Python's twin creates it too)
    if (std::filesystem::create_directories(dir, made))
        chmod(dir.c_str(), 01777); // shared by every user's tests, as /tmp is
    const auto [first, last] = port_candidates();
    std::random_device rd;
    std::mt19937 rng(rd());
    std::uniform_int_distribution<int> pick(first, last);
    int open_error = 0;
    for (int attempt = 0; attempt < 2000; ++attempt) {
        const int port = pick(rng);
        const std::string lock = dir + "/" + std::to_string(port) + ".lock";
        const int fd = open_port_lock(lock);
        if (fd < 0) {
            open_error = errno;
            continue; // a port this user cannot reserve: another one
        }
        if (flock(fd, LOCK_EX | LOCK_NB) == 0 && port_bindable(port, SOCK_DGRAM))
            return port; // fd stays open: the reservation lasts as long as the process
        close(fd);
    }
    std::fprintf(stderr,
                 "osctest: no free UDP port in %d..%d after 2000 tries (lock files in %s%s%s)\n",
                 first, last, dir.c_str(), open_error ? ": " : "",
                 open_error ? std::strerror(open_error) : "");
    std::abort();
}

// Waits until something (a peer started as a child: oscdump -L PORT) has
// bound the UDP port, up to `deadline_s`: true when it has. A handshake
// instead of a fixed sleep: a packet sent before the peer binds is lost.
inline bool wait_until_bound(int port, double deadline_s = 20.0)
{
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(deadline_s);
    for (;;) {
        const int fd = socket(AF_INET, SOCK_DGRAM, 0);
        sockaddr_in sa{};
        sa.sin_family = AF_INET;
        sa.sin_port = htons(static_cast<uint16_t>(port));
        const bool bound = bind(fd, reinterpret_cast<sockaddr *>(&sa), sizeof sa) != 0;
        close(fd);
        if (bound)
            return true;
        if (std::chrono::steady_clock::now() >= deadline)
            return false;
        poll(nullptr, 0, 20);
    }
}

// A child process whose stdout we read line by line; killed (SIGTERM) and
// reaped on destruction.
class Child
{
  public:
    explicit Child(const std::vector<std::string> &args)
    {
        int fds[2];
        if (pipe(fds) != 0)
            return;
        pid_ = fork();
        if (pid_ == 0) {
            // Dies with the test, even when the test aborts (a sanitizer
            // error): an orphan would hold ctest's output pipe open.
            prctl(PR_SET_PDEATHSIG, SIGTERM);
            dup2(fds[1], STDOUT_FILENO);
            close(fds[0]);
            close(fds[1]);
            std::vector<char *> argv;
            for (const std::string &a : args)
                argv.push_back(const_cast<char *>(a.c_str()));
            argv.push_back(nullptr);
            execvp(argv[0], argv.data());
            _exit(127);
        }
        close(fds[1]);
        fd_ = fds[0];
    }
    ~Child()
    {
        if (pid_ > 0) {
            kill(pid_, SIGTERM);
            waitpid(pid_, nullptr, 0);
        }
        if (fd_ >= 0)
            close(fd_);
    }
    bool started() const { return pid_ > 0; }
    // Next line of stdout, or false after `timeout_ms` without one.
    bool line(std::string &out, int timeout_ms)
    {
        const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
        for (;;) {
            const size_t nl = buffer_.find('\n');
            if (nl != std::string::npos) {
                out = buffer_.substr(0, nl);
                buffer_.erase(0, nl + 1);
                return true;
            }
            const int left = static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(
                                                  end - std::chrono::steady_clock::now())
                                                  .count());
            if (left <= 0)
                return false;
            pollfd p{fd_, POLLIN, 0};
            if (poll(&p, 1, left) <= 0)
                return false;
            char buf[4096];
            const ssize_t n = read(fd_, buf, sizeof buf);
            if (n <= 0)
                return false;
            buffer_.append(buf, static_cast<size_t>(n));
        }
    }

  private:
    pid_t pid_ = -1;
    int fd_ = -1;
    std::string buffer_;
};

// Polls ready() every 5 ms until it holds or deadline_s of wall time pass (a server's
// thread on a busy machine may be slow to take a packet): whether it held.
template <class Ready> bool poll_until(Ready ready, double deadline_s = 10.0)
{
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(deadline_s);
    while (!ready()) {
        if (std::chrono::steady_clock::now() > end)
            return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
}

// Runs a command to completion; its exit status.
inline int run(const std::vector<std::string> &args)
{
    const pid_t pid = fork();
    if (pid == 0) {
        std::vector<char *> argv;
        for (const std::string &a : args)
            argv.push_back(const_cast<char *>(a.c_str()));
        argv.push_back(nullptr);
        execvp(argv[0], argv.data());
        _exit(127);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A UDP socket on a loopback address that sends raw packets and receives
// OSC replies.
class Peer
{
  public:
    explicit Peer(const char *address = "127.0.0.1")
    {
        fd_ = socket(AF_INET, SOCK_DGRAM, 0);
        sockaddr_in sa{};
        sa.sin_family = AF_INET;
        inet_pton(AF_INET, address, &sa.sin_addr);
        bind(fd_, reinterpret_cast<sockaddr *>(&sa), sizeof sa);
        int big = 1 << 20;
        setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &big, sizeof big);
    }
    ~Peer() { close(fd_); }
    void send_raw(int port, const void *data, size_t size)
    {
        sockaddr_in to{};
        to.sin_family = AF_INET;
        to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        to.sin_port = htons(static_cast<uint16_t>(port));
        sendto(fd_, data, size, 0, reinterpret_cast<sockaddr *>(&to), sizeof to);
    }
    void send(int port, const char *path, lo_message m)
    {
        size_t size = 0;
        void *data = lo_message_serialise(m, path, nullptr, &size);
        send_raw(port, data, size);
        std::free(data);
        lo_message_free(m);
    }
    // Next OSC message: path and its arguments rendered as text, or false.
    struct Message {
        std::string path, types;
        std::vector<std::string> strings;
        std::vector<float> floats;
        std::vector<int> ints;
    };
    bool receive(Message &out, int timeout_ms)
    {
        pollfd p{fd_, POLLIN, 0};
        if (poll(&p, 1, timeout_ms) <= 0)
            return false;
        unsigned char buf[65536];
        const ssize_t n = recv(fd_, buf, sizeof buf, 0);
        if (n <= 0)
            return false;
        int result = 0;
        lo_message m = lo_message_deserialise(buf, static_cast<size_t>(n), &result);
        if (!m)
            return false;
        out = Message();
        out.path = reinterpret_cast<const char *>(buf);
        out.types = lo_message_get_types(m);
        lo_arg **argv = lo_message_get_argv(m);
        for (size_t i = 0; i < out.types.size(); ++i) {
            if (out.types[i] == 's')
                out.strings.push_back(lo_arg_string(argv[i]));
            else if (out.types[i] == 'f')
                out.floats.push_back(lo_arg_float(argv[i]));
            else if (out.types[i] == 'i')
                out.ints.push_back(lo_arg_int(argv[i]));
        }
        lo_message_free(m);
        return true;
    }
    // The next datagram as it came, for what receive() hides: its size (its
    // OSC path in `path`), or -1 after timeout_ms.
    long receive_size(std::string &path, int timeout_ms)
    {
        pollfd p{fd_, POLLIN, 0};
        if (poll(&p, 1, timeout_ms) <= 0)
            return -1;
        char buf[65536];
        const ssize_t n = recv(fd_, buf, sizeof buf - 1, 0);
        if (n < 0)
            return -1;
        buf[n] = '\0';
        path = buf;
        return static_cast<long>(n);
    }
    void drain()
    {
        Message m;
        while (receive(m, 0)) {
        }
    }
    int port() const
    {
        sockaddr_in sa{};
        socklen_t len = sizeof sa;
        getsockname(fd_, reinterpret_cast<sockaddr *>(&sa), &len);
        return ntohs(sa.sin_port);
    }

  private:
    int fd_ = -1;
};

} // namespace osctest
