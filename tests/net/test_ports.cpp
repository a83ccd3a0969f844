// The ports the tests listen on, drawn by osctest::free_udp_port() (tests/support/
// osc_test_util.hpp): never twice while the drawer lives, outside the kernel's ephemeral
// range (read here from /proc), bindable; and never one that a Python test beside it holds
// (python/ictus_tools/pdrun.py reserves from the same range with the same lock files).
#include "support/osc_test_util.hpp"

#include <catch2/catch.hpp>

#include <cstdio>
#include <set>
#include <sstream>

namespace
{

std::pair<int, int> ephemeral_range()
{
    int low = 0, high = 0;
    FILE *f = std::fopen("/proc/sys/net/ipv4/ip_local_port_range", "r");
    REQUIRE(f != nullptr);
    REQUIRE(std::fscanf(f, "%d %d", &low, &high) == 2);
    std::fclose(f);
    return {low, high};
}

} // namespace

TEST_CASE("free_udp_port: outside the ephemeral range, bindable, never twice, never a port "
          "a Python test holds",
          "[ports]")
{
    const auto [low, high] = ephemeral_range();
    // A Python process draws 40 and holds them (it prints them, then waits for its stdin).
    const std::string cmd = "PYTHONPATH=" ICTUS_SOURCE_DIR "/python /usr/bin/python3 -c '"
                            "import sys\nfrom ictus_tools.pdrun import free_udp_port\n"
                            "print(\" \".join(str(free_udp_port()) for _ in range(40)), "
                            "flush=True)\nsys.stdin.read()'";
    int to_child[2], from_child[2];
    REQUIRE(pipe(to_child) == 0);
    REQUIRE(pipe(from_child) == 0);
    const pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
        dup2(to_child[0], 0);
        dup2(from_child[1], 1);
        close(to_child[1]);
        close(from_child[0]);
        execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char *>(nullptr));
        _exit(127);
    }
    close(to_child[0]);
    close(from_child[1]);
    std::string line;
    char c;
    while (read(from_child[0], &c, 1) == 1 && c != '\n')
        line += c;
    std::set<int> theirs;
    std::istringstream in(line);
    for (int p; in >> p;)
        theirs.insert(p);
    REQUIRE(theirs.size() == 40);

    std::set<int> mine;
    for (int i = 0; i < 200; ++i) {
        const int port = osctest::free_udp_port();
        INFO("port " << port << ", ephemeral range " << low << ".." << high);
        CHECK((port < low || port > high));
        CHECK(port >= 1024);
        CHECK(osctest::port_bindable(port, SOCK_DGRAM));
        CHECK(theirs.count(port) == 0);
        CHECK(mine.insert(port).second);
    }
    close(to_child[1]);
    close(from_child[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
}

TEST_CASE("free_udp_port: a TMPDIR that does not exist yet is made, and the port reserved in it",
          "[ports]")
{
    char base[] = "/tmp/ictus-ports-test-XXXXXX";
    REQUIRE(mkdtemp(base) != nullptr);
    const std::string tmpdir = std::string(base) + "/not/yet";
    const char *old = std::getenv("TMPDIR");
    const std::string saved = old ? old : "";
    setenv("TMPDIR", tmpdir.c_str(), 1);
    const int port = osctest::free_udp_port();
    if (old)
        setenv("TMPDIR", saved.c_str(), 1);
    else
        unsetenv("TMPDIR");
    CHECK(port > 0);
    CHECK(std::filesystem::exists(tmpdir + "/ictus-test-ports/" + std::to_string(port) + ".lock"));
    std::error_code ignored;
    std::filesystem::remove_all(base, ignored);
}
