// The one place where a model's references to other files (an OBJ's mtllib,
// an MTL's map_* paths, a glTF buffer or image uri) become files that are
// read, and the one safe way to read a file.
//
// The rule: a reference resolves only inside the model's folder (the folder
// of the .obj/.gltf/.glb the user named), after backslashes are read as
// separators, `..` is applied and every symbolic link is followed; and only a
// regular file on a real file system is read (no FIFO, device, socket,
// directory, nothing under /proc or /sys). Nothing is looked up in the current
// directory. `--allow-outside-paths` (FileScope's allow_outside) lifts the
// folder rule, never the regular-file rule. A model from the web therefore
// cannot make the renderer read, and leak through its pixels, any other file
// the user can read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "scene/huge_pages.h"

namespace prast {

// No single file is read past this (2 GiB; stb_image and tinygltf take int
// lengths, and no asset of the project comes near it).
constexpr std::uint64_t kMaxReadBytes = std::uint64_t(1) << 31;
// Distinct references one model may name (each is one look-up on disk).
constexpr std::size_t kMaxFileReferences = 4096;
// Bytes read for one model's references together, counting repeats (200
// buffers naming the same 10 MB file read 2 GB).
constexpr std::uint64_t kMaxReferencedBytes = std::uint64_t(4) << 30;

// Opens the regular file at `path` for reading the way read_regular_file does
// (same checks, same messages) and returns the descriptor, which the caller
// closes; `size` receives the file's size.
int open_regular_file(const std::string& path, const std::string& name, std::uint64_t& size);

// Reads the whole regular file at `path`: opened without blocking (a FIFO
// cannot stall the open), checked with fstat to be a regular file and not on
// a pseudo file system, and read to at most its size when opened and at most
// max_bytes. Throws LoadError "NAME: problem" (NAME defaults to the path,
// escaped for printing).
std::vector<unsigned char> read_regular_file(const std::string& path, std::uint64_t max_bytes = kMaxReadBytes,
                                             const std::string& name = "");
// The same into `out`, on huge pages where large (scene/huge_pages.h).
void read_regular_file(const std::string& path, std::uint64_t max_bytes, const std::string& name, HugeBytes& out);

// What a model may read: its folder and the references resolved so far.
class FileScope {
public:
    // `model`: the model file as the user named it (messages show it).
    FileScope(const std::string& model, bool allow_outside);

    struct Resolved {
        std::string path;     // canonical path of a readable regular file; empty when not
        bool missing = false; // no such file (a warning: "not found")
        std::string refused;  // else why it may not be read: the rule, in words
        bool outside = false; // refused by the folder rule (--allow-outside-paths lifts it)
        bool ok() const { return !path.empty(); }
    };

    // Resolves `reference` as written in a file (not percent-decoded; glTF
    // callers decode URIs first) relative to the folder `from_dir` of the file
    // that names it (canonical, inside the scope: root() or a folder of a
    // resolved file). Repeated spellings are answered from a cache; more than
    // kMaxFileReferences distinct ones are refused without touching the disk.
    Resolved resolve(const std::string& from_dir, const std::string& reference);

    // Charges `bytes` read for a reference against kMaxReferencedBytes;
    // returns false (and the reason in `why`) when the budget is spent.
    bool charge(std::uint64_t bytes, std::string& why);

    const std::string& root() const { return root_; }  // canonical model folder
    const std::string& model() const { return model_; }
    bool allow_outside() const { return allow_outside_; }

    // "MODEL: WHAT 'REFERENCE' refused: RULE" with every part printable.
    std::string refusal(const std::string& what, const std::string& reference, const Resolved& r) const;

private:
    Resolved resolve_uncached(const std::string& from_dir, const std::string& reference) const;

    std::string model_;
    std::string root_;
    bool allow_outside_ = false;
    std::map<std::string, Resolved> cache_;  // key: from_dir + '\0' + reference
    std::uint64_t bytes_read_ = 0;
};

// The folder of a resolved (canonical) file, for resolving what it names.
std::string folder_of(const std::string& canonical_path);

} // namespace prast
