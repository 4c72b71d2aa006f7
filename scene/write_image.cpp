// Atomic PNG/HDR output; see image_write.h.
#include "scene/write_image.h"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <new>

#include <fcntl.h>
#include <unistd.h>

#include <stb_image_write.h>

#include "scene/encode_png.h"

namespace prast {

namespace {

void append_bytes(void* ctx, void* data, int size) {
    auto* out = static_cast<std::vector<std::uint8_t>*>(ctx);
    const auto* p = static_cast<const std::uint8_t*>(data);
    out->insert(out->end(), p, p + size);
}

// The temporary file being written, for remove_temporary_output(): plain
// storage and a lock-free flag, all a signal handler may touch.
char g_pending_path[4097];
std::atomic<bool> g_pending{false};
static_assert(std::atomic<bool>::is_always_lock_free, "a signal handler reads the flag");

struct PendingGuard {
    ~PendingGuard() { g_pending.store(false); }
};

void write_file_atomic(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    // Next to the target (rename must not cross file systems), hidden, and
    // short: "<target>.tmp<pid>" would pass NAME_MAX for a 250-byte name.
    const std::filesystem::path target(path);
    std::string base = target.filename().string();
    if (base.size() > 64) base.resize(64);
    const std::string tmp = (target.parent_path() / ("." + base + "." + std::to_string(long(getpid())) + ".tmp")).string();
    if (tmp.size() >= sizeof g_pending_path) throw WriteError(path + ": cannot write (path too long)");
    std::memcpy(g_pending_path, tmp.c_str(), tmp.size() + 1);
    g_pending.store(true);
    PendingGuard pending;

    // O_NOFOLLOW: a symbolic link planted under the temporary name is not followed.
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0666);
    if (fd < 0) throw WriteError(path + ": cannot write (" + std::strerror(errno) + ")");
    bool ok = true;
    int err = 0;
    for (std::size_t done = 0; ok && done < bytes.size();) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            ok = false;
            err = n < 0 ? errno : EIO;
        } else {
            done += std::size_t(n);
        }
    }
    if (ok && ::fsync(fd) != 0) {
        ok = false;
        err = errno;
    }
    if (::close(fd) != 0 && ok) {
        ok = false;
        err = errno;
    }
    if (!ok) {
        ::unlink(tmp.c_str());
        throw WriteError(path + ": write failed (" + std::strerror(err) + ")");
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        err = errno;
        ::unlink(tmp.c_str());
        throw WriteError(path + ": cannot replace (" + std::strerror(err) + ")");
    }
}

} // namespace

std::vector<std::uint8_t> encode_png(int width, int height, const std::uint8_t* rgba8) {
    // Every byte is written below: no zero fill first.
    const std::unique_ptr<std::uint8_t[]> rgb(new std::uint8_t[std::size_t(width) * height * 3]);
    for (std::size_t i = 0, n = std::size_t(width) * height; i < n; ++i) {
        rgb[i * 3] = rgba8[i * 4];
        rgb[i * 3 + 1] = rgba8[i * 4 + 1];
        rgb[i * 3 + 2] = rgba8[i * 4 + 2];
    }
    try {
        return encode_png_pixels(rgb.get(), width, height, 3, png_options_threads());
    } catch (const std::bad_alloc&) {
        throw WriteError("PNG encoding failed: out of memory");
    } catch (const std::exception& e) {
        throw WriteError(std::string("PNG encoding failed: ") + e.what());
    }
}

void remove_temporary_output() noexcept {
    if (g_pending.load()) ::unlink(g_pending_path);
}

void write_png_atomic(const std::string& path, int width, int height, const std::uint8_t* rgba8) {
    std::vector<std::uint8_t> bytes;
    try {
        bytes = encode_png(width, height, rgba8);
    } catch (const std::bad_alloc&) {
        throw WriteError(path + ": PNG encoding failed: out of memory");
    } catch (const WriteError& e) {
        throw WriteError(path + ": " + e.what());
    }
    write_file_atomic(path, bytes);
}

void write_hdr_atomic(const std::string& path, int width, int height, const float* rgba) {
    std::vector<float> rgb(std::size_t(width) * height * 3);
    for (std::size_t i = 0, n = std::size_t(width) * height; i < n; ++i)
        for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = rgba[i * 4 + c];
    std::vector<std::uint8_t> bytes;
    if (!stbi_write_hdr_to_func(append_bytes, &bytes, width, height, 3, rgb.data()))
        throw WriteError(path + ": HDR encoding failed");
    write_file_atomic(path, bytes);
}

} // namespace prast
