// The flags of the four tools (render, step, bench, prast-diff), each defined
// once: the definition parses (through CLI11), writes --help and the flags
// page (docs/flags.md), and tells the tests which value it must refuse.
// Errors are one line without the tool's prefix, naming the flag and the
// value; an unknown flag gets the nearest defined one as a suggestion. CLI11
// stays inside flags.cpp, so the tools compile without it.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace prast::cli {

// What a flag's handler throws for a usage error: the one line. Not a
// std::exception, so nothing on the way (CLI11 included) mistakes it for its own.
struct UsageError {
    std::string message;
};

[[noreturn]] inline void fail(std::string message) { throw UsageError{std::move(message)}; }
// "FLAG 'VALUE': why", the shape of every bad-value message.
[[noreturn]] inline void bad_value(const std::string& flag, const std::string& value, const std::string& why) {
    fail(flag + " '" + value + "': " + why);
}

struct Flag {
    std::vector<std::string> names;  // every spelling, short first: {"-o", "--output"}
    std::string value;               // what it takes ("WxH", "FILE"); empty: a switch
    int arity = 1;                   // values after the flag (2 for --psnr A B)
    std::string brief;               // the words in --help
    std::string help;                // the words on the flags page (brief when empty)
    std::string fallback;            // the default as the page shows it; empty: none
    std::vector<std::string> bad;    // values the flag must refuse (tests/test_flags.cpp)
    std::vector<std::string> hints;  // other words people use for it ("resolution"), for suggestions
    bool stops = false;              // --help and --version end the parse
    // Called for every occurrence, in command-line order, with the spelling
    // used and the values; throws UsageError for a bad value.
    std::function<void(const std::string& flag, const std::vector<std::string>& values)> apply;

    const std::string& name() const { return names.back(); }
    std::string spelled() const;  // "-o, --output FILE"
};

// Words for a positional argument (the tools check their count themselves).
struct Positional {
    std::string name, help;
};

// One line of a compact --help: the flags it shows, then its words (for a
// single flag, its brief when empty).
struct HelpRow {
    std::vector<std::string> flags;
    std::string caption;
};

class FlagSet {
public:
    // Room for every tool's flags: add() hands out references that a
    // reallocation would invalidate.
    explicit FlagSet(std::string tool) : tool_(std::move(tool)) { flags_.reserve(64); }

    Flag& add(Flag f);
    // A switch: apply() with no value.
    Flag& toggle(std::vector<std::string> names, std::string brief, std::function<void()> on);
    // One value: apply(flag, value).
    Flag& value(std::vector<std::string> names, std::string metavar, std::string brief, std::string fallback,
                std::vector<std::string> bad, std::function<void(const std::string&, const std::string&)> on);
    void positional(std::string name, std::string help) { positionals_.push_back({std::move(name), std::move(help)}); }

    // What an unknown flag gets when no flag is near: " (render --help lists them)".
    std::string unknown_hint;
    // Called with an unknown flag's name (without "=value") before the
    // suggestion: a non-empty result is the error (step: render's flags it refuses).
    std::function<std::string(const std::string&)> refuse;
    // The missing-value line; default "FLAG: missing value (VALUE)".
    std::function<std::string(const std::string& flag, const std::string& metavar)> missing;

    // Parses argv[1..argc). Returns "" or the error line; the positional
    // arguments, in order, go to `positionals`. A stopping flag ends it with "".
    std::string parse(int argc, const char* const* argv, std::vector<std::string>& positionals) const;

    const std::string& tool() const { return tool_; }
    const std::vector<Flag>& flags() const { return flags_; }
    const std::vector<Positional>& positionals() const { return positionals_; }
    const Flag* find(const std::string& spelling) const;
    // The defined flag nearest an unknown name ("--resolution" -> "--size"), or "".
    std::string suggest(const std::string& unknown) const;

    // --help: `head`, one line per row, `tail`. Every flag must be in one row
    // (std::logic_error otherwise, so a new flag cannot go unlisted).
    std::string usage(const std::string& head, const std::vector<HelpRow>& rows, const std::string& tail,
                      std::size_t column = 23) const;
    // The tool's section of docs/flags.md: a table of the flags `in_table`
    // accepts (all when empty), the others named after it as `others`' flags.
    std::string markdown(const std::string& synopsis, const std::string& about,
                         const std::function<bool(const Flag&)>& in_table = {},
                         const std::string& others = "") const;

private:
    std::string tool_;
    std::vector<Flag> flags_;
    std::vector<Positional> positionals_;
};

// Edit distance (insertions, deletions, substitutions, adjacent swaps).
std::size_t edit_distance(const std::string& a, const std::string& b);

} // namespace prast::cli
