// Printable names and capped warning lists; see messages.h.
#include "scene/messages.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>

namespace prast {

namespace {

void append_hex(std::string& out, unsigned char c) {
    char buf[5];
    std::snprintf(buf, sizeof buf, "\\x%02X", unsigned(c));
    out += buf;
}

// Length of the valid UTF-8 sequence starting at s[i] (2..4) and its code
// point, or 0 when the bytes there are not one (RFC 3629: no overlong forms,
// no surrogates, nothing above U+10FFFF).
std::size_t utf8_sequence(const std::string& s, std::size_t i, std::uint32_t& cp) {
    const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
    const unsigned char c = byte(i);
    std::size_t n = 0;
    std::uint32_t min = 0;
    if (c >= 0xC2 && c <= 0xDF) { n = 2; cp = c & 0x1Fu; min = 0x80; }
    else if (c >= 0xE0 && c <= 0xEF) { n = 3; cp = c & 0x0Fu; min = 0x800; }
    else if (c >= 0xF0 && c <= 0xF4) { n = 4; cp = c & 0x07u; min = 0x10000; }
    else return 0;
    if (i + n > s.size()) return 0;
    for (std::size_t k = 1; k < n; ++k) {
        if ((byte(i + k) & 0xC0) != 0x80) return 0;
        cp = cp << 6 | (byte(i + k) & 0x3Fu);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
    return n;
}

// Code points a terminal acts on: C1 controls, and the bidirectional
// overrides and isolates that reorder what is shown ("Trojan Source").
bool is_control(std::uint32_t cp) {
    return (cp >= 0x80 && cp <= 0x9F) || (cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069);
}

// The bytes of the unit of `s` at i that printable() shows as one piece (an
// ASCII character, a valid UTF-8 sequence, one invalid byte) and how many
// characters it shows it as.
std::size_t shown_unit(const std::string& s, std::size_t i, std::size_t& shown) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c >= 0x20 && c < 0x7F) return shown = 1, 1;
    if (c < 0x80) {
        shown = c == '\n' || c == '\r' || c == '\t' || c == 0x1B ? 2 : 4;
        return 1;
    }
    std::uint32_t cp = 0;
    const std::size_t n = utf8_sequence(s, i, cp);
    if (n == 0) return shown = 4, 1;
    shown = is_control(cp) ? 4 * n : 1;
    return n;
}

} // namespace

std::string cut(const std::string& s, std::size_t max_chars) {
    std::size_t i = 0, chars = 0;
    while (i < s.size()) {
        std::size_t shown = 0;
        const std::size_t n = shown_unit(s, i, shown);
        if (chars + shown > max_chars) break;
        chars += shown;
        i += n;
    }
    if (i == s.size()) return s;
    return s.substr(0, i) + "...";
}

std::string printable(const std::string& s) {
    std::string out;
    out.reserve(s.size());
    for (std::size_t i = 0; i < s.size();) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        if (c >= 0x20 && c < 0x7F) {
            out += char(c);
            ++i;
            continue;
        }
        if (c < 0x80) {
            switch (c) {
            case '\n': out += "\\n"; break;
            case '\r': out += "\\r"; break;
            case '\t': out += "\\t"; break;
            case 0x1B: out += "\\e"; break;
            default: append_hex(out, c);
            }
            ++i;
            continue;
        }
        std::uint32_t cp = 0;
        const std::size_t n = utf8_sequence(s, i, cp);
        if (n == 0 || is_control(cp)) {
            // One escape per byte keeps every byte visible and the rule simple.
            for (std::size_t k = 0; k < std::max<std::size_t>(n, 1); ++k)
                append_hex(out, static_cast<unsigned char>(s[i + k]));
            i += std::max<std::size_t>(n, 1);
            continue;
        }
        out.append(s, i, n);
        i += n;
    }
    return out;
}

std::string warning_kind(const std::string& line) {
    std::string kind;
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (c == '\'') {
            quoted = !quoted;
            kind += c;
        } else if (quoted) {
            continue;
        } else if (c >= '0' && c <= '9') {
            if (kind.empty() || kind.back() != '#') kind += '#';
        } else {
            kind += c;
        }
    }
    return kind;
}

void WarningLog::add(const std::string& line) {
    ++total_;
    Kind& k = kinds_[warning_kind(line)];
    if (k.count == 0) k.order = kinds_.size();
    if (++k.count <= per_kind_) kept_.push_back(line);
    else if (k.count == per_kind_ + 1) k.first_dropped = line;
}

std::vector<std::string> WarningLog::lines() const {
    std::vector<std::string> out = kept_;
    std::vector<const Kind*> over;
    for (const auto& entry : kinds_)
        if (entry.second.count > per_kind_) over.push_back(&entry.second);
    std::sort(over.begin(), over.end(), [](const Kind* a, const Kind* b) { return a->order < b->order; });
    for (const Kind* k : over)
        out.push_back(std::to_string(k->count - per_kind_) + " more warnings like: " + k->first_dropped);
    return out;
}

std::vector<std::string> cap_warnings(const std::vector<std::string>& lines, std::size_t per_kind) {
    WarningLog log(per_kind);
    for (const std::string& line : lines) log.add(line);
    return log.lines();
}

} // namespace prast
