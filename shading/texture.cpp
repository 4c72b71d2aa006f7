// Texture: the box-filtered mip chain and the sampler tables; the samplers
// themselves are inline in texture.h.
#include "shading/texture.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace prast {

namespace {


// The source texels under output texel i when a row of n texels becomes
// max(1, n / 2): weights are the overlapped areas, normalised to sum to 1.
struct BoxTaps {
    int first = 0;
    int count = 0;
    float weight[3] = {0.0f, 0.0f, 0.0f};
};

BoxTaps box_taps(int n, int i) {
    BoxTaps t;
    if (n == 1) {  // this axis is already 1 texel: copy
        t.first = 0;
        t.count = 1;
        t.weight[0] = 1.0f;
    } else if (n % 2 == 0) {
        t.first = 2 * i;
        t.count = 2;
        t.weight[0] = t.weight[1] = 0.5f;
    } else {
        // n = 2m + 1 shrinks to m texels of width n / m = 2 + 1/m source texels;
        // output i spans [i n / m, (i + 1) n / m), which overlaps texels 2i, 2i+1
        // and 2i+2 by (m - i) / m, 1 and (i + 1) / m.
        const int m = n / 2;
        t.first = 2 * i;
        t.count = 3;
        t.weight[0] = float(m - i) / float(n);
        t.weight[1] = float(m) / float(n);
        t.weight[2] = float(i + 1) / float(n);
    }
    return t;
}

// Separable area filter: rows first into `tmp`, then columns into dst.
void downsample(const glm::vec4* src, int sw, int sh, glm::vec4* dst, int dw, int dh,
                std::vector<glm::vec4>& tmp) {
    std::vector<BoxTaps> tx(static_cast<std::size_t>(dw)), ty(static_cast<std::size_t>(dh));
    for (int i = 0; i < dw; ++i) tx[i] = box_taps(sw, i);
    for (int j = 0; j < dh; ++j) ty[j] = box_taps(sh, j);

    tmp.assign(std::size_t(dw) * std::size_t(sh), glm::vec4(0.0f));
    for (int y = 0; y < sh; ++y) {
        const glm::vec4* row = src + std::size_t(y) * std::size_t(sw);
        glm::vec4* out = tmp.data() + std::size_t(y) * std::size_t(dw);
        for (int i = 0; i < dw; ++i) {
            const BoxTaps& t = tx[i];
            glm::vec4 sum(0.0f);
            for (int k = 0; k < t.count; ++k) sum += row[t.first + k] * t.weight[k];
            out[i] = sum;
        }
    }
    for (int j = 0; j < dh; ++j) {
        const BoxTaps& t = ty[j];
        glm::vec4* out = dst + std::size_t(j) * std::size_t(dw);
        for (int i = 0; i < dw; ++i) out[i] = glm::vec4(0.0f);
        for (int k = 0; k < t.count; ++k) {
            const glm::vec4* row = tmp.data() + std::size_t(t.first + k) * std::size_t(dw);
            for (int i = 0; i < dw; ++i) out[i] += row[i] * t.weight[k];
        }
    }
}

} // namespace

// The samplers for each (wrap_s, wrap_t), indexed by the Wrap enumerators.
static_assert(int(Wrap::Repeat) == 0 && int(Wrap::ClampToEdge) == 1 && int(Wrap::MirroredRepeat) == 2);
namespace {
constexpr Wrap kR = Wrap::Repeat, kC = Wrap::ClampToEdge, kM = Wrap::MirroredRepeat;
} // namespace
const Texture::Sampler Texture::kTrilinear[3][3] = {
    {&Texture::trilinear_wrapped<kR, kR>, &Texture::trilinear_wrapped<kR, kC>, &Texture::trilinear_wrapped<kR, kM>},
    {&Texture::trilinear_wrapped<kC, kR>, &Texture::trilinear_wrapped<kC, kC>, &Texture::trilinear_wrapped<kC, kM>},
    {&Texture::trilinear_wrapped<kM, kR>, &Texture::trilinear_wrapped<kM, kC>, &Texture::trilinear_wrapped<kM, kM>}};
const Texture::LevelSampler Texture::kBilinear[3][3] = {
    {&Texture::bilinear_wrapped<kR, kR>, &Texture::bilinear_wrapped<kR, kC>, &Texture::bilinear_wrapped<kR, kM>},
    {&Texture::bilinear_wrapped<kC, kR>, &Texture::bilinear_wrapped<kC, kC>, &Texture::bilinear_wrapped<kC, kM>},
    {&Texture::bilinear_wrapped<kM, kR>, &Texture::bilinear_wrapped<kM, kC>, &Texture::bilinear_wrapped<kM, kM>}};

Texture::Texture() {
    texels_.assign(1, glm::vec4(1.0f));
    levels_[0] = Level{1, 1, 1.0f, 1.0f, 0};
    level_count_ = 1;
}

Texture Texture::from_image(Image img, Wrap s, Wrap t) {
    if (img.empty())
        throw std::invalid_argument("Texture::from_image: empty image (" +
                                    std::to_string(img.width) + "x" + std::to_string(img.height) + ")");
    const std::size_t count0 = std::size_t(img.width) * std::size_t(img.height);
    if (img.rgba.size() != count0 * 4)
        throw std::invalid_argument("Texture::from_image: rgba holds " +
                                    std::to_string(img.rgba.size()) + " floats, expected " +
                                    std::to_string(count0 * 4));
    Texture tex;
    tex.wrap_s_ = s;
    tex.wrap_t_ = t;

    // Lay out the chain: halve, round down, at least 1.
    int w = img.width, h = img.height, n = 0;
    std::size_t total = 0;
    for (;;) {
        tex.levels_[n] = Level{w, h, float(w), float(h), total};
        total += std::size_t(w) * std::size_t(h);
        ++n;
        if (w == 1 && h == 1) break;
        w = std::max(1, w / 2);
        h = std::max(1, h / 2);
    }
    tex.level_count_ = n;

    // Level 0 is the image; each further level is the box-filtered one above.
    tex.texels_.assign(total, glm::vec4(0.0f));
    for (std::size_t i = 0; i < count0; ++i)
        tex.texels_[i] = glm::vec4(img.rgba[4 * i], img.rgba[4 * i + 1], img.rgba[4 * i + 2],
                                   img.rgba[4 * i + 3]);
    img = Image();  // release the source before the chain needs its scratch row
    std::vector<glm::vec4> tmp;
    for (int l = 1; l < n; ++l) {
        const Level& a = tex.levels_[l - 1];
        const Level& b = tex.levels_[l];
        downsample(tex.texels_.data() + a.offset, a.width, a.height, tex.texels_.data() + b.offset,
                   b.width, b.height, tmp);
    }
    return tex;
}

glm::vec4 Texture::texel(int level, int x, int y) const {
    const Level& L = levels_[clamp_level(level)];
    x = std::clamp(x, 0, L.width - 1);
    y = std::clamp(y, 0, L.height - 1);
    return texels_[L.offset + std::size_t(y) * std::size_t(L.width) + std::size_t(x)];
}

} // namespace prast
