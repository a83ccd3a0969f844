// args.hpp -- the one argument module of ictusd's verbs: the usage error, the
// strict number parsers, the argv walker, the interrupt flag (SIGINT/SIGTERM/SIGHUP)
// and the exit-status mapping every verb shares. Exit status: 0 ok, 1 error in
// a file or the data, 2 usage error, 3 the simulation diverged, 130 interrupted.
#pragma once

#include <Eigen/Core>

#include <csignal>
#include <functional>
#include <iosfwd>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictus
{
namespace cli
{

// A bad command line: the verb exits with status 2.
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Strict parsers: the whole text must be a finite number. Each throws a
// UsageError naming the option and the text.
double parse_number(const std::string &option, const std::string &text);
double parse_number(const std::string &option, const std::string &text, double lo, double hi);
double parse_positive(const std::string &option, const std::string &text);
int parse_int(const std::string &option, const std::string &text, int lo, int hi);
// "X,Y,Z", each a number in [lo, hi].
Eigen::Vector3d parse_vec3(const std::string &option, const std::string &text, double lo,
                           double hi);
std::vector<std::string> split(const std::string &text, char separator);

// The argv walker: options with one value, flags, positional arguments.
class Args
{
  public:
    Args(int argc, char **argv); // argv[0] is skipped (the program or the verb)
    bool done() const { return at_ >= items_.size(); }
    const std::string &next() { return items_[at_++]; }
    // The value of `option` (the next item); UsageError "OPTION: missing value".
    std::string value(const std::string &option);
    // The value of an option that is one of a few words (a mode, a kit, a preset,
    // a nuance), lower-cased: any case is taken, as the score's words are.
    std::string word(const std::string &option);

  private:
    std::vector<std::string> items_;
    size_t at_ = 0;
};

// What a verb does with one of its options: `option` is its name, its value
// (when it has one) is the next item of `args`.
using OptionHandler = std::function<void(const std::string &option, Args &args)>;

// A verb's options as a table of {name, handler}, in the manner of liblo's
// lo_server_add_method registry.
struct Option {
    const char *name;
    OptionHandler handle;
};
using OptionTable = std::vector<Option>;

// Runs the handler of `option` from `table`; false when the table has none.
bool dispatch_option(const OptionTable &table, const std::string &option, Args &args);

// Handlers that store an option's value in `target` (which must outlive
// the table): as it is, or read by one of the parsers above, e.g.
// store(k, parse_positive), store(channel, parse_int, 1, 16).
OptionHandler store_text(std::string &target);
OptionHandler store_word(std::string &target); // Args::word
template <typename T>
OptionHandler store(T &target, T (*parse)(const std::string &, const std::string &))
{
    return [&target, parse](const std::string &option, Args &args) {
        target = parse(option, args.value(option));
    };
}
template <typename T>
OptionHandler store(T &target, T (*parse)(const std::string &, const std::string &, T, T), T lo,
                    T hi)
{
    return [&target, parse, lo, hi](const std::string &option, Args &args) {
        target = parse(option, args.value(option), lo, hi);
    };
}
// A flag: no value; sets `target` to true.
OptionHandler store_flag(bool &target);

// Walks a verb's command line: --help or -h prints `usage` and returns false
// at once (the verb exits 0); every other item goes to `handle`.
bool walk_args(Args &args, void (*usage)(std::ostream &),
               const std::function<void(const std::string &item)> &handle);

// The signal (SIGINT, SIGTERM or SIGHUP) that asked the verb to stop, 0
// while none did; the loops of track, run and render check it every step and
// the verb exits 130 (docs/perform.md, "Signals"). Set from the first moment
// of the process: a signal during loading is not forgotten.
extern volatile std::sig_atomic_t g_interrupted;
// A child process (render --wav's pd) ended with ictusd: a second signal,
// which exits at once, kills it first. 0: none.
extern volatile std::sig_atomic_t g_child_pid;
// SIGINT, SIGTERM and SIGHUP set g_interrupted (a second one exits 130 at
// once); SIGXFSZ is ignored, so that a file-size limit is a write error
// (EFBIG) each writer reports, not the end of the process.
void install_signal_handlers();

// Runs a verb: its return value is the exit status; an exception is printed
// as "ictusd VERB: what" and mapped to 2 (UsageError, a bad network option)
// or 1 (anything else: a file, the data).
int run_verb(const char *verb, const std::function<int()> &body);

} // namespace cli
} // namespace ictus
