// args.cpp -- the argument module of ictusd (args.hpp).
#include "ictus/cli/args.hpp"

#include "ictus/net/osc_sender.hpp" // OscError: a bad --target/--bind is a usage error

#include <cctype>
#include <cerrno>
#include <csignal>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include <signal.h>
#include <unistd.h>

namespace ictus
{
namespace cli
{

volatile std::sig_atomic_t g_interrupted = 0;
volatile std::sig_atomic_t g_child_pid = 0;

namespace
{
// The first SIGINT / SIGTERM / SIGHUP asks the verb to stop cleanly at its
// next step (files closed, summary printed); a second one, if it has not
// stopped yet, ends the process at once, whatever it is doing, and its child
// with it (async-signal-safe calls only).
void on_interrupt(int signal_number)
{
    if (g_interrupted) {
        static const char msg[] = "ictusd: interrupted again: exiting now\n";
        const ssize_t ignored = write(2, msg, sizeof msg - 1);
        (void)ignored;
        if (g_child_pid > 0)
            kill(static_cast<pid_t>(g_child_pid), SIGKILL);
        _exit(130);
    }
    g_interrupted = signal_number;
}
} // namespace

void install_signal_handlers()
{
    struct sigaction action {
    };
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    for (int s : {SIGINT, SIGTERM, SIGHUP})
        sigaction(s, &action, nullptr);
    std::signal(SIGXFSZ, SIG_IGN);
}

double parse_number(const std::string &option, const std::string &text)
{
    char *end = nullptr;
    errno = 0;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
        throw UsageError(option + ": expected a number, got '" + text + "'");
    return v;
}

double parse_number(const std::string &option, const std::string &text, double lo, double hi)
{
    char *end = nullptr;
    errno = 0;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v) || v < lo || v > hi) {
        std::ostringstream s;
        s << option << ": expected a number in [" << lo << ", " << hi << "], got '" << text << "'";
        throw UsageError(s.str());
    }
    return v;
}

double parse_positive(const std::string &option, const std::string &text)
{
    const double v = parse_number(option, text);
    if (!(v > 0.0))
        throw UsageError(option + ": expected a number > 0, got '" + text + "'");
    return v;
}

int parse_int(const std::string &option, const std::string &text, int lo, int hi)
{
    char *end = nullptr;
    errno = 0;
    const long v = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || errno == ERANGE || v < lo || v > hi)
        throw UsageError(option + ": expected an integer in [" + std::to_string(lo) + ", " +
                         std::to_string(hi) + "], got '" + text + "'");
    return static_cast<int>(v);
}

std::vector<std::string> split(const std::string &text, char separator)
{
    std::vector<std::string> parts;
    std::stringstream in(text);
    std::string part;
    while (std::getline(in, part, separator))
        parts.push_back(part);
    return parts;
}

Eigen::Vector3d parse_vec3(const std::string &option, const std::string &text, double lo, double hi)
{
    const std::vector<std::string> parts = split(text, ',');
    if (parts.size() != 3)
        throw UsageError(option + ": expected X,Y,Z, got '" + text + "'");
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i)
        v[i] = parse_number(option, parts[static_cast<size_t>(i)], lo, hi);
    return v;
}

Args::Args(int argc, char **argv)
{
    for (int i = 1; i < argc; ++i)
        items_.emplace_back(argv[i]);
}

std::string Args::value(const std::string &option)
{
    if (done())
        throw UsageError(option + ": missing value");
    return next();
}

std::string Args::word(const std::string &option)
{
    std::string w = value(option);
    for (char &c : w)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return w;
}

bool dispatch_option(const OptionTable &table, const std::string &option, Args &args)
{
    for (const Option &entry : table)
        if (option == entry.name) {
            entry.handle(option, args);
            return true;
        }
    return false;
}

OptionHandler store_text(std::string &target)
{
    return [&target](const std::string &option, Args &args) { target = args.value(option); };
}

OptionHandler store_word(std::string &target)
{
    return [&target](const std::string &option, Args &args) { target = args.word(option); };
}

OptionHandler store_flag(bool &target)
{
    return [&target](const std::string &, Args &) { target = true; };
}

bool walk_args(Args &args, void (*usage)(std::ostream &),
               const std::function<void(const std::string &item)> &handle)
{
    while (!args.done()) {
        const std::string item = args.next();
        if (item == "--help" || item == "-h") {
            usage(std::cout);
            return false;
        }
        handle(item);
    }
    return true;
}

int run_verb(const char *verb, const std::function<int()> &body)
{
    try {
        const int status = body();
        if (status == 0 && g_interrupted) { // a verb of one step (limits, gestures) finished it
            std::cerr << "ictusd " << verb << ": interrupted\n";
            return 130;
        }
        return status;
    } catch (const UsageError &e) {
        std::cerr << "ictusd " << verb << ": " << e.what() << "\n";
        return 2;
    } catch (const OscError &e) {
        std::cerr << "ictusd " << verb << ": " << e.what() << "\n";
        return 2;
    } catch (const std::exception &e) {
        std::cerr << "ictusd " << verb << ": " << e.what() << "\n";
        return 1;
    }
}

} // namespace cli
} // namespace ictus
