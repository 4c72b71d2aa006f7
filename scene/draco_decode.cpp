// Draco decoding for KHR_draco_mesh_compression: libdraco's Decoder, with the
// header's counts read here first (scene/draco_decode.h) so that the loader
// can hold them to the accessors' counts before libdraco allocates.
#include "scene/draco_decode.h"

#include <cstring>
#include <memory>

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

namespace prast::draco_gltf {

namespace {

bool varint(const unsigned char*& p, const unsigned char* end, std::uint64_t& v) {
    v = 0;
    for (int i = 0; i < 5; ++i) {
        if (p >= end) return false;
        const unsigned char b = *p++;
        v |= std::uint64_t(b & 127) << (7 * i);
        if (!(b & 128)) return true;
    }
    return false;  // more than 32 bits
}

int gltf_component(draco::DataType t) {
    switch (t) {
    case draco::DT_INT8: return 5120;
    case draco::DT_UINT8: return 5121;
    case draco::DT_INT16: return 5122;
    case draco::DT_UINT16: return 5123;
    case draco::DT_UINT32: return 5125;
    case draco::DT_FLOAT32: return 5126;
    default: return 0;
    }
}

// libdraco sizes its corner table and vertex arrays from the header's
// counts before it reads the connectivity (about 24 bytes a face: a 1.4 KB
// glTF whose edgebreaker stream and accessors claim 44 million faces took
// 1 GB before libdraco refused it), and an edgebreaker stream codes a very
// regular mesh in few bits, so the counts are held to the stream's size:
// above kDracoFreeElements, at most kMaxDracoElementsPerByte faces (and as
// many vertices) a byte. The densest stream libdraco's encoder wrote in our
// measurements (valence coding, a flat 3000x3000 grid quantized to 1 bit)
// holds 1,020 faces a byte; with 11-bit positions such a grid holds 9.
constexpr std::uint64_t kDracoFreeElements = std::uint64_t(1) << 20;
constexpr std::uint64_t kMaxDracoElementsPerByte = 4096;

std::string density(const char* what, std::uint64_t claimed, std::size_t size) {
    if (claimed <= kDracoFreeElements || claimed <= kMaxDracoElementsPerByte * std::uint64_t(size)) return "";
    return "the Draco stream claims " + std::to_string(claimed) + " " + what + " in only " + std::to_string(size) +
           " bytes (more than " + std::to_string(kMaxDracoElementsPerByte) + " a byte are refused)";
}

} // namespace

std::string read_counts(const unsigned char* data, std::size_t size, Counts& counts) {
    constexpr std::size_t kHeader = 11;  // "DRACO", major, minor, encoder type, method, flags (16 bits)
    if (size < kHeader) return "truncated Draco header";
    if (std::memcmp(data, "DRACO", 5) != 0) return "not a Draco stream (no DRACO signature)";
    const int major = data[5], minor = data[6], type = data[7], method = data[8];
    const unsigned flags = unsigned(data[9]) | unsigned(data[10]) << 8;
    if (major != 2 || minor != 2)
        return "Draco bitstream " + std::to_string(major) + "." + std::to_string(minor) + " is not supported (only 2.2)";
    if (type != 1) return "the Draco stream is not a triangle mesh (encoder type " + std::to_string(type) + ")";
    if (flags & 0x8000) return "Draco metadata is not supported";
    const unsigned char* p = data + kHeader;
    const unsigned char* const end = data + size;
    std::uint64_t a = 0, b = 0;
    if (method == 1) {           // edgebreaker: traversal type, encoded vertices, faces
        if (p >= end) return "truncated Draco header";
        ++p;
        if (!varint(p, end, a) || !varint(p, end, b)) return "truncated Draco header";
        counts.vertices = a;
        counts.faces = b;
    } else if (method == 0) {    // sequential: faces, points
        if (!varint(p, end, a) || !varint(p, end, b)) return "truncated Draco header";
        counts.faces = a;
        counts.vertices = b;
    } else {
        return "unknown Draco encoding method " + std::to_string(method);
    }
    return "";
}

std::string check_density(const Counts& counts, std::size_t size) {
    const std::string why = density("faces", counts.faces, size);
    return why.empty() ? density("vertices", counts.vertices, size) : why;
}

std::string decode(const unsigned char* data, std::size_t size, const std::vector<int>& ids, Mesh& out) {
    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char*>(data), size);
    draco::Decoder decoder;
    auto result = decoder.DecodeMeshFromBuffer(&buffer);
    if (!result.ok()) return "Draco: " + result.status().error_msg_string();
    const std::unique_ptr<draco::Mesh> mesh = std::move(result).value();
    if (!mesh) return "Draco: no mesh";
    out.points = mesh->num_points();
    out.indices.resize(std::size_t(mesh->num_faces()) * 3);
    for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f) {
        const draco::Mesh::Face& face = mesh->face(f);
        for (int c = 0; c < 3; ++c) out.indices[std::size_t(f.value()) * 3 + std::size_t(c)] = face[c].value();
    }
    for (int id : ids) {
        const draco::PointAttribute* att = id >= 0 ? mesh->GetAttributeByUniqueId(std::uint32_t(id)) : nullptr;
        if (!att) return "no Draco attribute with id " + std::to_string(id);
        Attribute a;
        a.components = att->num_components();
        a.component_type = gltf_component(att->data_type());
        a.normalized = att->normalized();
        const std::size_t value = draco::DataTypeLength(att->data_type()) * std::size_t(a.components);
        if (value == 0 || std::size_t(att->byte_stride()) < value) return "Draco attribute " + std::to_string(id) + " has no values";
        a.bytes.resize(out.points * value);
        for (draco::PointIndex i(0); i < mesh->num_points(); ++i)
            std::memcpy(a.bytes.data() + std::size_t(i.value()) * value, att->GetAddressOfMappedIndex(i), value);
        out.attributes[id] = std::move(a);
    }
    return "";
}

} // namespace prast::draco_gltf
