// FlagSet: definitions to CLI11 options, CLI11's errors to one line,
// suggestions, --help and the flags page; see flags.h.
#include "apps/cli/flags.h"
#include "apps/cli/values.h"

#include <algorithm>
#include <stdexcept>

#include <CLI/CLI.hpp>

namespace prast::cli {

namespace {

// Thrown by a stopping flag (--help): the parse ends without an error.
struct Stop {};

std::string without_dashes(const std::string& s) {
    std::size_t i = 0;
    while (i < s.size() && s[i] == '-') ++i;
    return s.substr(i);
}

// Markdown table cells: a '|' would end the cell.
std::string cell(const std::string& s) {
    std::string out;
    for (char c : s) {
        if (c == '|') out += "\\|";
        else out += c;
    }
    return out;
}

} // namespace

std::string Flag::spelled() const {
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
    return value.empty() ? s : s + " " + value;
}

Flag& FlagSet::add(Flag f) {
    if (f.names.empty()) throw std::logic_error(tool_ + ": a flag without a name");
    for (const std::string& n : f.names)
        if (find(n)) throw std::logic_error(tool_ + ": " + n + " defined twice");
    if (flags_.size() == flags_.capacity()) throw std::logic_error(tool_ + ": more flags than FlagSet reserves");
    flags_.push_back(std::move(f));
    return flags_.back();
}

Flag& FlagSet::toggle(std::vector<std::string> names, std::string brief, std::function<void()> on) {
    Flag f;
    f.names = std::move(names);
    f.brief = std::move(brief);
    f.apply = [on](const std::string&, const std::vector<std::string>&) { on(); };
    return add(std::move(f));
}

Flag& FlagSet::value(std::vector<std::string> names, std::string metavar, std::string brief, std::string fallback,
                     std::vector<std::string> bad, std::function<void(const std::string&, const std::string&)> on) {
    Flag f;
    f.names = std::move(names);
    f.value = std::move(metavar);
    f.brief = std::move(brief);
    f.fallback = std::move(fallback);
    f.bad = std::move(bad);
    f.apply = [on](const std::string& flag, const std::vector<std::string>& v) { on(flag, v.at(0)); };
    return add(std::move(f));
}

const Flag* FlagSet::find(const std::string& spelling) const {
    for (const Flag& f : flags_)
        if (std::find(f.names.begin(), f.names.end(), spelling) != f.names.end()) return &f;
    return nullptr;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
    // Damerau-Levenshtein (optimal string alignment), three rows.
    const std::size_t n = a.size(), m = b.size();
    std::vector<std::size_t> prev2(m + 1), prev(m + 1), cur(m + 1);
    for (std::size_t j = 0; j <= m; ++j) prev[j] = j;
    for (std::size_t i = 1; i <= n; ++i) {
        cur[0] = i;
        for (std::size_t j = 1; j <= m; ++j) {
            const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                cur[j] = std::min(cur[j], prev2[j - 2] + 1);
        }
        prev2.swap(prev);
        prev.swap(cur);
    }
    return prev[m];
}

std::string FlagSet::suggest(const std::string& unknown) const {
    const std::string u = lower(without_dashes(unknown));
    if (u.empty()) return "";
    // A word people use for the flag ("--resolution" for --size).
    for (const Flag& f : flags_)
        for (const std::string& h : f.hints)
            if (u == h) return f.name();
    // A typo: the nearest spelling within a third of its length (one edit at least).
    const Flag* best = nullptr;
    std::size_t best_d = 0;
    for (const Flag& f : flags_)
        for (const std::string& spelling : f.names) {
            const std::string n = without_dashes(spelling);
            if (n.size() < 2) continue;
            const std::size_t d = edit_distance(u, n);
            if (d <= std::max<std::size_t>(1, n.size() / 3) && (!best || d < best_d)) {
                best = &f;
                best_d = d;
            }
        }
    if (best) return best->name();
    // The start of a name ("--thr" for --threads; the shortest when several
    // match), or a name with something after it ("--threads-per-core").
    const Flag* prefix = nullptr;
    for (const Flag& f : flags_) {
        const std::string n = without_dashes(f.name());
        if ((u.size() >= 3 && n.compare(0, u.size(), u) == 0) || (n.size() >= 4 && u.compare(0, n.size(), n) == 0))
            if (!prefix || n.size() < without_dashes(prefix->name()).size()) prefix = &f;
    }
    if (prefix) return prefix->name();
    // A word people use for it inside the name ("--image-width").
    for (const Flag& f : flags_)
        for (const std::string& h : f.hints)
            if (h.size() >= 4 && u.find(h) != std::string::npos) return f.name();
    return "";
}

std::string FlagSet::parse(int argc, const char* const* argv, std::vector<std::string>& positionals) const {
    CLI::App app("", tool_);
    app.set_help_flag();  // --help is one of our flags: it must stop the parse where it stands
    app.allow_extras();   // unknown flags and positionals come back in order, for our messages
    for (const Flag& f : flags_) {
        // One CLI11 option per spelling, so that a message names the flag as typed (-o or --output).
        for (const std::string& spelling : f.names) {
            CLI::Option* o = app.add_option(spelling, [&f, spelling](const CLI::results_t& r) {
                if (f.value.empty()) {
                    // CLI11 gives a switch "true", or the value of --switch=VALUE.
                    if (r.size() != 1 || r[0] != "true") fail(spelling + ": takes no value");
                    f.apply(spelling, {});
                    if (f.stops) throw Stop{};
                } else {
                    f.apply(spelling, r);
                }
                return true;
            });
            if (f.value.empty()) o->expected(0);
            else o->type_size(f.arity)->expected(1);
            // Each occurrence runs its handler at once: command-line order
            // (repeatable --sun and --point), the last value wins, and the
            // first bad value is the one reported.
            o->trigger_on_parse();
        }
    }

    std::vector<std::string> args;
    for (int i = argc - 1; i > 0; --i) args.emplace_back(argv[i]);
    // CLI11 reads "--flag=" as "the value follows"; here it is an empty value.
    for (std::size_t k = args.size(); k-- > 0;) {
        const std::string& a = args[k];
        if (a == "--") break;
        if (a.size() > 3 && a.compare(0, 2, "--") == 0 && a.find('=') == a.size() - 1) {
            const Flag* f = find(a.substr(0, a.size() - 1));
            if (f && f->value.empty()) return a.substr(0, a.size() - 1) + ": takes no value";
            if (f) {
                std::string name = a.substr(0, a.size() - 1);
                args[k] = "";
                args.insert(args.begin() + std::ptrdiff_t(k) + 1, name);
            }
        }
    }

    try {
        app.parse(args);
    } catch (const Stop&) {
        return "";
    } catch (const UsageError& e) {
        return e.message;
    } catch (const CLI::ArgumentMismatch& e) {
        // "NAME: 1 required TYPE missing": the flag was the last argument.
        const std::string what = e.what();
        const std::string flag = what.substr(0, what.find(':'));
        if (const Flag* f = find(flag)) {
            if (missing) return missing(flag, f->value);
            return flag + ": missing value (" + f->value + ")";
        }
        return what;
    } catch (const CLI::ParseError& e) {
        return e.what();
    }

    bool only_positional = false;
    for (const std::string& a : app.remaining()) {
        if (!only_positional && a == "--") {
            only_positional = true;
            continue;
        }
        if (only_positional || a.size() < 2 || a[0] != '-') {
            positionals.push_back(a);
            continue;
        }
        const std::string name = a.substr(0, a.find('='));
        if (refuse) {
            const std::string why = refuse(name);
            if (!why.empty()) return why;
        }
        const std::string near = suggest(name);
        if (!near.empty()) return "unknown option '" + a + "' (did you mean " + near + "?)";
        return "unknown option '" + a + "'" + unknown_hint;
    }
    return "";
}

std::string FlagSet::usage(const std::string& head, const std::vector<HelpRow>& rows, const std::string& tail,
                           std::size_t column) const {
    std::vector<int> shown(flags_.size(), 0);
    std::string out = head;
    for (const HelpRow& row : rows) {
        if (row.flags.empty()) {  // words only
            out += "  " + row.caption + "\n";
            continue;
        }
        std::string line = " ";
        std::string caption = row.caption;
        for (const std::string& name : row.flags) {
            const Flag* f = find(name);
            if (!f) throw std::logic_error(tool_ + " --help shows " + name + ", which is not defined");
            ++shown[std::size_t(f - flags_.data())];
            line += " " + f->spelled();
            if (row.flags.size() == 1 && caption.empty()) caption = f->brief;
        }
        if (!caption.empty()) {
            line += std::string(line.size() + 2 < column ? column - line.size() : 2, ' ');
            // Further lines of the words start where the first did.
            const std::string indent(line.size(), ' ');
            std::vector<std::string> parts = split(caption, '\n');
            line += parts[0];
            for (std::size_t k = 1; k < parts.size(); ++k) line += "\n" + indent + parts[k];
        }
        out += line + "\n";
    }
    for (std::size_t i = 0; i < flags_.size(); ++i)
        if (shown[i] != 1)
            throw std::logic_error(tool_ + " --help shows " + flags_[i].name() + " " + std::to_string(shown[i]) +
                                   " times");
    return out + tail;
}

std::string FlagSet::markdown(const std::string& synopsis, const std::string& about,
                              const std::function<bool(const Flag&)>& in_table, const std::string& others) const {
    std::string out = "## " + tool_ + "\n\n```\n" + synopsis + "\n```\n\n" + about + "\n\n";
    for (const Positional& p : positionals_) out += "- `" + p.name + "`: " + p.help + "\n";
    if (!positionals_.empty()) out += "\n";
    out += "| Flag | Default | What it does |\n|---|---|---|\n";
    std::string rest;
    for (const Flag& f : flags_) {
        if (in_table && !in_table(f)) {
            rest += (rest.empty() ? "" : ", ") + ("`" + f.name() + "`");
            continue;
        }
        std::string names;
        for (const std::string& n : f.names) {
            std::string one = n;
            if (!f.value.empty()) one += " " + f.value;
            names += (names.empty() ? "" : ", ") + ("`" + one + "`");
        }
        out += "| " + cell(names) + " | " + cell(f.fallback.empty() || f.fallback.find(' ') != std::string::npos ? f.fallback
                                                                                            : "`" + f.fallback + "`") + " | " +
               cell(f.help.empty() ? f.brief : f.help) + " |\n";
    }
    if (!rest.empty()) out += "\nAnd, as " + others + "'s: " + rest + ".\n";
    return out;
}

} // namespace prast::cli
