// Confined resolution of a model's references and safe reading of regular
// files; see file_access.h.
#include "scene/file_access.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/statfs.h>
#include <unistd.h>

#include "scene/messages.h"
#include "scene/scene.h"

namespace prast {

namespace fs = std::filesystem;

namespace {

// What a non-regular file is, for messages.
const char* file_type_name(mode_t mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

// Kernel pseudo file systems: their "regular" files report size 0 or
// anything at all (/proc/self/pagemap reads for gigabytes), and reading some
// has side effects. Magic numbers from linux/magic.h.
bool pseudo_file_system(long type) {
    switch (static_cast<unsigned long>(type) & 0xFFFFFFFFul) {
    case 0x9FA0ul:      // proc
    case 0x62656572ul:  // sysfs
    case 0x64626720ul:  // debugfs
    case 0x74726163ul:  // tracefs
    case 0x73636673ul:  // securityfs
    case 0x27E0EBul:    // cgroup
    case 0x63677270ul:  // cgroup2
    case 0xCAFE4A11ul:  // bpf
    case 0x62656570ul:  // configfs
    case 0xDE5E81E4ul:  // efivarfs
    case 0x6165676Cul:  // pstore
        return true;
    default:
        return false;
    }
}

// True when the lexically normal absolute path `p` is `root` or below it.
bool within(const std::string& p, const std::string& root) {
    if (root == "/") return !p.empty() && p[0] == '/';
    if (p.compare(0, root.size(), root) != 0) return false;
    return p.size() == root.size() || p[root.size()] == '/';
}

} // namespace

int open_regular_file(const std::string& path, const std::string& name_in, std::uint64_t& size) {
    const std::string name = printable(name_in.empty() ? path : name_in);
    // Refuse what is not a regular file before opening it: opening a device
    // can have effects of its own.
    struct stat st;
    if (::stat(path.c_str(), &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR) throw LoadError(name + ": cannot open file (no such file)");
        throw LoadError(name + ": cannot open file (" + std::strerror(errno) + ")");
    }
    if (S_ISDIR(st.st_mode)) throw LoadError(name + ": is a directory, not a file");
    if (!S_ISREG(st.st_mode))
        throw LoadError(name + ": not a regular file (" + file_type_name(st.st_mode) + "), not read");

    // O_NONBLOCK: should the path have become a FIFO since, the open cannot hang.
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) throw LoadError(name + ": cannot open file (" + std::strerror(errno) + ")");
    std::string bad;
    struct statfs sfs;
    if (::fstat(fd, &st) != 0) bad = std::string("cannot read file (") + std::strerror(errno) + ")";
    else if (!S_ISREG(st.st_mode)) bad = std::string("not a regular file (") + file_type_name(st.st_mode) + "), not read";
    else if (::fstatfs(fd, &sfs) == 0 && pseudo_file_system(long(sfs.f_type)))
        bad = "on a kernel pseudo file system (/proc, /sys), not read";
    if (!bad.empty()) {
        ::close(fd);
        throw LoadError(name + ": " + bad);
    }
    size = std::uint64_t(st.st_size);
    return fd;
}

namespace {

template <class Bytes>
void read_whole_file(const std::string& path, std::uint64_t max_bytes, const std::string& name_in, Bytes& bytes) {
    const std::string name = printable(name_in.empty() ? path : name_in);
    std::uint64_t size = 0;
    const int fd = open_regular_file(path, name_in, size);
    struct FdCloser {
        int fd;
        ~FdCloser() { ::close(fd); }
    } closer{fd};
    // At most the size stat gave when opened: a file that grows (or claims
    // more than it holds) cannot make the read go on.
    if (size == 0) throw LoadError(name + ": empty file");
    if (size > max_bytes)
        throw LoadError(name + ": file too large (" + std::to_string(size) + " bytes; the limit is " +
                        std::to_string(max_bytes) + ")");
    bytes.assign(static_cast<std::size_t>(size), 0);
    std::size_t got = 0;
    while (got < bytes.size()) {
        const ssize_t n = ::read(fd, bytes.data() + got, bytes.size() - got);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw LoadError(name + ": read error (" + std::strerror(errno) + ")");
        if (n == 0) throw LoadError(name + ": read error (the file shrank while being read)");
        got += std::size_t(n);
    }
}

} // namespace

std::vector<unsigned char> read_regular_file(const std::string& path, std::uint64_t max_bytes,
                                             const std::string& name) {
    std::vector<unsigned char> bytes;
    read_whole_file(path, max_bytes, name, bytes);
    return bytes;
}

void read_regular_file(const std::string& path, std::uint64_t max_bytes, const std::string& name, HugeBytes& out) {
    read_whole_file(path, max_bytes, name, out);
}

FileScope::FileScope(const std::string& model, bool allow_outside) : model_(model), allow_outside_(allow_outside) {
    fs::path dir = fs::path(model).parent_path();
    if (dir.empty()) dir = ".";
    std::error_code ec;
    fs::path root = fs::canonical(dir, ec);
    if (ec) root = fs::absolute(dir, ec).lexically_normal();
    root_ = root.string();
    if (root_.size() > 1 && root_.back() == '/') root_.pop_back();
}

FileScope::Resolved FileScope::resolve(const std::string& from_dir, const std::string& reference) {
    std::string key = from_dir;
    key += '\0';
    key += reference;
    const auto found = cache_.find(key);
    if (found != cache_.end()) return found->second;
    if (cache_.size() >= kMaxFileReferences) {
        Resolved r;
        r.refused = "the model names more than " + std::to_string(kMaxFileReferences) + " files";
        return r;
    }
    Resolved r = resolve_uncached(from_dir, reference);
    cache_.emplace(std::move(key), r);
    return r;
}

FileScope::Resolved FileScope::resolve_uncached(const std::string& from_dir, const std::string& reference) const {
    Resolved r;
    if (reference.empty()) {
        r.missing = true;
        return r;
    }
    if (reference.find('\0') != std::string::npos) {
        r.refused = "the name holds a NUL byte";
        return r;
    }
    // Windows exporters write backslashes; a backslash is never part of a
    // name here, so "..\\..\\x" climbs like "../../x".
    std::string ref = reference;
    for (char& c : ref)
        if (c == '\\') c = '/';
    const fs::path written(ref);
    const bool absolute = written.is_absolute();
    const fs::path joined = (absolute ? written : fs::path(from_dir) / written).lexically_normal();
    std::string joined_str = joined.string();
    if (joined_str.size() > 1 && joined_str.back() == '/') joined_str.pop_back();

    // Lexical check first, so that nothing outside is even looked at.
    const std::string folder = "the model's folder " + printable(root_);
    if (!allow_outside_ && !within(joined_str, root_)) {
        r.refused = absolute ? "an absolute path outside " + folder : "climbs out of " + folder + " with '..'";
        r.outside = true;
        return r;
    }
    std::error_code ec;
    const fs::path real = fs::canonical(joined, ec);
    if (ec) {
        if (ec == std::errc::no_such_file_or_directory || ec == std::errc::not_a_directory) r.missing = true;
        else r.refused = "cannot be resolved (" + ec.message() + ")";
        return r;
    }
    const std::string real_str = real.string();
    if (!allow_outside_ && !within(real_str, root_)) {
        r.refused = "a symbolic link leads outside " + folder;
        r.outside = true;
        return r;
    }
    struct stat st;
    if (::stat(real_str.c_str(), &st) != 0) {
        r.missing = true;
        return r;
    }
    if (!S_ISREG(st.st_mode)) {
        r.refused = std::string("not a regular file (") + file_type_name(st.st_mode) + ")";
        return r;
    }
    struct statfs sfs;
    if (::statfs(real_str.c_str(), &sfs) == 0 && pseudo_file_system(long(sfs.f_type))) {
        r.refused = "on a kernel pseudo file system (/proc, /sys)";
        return r;
    }
    r.path = real_str;
    return r;
}

bool FileScope::charge(std::uint64_t bytes, std::string& why) {
    bytes_read_ += bytes;
    if (bytes_read_ <= kMaxReferencedBytes) return true;
    why = "the files the model names add up to more than " + std::to_string(kMaxReferencedBytes) + " bytes";
    return false;
}

std::string FileScope::refusal(const std::string& what, const std::string& reference, const Resolved& r) const {
    std::string line = printable(model_) + ": " + printable(what) + " '" + printable(cut(reference)) + "' refused: " +
                       r.refused;
    if (r.outside) line += " (--allow-outside-paths reads it)";
    return line;
}

std::string folder_of(const std::string& canonical_path) { return fs::path(canonical_path).parent_path().string(); }

} // namespace prast
