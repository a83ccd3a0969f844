// The gesture database reader under hostile files: nesting far past a
// database's 5 levels, a long key over many values, an endless file. Each
// load runs in a child process under a 1 GB address-space limit and must
// end (before kDeadlineS) with a GestureError naming the file and the line.
#include "ictus/gesture/gesture.hpp"

#include <catch2/catch.hpp>

#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>

using namespace ictus;
namespace fs = std::filesystem;

namespace
{

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true; // the shadow memory needs terabytes of address space
#else
constexpr bool kSanitized = false;
#endif

struct ChildEnd {
    bool in_time = false; // ended by itself within the deadline
    int exit_status = -1; // 0: the load threw a GestureError
    std::string message;  // its what()
};

// The child's wall-time deadline: no speed bound (a busy machine may be slow), the end of a
// load that would never end; a quadratic path over the inputs below (200000 values, 100000
// levels, an endless file) would not end in it either, and memory is bounded apart.
constexpr double kDeadlineS = 30.0;

// GestureDatabase::load_json(path) in a child with RLIMIT_AS = 1 GB (not
// under a sanitizer), given `deadline_s` of wall time; killed after it.
ChildEnd load_in_child(const std::string &path, double deadline_s)
{
    int fds[2];
    REQUIRE(::pipe(fds) == 0);
    const pid_t pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
        ::close(fds[0]);
        if (!kSanitized) {
            const rlimit limit{rlim_t{1} << 30, rlim_t{1} << 30};
            ::setrlimit(RLIMIT_AS, &limit);
        }
        int status = 2;
        std::string message = "loaded without an error";
        try {
            GestureDatabase::load_json(path);
        } catch (const GestureError &e) {
            status = 0;
            message = e.what();
        } catch (const std::exception &e) {
            message = std::string("not a GestureError: ") + e.what();
        }
        const ssize_t ignored = ::write(fds[1], message.data(), message.size());
        (void)ignored;
        ::_exit(status);
    }
    ::close(fds[1]);
    ChildEnd end;
    const auto t0 = std::chrono::steady_clock::now();
    auto left_ms = [&] {
        const double s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        return static_cast<int>(std::max(0.0, (deadline_s - s) * 1000.0));
    };
    char buf[4096];
    for (;;) { // the message, until the child closes the pipe or the time is up
        pollfd p{fds[0], POLLIN, 0};
        if (::poll(&p, 1, left_ms()) <= 0)
            break;
        const ssize_t n = ::read(fds[0], buf, sizeof buf);
        if (n <= 0)
            break;
        end.message.append(buf, static_cast<size_t>(n));
    }
    int status = 0;
    end.in_time = left_ms() > 0 && ::waitpid(pid, &status, 0) == pid;
    if (!end.in_time) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
    }
    ::close(fds[0]);
    end.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return end;
}

std::string temp_file(const std::string &name, const std::string &text)
{
    const fs::path p = fs::temp_directory_path() /
                       ("ictus_json_bounds_" + std::to_string(::getpid()) + "_" + name);
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
}

// A valid one-unit database with `extra` inserted as members after "version".
std::string database_with(const std::string &extra)
{
    return "{\n\"format\": \"ictus-gestures\",\n\"version\": 1,\n" + extra +
           "\"units\": [\n{\"grip\": \"french\", \"nuance\": \"legato\", \"hand\": \"left\", "
           "\"rate_hz\": 250, \"strike_index\": 1, \"dynamics\": 0.6,\n\"tip_m\": [\n[0, 0.2, "
           "0],\n[0, 0.1, 0],\n[0, 0, 0]\n]}\n]\n}\n";
}

} // namespace

TEST_CASE("gesture JSON: nesting 100000 deep is refused at its line, under 1 GB",
          "[gesture][json][bounds]")
{
    // 100000 '[' then 100000 ']' on the third line of the file: the bound is
    // 16 levels, passed on that line.
    const std::string path = temp_file("deep.json", "{\n\"units\":\n" + std::string(100000, '[') +
                                                        std::string(100000, ']') + "\n}\n");
    const ChildEnd end = load_in_child(path, kDeadlineS);
    fs::remove(path);
    CHECK(end.in_time);
    CHECK(end.exit_status == 0);
    CHECK_THAT(end.message, Catch::StartsWith(path + ":3: ") && Catch::Contains("deeper than 16"));
}

TEST_CASE("gesture JSON: a valid database nested 16 deep in an extra member still loads",
          "[gesture][json][bounds]")
{
    // 15 levels inside the document's object: 16 in all, the bound itself.
    const std::string path =
        temp_file("sixteen.json", database_with("\"note\": " + std::string(15, '[') +
                                                std::string(15, ']') + ",\n"));
    const GestureDatabase db = GestureDatabase::load_json(path);
    fs::remove(path);
    CHECK(db.units().size() == 1);
}

TEST_CASE("gesture JSON: a 1 MB key over 200000 values costs linear time and memory",
          "[gesture][json][bounds]")
{
    // The error's line is looked up along its pointer only: a path of every
    // value kept in memory would be 200000 copies of the 1 MB key (200 GB).
    std::string values;
    for (int i = 0; i < 200000; ++i)
        values += i ? ",0" : "0";
    std::string text = database_with("\"" + std::string(1 << 20, 'k') + "\": [" + values + "],\n");
    const std::string bad = "\"nuance\": \"legato\"";
    text.replace(text.find(bad), bad.size(), "\"nuance\": \"sforzando\"");
    const std::string path = temp_file("wide.json", text);
    const ChildEnd end = load_in_child(path, kDeadlineS);
    fs::remove(path);
    CHECK(end.in_time);
    CHECK(end.exit_status == 0);
    // The unit's header is the file's sixth line.
    CHECK_THAT(end.message, Catch::StartsWith(path + ":6: /units/0/nuance: unknown nuance"));
}

TEST_CASE("gesture JSON: an endless file (/dev/zero) is refused past 16 MiB",
          "[gesture][json][bounds]")
{
    const ChildEnd end = load_in_child("/dev/zero", kDeadlineS);
    CHECK(end.in_time);
    CHECK(end.exit_status == 0);
    CHECK_THAT(end.message, Catch::StartsWith("/dev/zero:0: larger than 16 MiB"));
}

TEST_CASE("gesture JSON: a number past a double's range is refused at its line",
          "[gesture][json][bounds]")
{
    // nlohmann reports it as out_of_range, not as a parse error.
    const std::string text = database_with("").replace(database_with("").find("\"rate_hz\": 250"),
                                                       14, "\"rate_hz\": 1e999");
    CHECK_THROWS_MATCHES(
        GestureDatabase::parse_json(text, "db.json"), GestureError,
        Catch::Matchers::Message("db.json:5: [json.exception.out_of_range.406] number overflow "
                                 "parsing '1e999'"));
}
