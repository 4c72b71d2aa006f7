// Helpers for the end-to-end tests of the `render` executable: a scratch
// directory to run it in, running it with stdout and stderr captured, and
// reading back the images it writes.
#pragma once

#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <unistd.h>

#include <stb_image.h>

namespace prast::cli_test {

namespace fs = std::filesystem;

// Single-quoted for /bin/sh: safe for any file name.
inline std::string shell_quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) {
        if (c == '\'') q += "'\\''";
        else q += c;
    }
    return q + "'";
}

inline std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline std::vector<std::uint8_t> read_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void write_text(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

// Lines of a text, without their '\n'.
inline std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::size_t begin = 0;
    while (begin < text.size()) {
        std::size_t end = text.find('\n', begin);
        if (end == std::string::npos) end = text.size();
        lines.push_back(text.substr(begin, end - begin));
        begin = end + 1;
    }
    return lines;
}

struct CliRun {
    int code = -1;    // exit code; 128 + signal when the process was killed
    std::string out;  // stdout
    std::string err;  // stderr
};

// A scratch directory: `render` runs with work() as its current directory,
// and its stdout/stderr are captured next to it, so work() holds exactly the
// files the render wrote. Removed with everything in it at scope exit.
class CliSandbox {
public:
    CliSandbox() {
        static int counter = 0;
        const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
        root_ = fs::temp_directory_path() / ("prast_cli_" + std::to_string(long(getpid())) + "_" +
                                             std::to_string(counter++) + "_" + std::to_string(stamp % 1000000));
        fs::create_directories(root_ / "work");
    }
    ~CliSandbox() {
        std::error_code ec;
        fs::permissions(work(), fs::perms::owner_all, fs::perm_options::add, ec);
        fs::remove_all(root_, ec);
    }
    CliSandbox(const CliSandbox&) = delete;
    CliSandbox& operator=(const CliSandbox&) = delete;

    fs::path work() const { return root_ / "work"; }
    std::string path(const std::string& name) const { return (work() / name).string(); }

    // Runs `exe args...` in work(), after the shell commands `setup` (e.g. a ulimit).
    CliRun run_exe(const std::string& exe, const std::vector<std::string>& args,
                   const std::string& setup = "") const {
        return run(exe, args, setup, "/dev/null");
    }
    // As run_exe, with `input` as standard input (step reads its commands there).
    CliRun run_exe_with_input(const std::string& exe, const std::vector<std::string>& args,
                              const std::string& input) const {
        write_text(root_ / "stdin.txt", input);
        return run(exe, args, "", (root_ / "stdin.txt").string());
    }

    // Names of the files (and directories) in work(), sorted.
    std::vector<std::string> work_files() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(work())) names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

private:
    CliRun run(const std::string& exe, const std::vector<std::string>& args, const std::string& setup,
               const std::string& stdin_path) const {
        std::string cmd = "cd " + shell_quote(work().string()) + " && " + (setup.empty() ? "" : setup + " && ") +
                          shell_quote(exe);
        for (const std::string& a : args) cmd += " " + shell_quote(a);
        cmd += " >" + shell_quote((root_ / "stdout.txt").string()) + " 2>" +
               shell_quote((root_ / "stderr.txt").string()) + " <" + shell_quote(stdin_path);
        const int status = std::system(cmd.c_str());
        CliRun r;
        if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
        else if (status != -1 && WIFSIGNALED(status)) r.code = 128 + WTERMSIG(status);
        r.out = read_text(root_ / "stdout.txt");
        r.err = read_text(root_ / "stderr.txt");
        return r;
    }

    fs::path root_;
};

// An 8-bit RGB image read back with stb_image (empty when unreadable).
struct Rgb8 {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;

    bool empty() const { return rgb.empty(); }
    double mean() const {
        double sum = 0.0;
        for (std::uint8_t v : rgb) sum += v;
        return rgb.empty() ? 0.0 : sum / double(rgb.size());
    }
    const std::uint8_t* at(int x, int y) const { return &rgb[(std::size_t(y) * width + x) * 3]; }
};

inline Rgb8 load_rgb8(const std::string& path) {
    Rgb8 img;
    int comp = 0;
    unsigned char* data = stbi_load(path.c_str(), &img.width, &img.height, &comp, 3);
    if (!data) return Rgb8{};
    img.rgb.assign(data, data + std::size_t(img.width) * img.height * 3);
    stbi_image_free(data);
    return img;
}

// Linear float RGB from a Radiance .hdr (empty when unreadable).
struct RgbFloat {
    int width = 0, height = 0;
    std::vector<float> rgb;
};

inline RgbFloat load_hdr(const std::string& path) {
    RgbFloat img;
    int comp = 0;
    float* data = stbi_loadf(path.c_str(), &img.width, &img.height, &comp, 3);
    if (!data) return RgbFloat{};
    img.rgb.assign(data, data + std::size_t(img.width) * img.height * 3);
    stbi_image_free(data);
    return img;
}

} // namespace prast::cli_test
