// The vertex pass's per-vertex projection; see vertex.h.
#include "raster/vertex.h"

#include <cmath>
#include <cstddef>

namespace prast {

void project_vertices(const float* vertices, int stride, std::uint32_t begin, std::uint32_t end,
                      const GuardBand& gb, int width, int height, std::uint16_t* codes, WindowVertex* window) {
    for (std::uint32_t v = begin; v < end; ++v) {
        const float* c = vertices + std::size_t(v) * std::size_t(stride);
        bool finite = true;
        for (int k = 0; k < 4; ++k) finite &= std::isfinite(c[k]);
        if (!finite) {
            codes[v] = std::uint16_t(kVertexNotFinite);
            window[v] = WindowVertex{};
            continue;
        }
        codes[v] = std::uint16_t(outcode(c, gb));
        window[v] = window_vertex(c, width, height);
    }
}

} // namespace prast
