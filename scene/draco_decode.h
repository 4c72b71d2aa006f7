// KHR_draco_mesh_compression: a Draco-compressed primitive decoded through
// libdraco (Debian's libdraco-dev, linked statically), with the counts in the
// stream's header checked before libdraco allocates anything for them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace prast::draco_gltf {

// The counts a Draco mesh stream's header announces: its faces and its
// connectivity vertices (libdraco allocates its corner table and attribute
// values from these). Read from the header (bitstream 2.2: "DRACO", version,
// encoder type and method, flags, then for the edgebreaker method its
// traversal type, and both counts as LEB128 varints; for the sequential
// method faces and points).
struct Counts {
    std::uint64_t faces = 0, vertices = 0;
};

// "" with `counts` filled, else why the stream is not one prast decodes (not
// Draco, a point cloud, another bitstream version, metadata, truncated).
std::string read_counts(const unsigned char* data, std::size_t size, Counts& counts);

// "" when a stream of `size` bytes can hold `counts`, else why not: above
// 2^20, more than 4096 faces (or vertices) a byte, far denser than any
// stream libdraco's encoder writes. libdraco allocates about 24 bytes a face
// from the header's counts before it reads the connectivity.
std::string check_density(const Counts& counts, std::size_t size);

// One attribute as the accessor needs it: `components` values of the glTF
// componentType `component_type` per point, little-endian, tightly packed.
struct Attribute {
    int components = 0;
    int component_type = 0;  // glTF enum (5120 ... 5126); 0 for a Draco type glTF has no name for
    bool normalized = false;
    std::vector<unsigned char> bytes;
};

struct Mesh {
    std::size_t points = 0;
    std::vector<std::uint32_t> indices;        // 3 per face
    std::map<int, Attribute> attributes;       // by the Draco unique id the extension names
};

// Decodes the stream (after read_counts accepted it) and fetches the
// attributes `ids`; "" or why not (libdraco's message, or a missing id).
std::string decode(const unsigned char* data, std::size_t size, const std::vector<int>& ids, Mesh& out);

} // namespace prast::draco_gltf
