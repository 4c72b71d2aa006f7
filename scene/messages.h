// What loaders tell the user about a file from a stranger: names taken from
// the file made safe to print, and warning lists that stay short however many
// times a file repeats the same mistake.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace prast {

// `s` with every control character shown as an escape (\n, \r, \t, \e, else
// \xNN): C0 controls, DEL, the C1 controls U+0080..U+009F and bytes that are
// not part of valid UTF-8. Other UTF-8 text and backslashes are kept, so the
// result prints as one line and printable(printable(s)) == printable(s).
// Used wherever a name from a file (material, light, image, uri, path) or a
// message holding one is printed.
std::string printable(const std::string& s);

// The most characters a name from a file (an extension, a material, a uri)
// takes in a message: a 10,000-character name would make a 10,000-character
// line that says no more than its first words.
constexpr std::size_t kMaxShownChars = 200;

// `s` cut to at most `max_chars` characters as printable() shows them, with
// "..." appended when anything was cut; never inside a UTF-8 sequence or an
// escape, so printable(cut(s)) is at most max_chars + 3 characters. Unchanged
// when it fits. Cut the raw name, then make the message printable.
std::string cut(const std::string& s, std::size_t max_chars = kMaxShownChars);

// How many warnings of one kind are kept before the rest are only counted.
constexpr std::size_t kWarningsPerKind = 5;

// Warnings in arrival order, at most `per_kind` of each kind; a kind is the
// line with its quoted parts ('...') and numbers blanked out, so "texture
// 'a.png' not found" and "texture 'b.png' not found" are one kind. lines()
// ends with one "N more warnings like: <first one not shown>" per kind that
// overflowed.
class WarningLog {
public:
    explicit WarningLog(std::size_t per_kind = kWarningsPerKind) : per_kind_(per_kind) {}
    void add(const std::string& line);
    std::vector<std::string> lines() const;
    std::size_t total() const { return total_; }

private:
    struct Kind {
        std::size_t count = 0;
        std::string first_dropped;
        std::size_t order = 0;
    };
    std::size_t per_kind_;
    std::size_t total_ = 0;
    std::vector<std::string> kept_;
    std::map<std::string, Kind> kinds_;
};

// The kind of a warning line (see WarningLog).
std::string warning_kind(const std::string& line);

// `lines` through a WarningLog: the first few of each kind and a count line.
std::vector<std::string> cap_warnings(const std::vector<std::string>& lines,
                                      std::size_t per_kind = kWarningsPerKind);

} // namespace prast
