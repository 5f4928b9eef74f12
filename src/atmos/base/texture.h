// atmos: lookup tables (LUTs) and their sampling, on host and device.
//
// A table holds `channels` (1..4) floats per texel, x fastest, then y, then z.
// Sampling follows GPU texture conventions: coordinates in [0, 1] address the
// whole table, texel i has its centre at (i + 0.5) / size, filtering is linear
// and borders clamp to the edge texel. Bruneton's 2017 implementation notes' mapping helpers
// (GetTextureCoordFromUnitRange and its inverse) map [0, 1] onto the texel
// centres so that the first and last texels hold the range's end points.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "atmos/math.h"
#include "base/table_storage.h"

namespace atmos {

struct Vec4f {
    float x = 0.0f, y = 0.0f, z = 0.0f, w = 0.0f;
    ATMOS_HD Rgb rgb() const { return {x, y, z}; }
};
ATMOS_HD inline Vec4f operator+(const Vec4f& a, const Vec4f& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w};
}
ATMOS_HD inline Vec4f operator*(const Vec4f& a, float s) {
    return {a.x * s, a.y * s, a.z * s, a.w * s};
}

// Bruneton's 2017 implementation notes: x in [0, 1] -> texture coordinate of the texel centres.
ATMOS_HD inline double GetTextureCoordFromUnitRange(double x, int texture_size) {
    return 0.5 / texture_size + x * (1.0 - 1.0 / texture_size);
}
// Bruneton's 2017 implementation notes: the inverse.
ATMOS_HD inline double GetUnitRangeFromTextureCoord(double u, int texture_size) {
    return (u - 0.5 / texture_size) / (1.0 - 1.0 / texture_size);
}

// GetTextureCoordFromUnitRange for one texture size, its two divisions done
// once (the same values, hence bit-identical results).
struct TexelCentreMap {
    double offset = 0.0, scale = 1.0;
    TexelCentreMap() = default;
    ATMOS_HD explicit TexelCentreMap(int texture_size)
        : offset(0.5 / texture_size), scale(1.0 - 1.0 / texture_size) {}
    ATMOS_HD double operator()(double x) const { return offset + x * scale; }
};

// A non-owning, trivially copyable view of a table (device-copyable when
// `data` points to device memory).
struct TableView {
    const float* data = nullptr;
    int width = 0, height = 1, depth = 1;
    int channels = 4;
    // The Table's identity (Table::id()), 0 for a view of other memory: the
    // precomputation loop (render/stages.h) keys device copies by it.
    uint64_t id = 0;

    ATMOS_HD Vec4f Fetch(int x, int y, int z = 0) const {
        x = Clamp(x, 0, width - 1);
        y = Clamp(y, 0, height - 1);
        z = Clamp(z, 0, depth - 1);
        const float* p = data + ((static_cast<size_t>(z) * height + y) * width + x) *
                                    static_cast<size_t>(channels);
        Vec4f v;
        v.x = p[0];
        if (channels > 1) v.y = p[1];
        if (channels > 2) v.z = p[2];
        if (channels > 3) v.w = p[3];
        return v;
    }

    // Linear filtering along x and y (z: the layer, no filtering across layers).
    ATMOS_HD Vec4f SampleBilinear(double u, double v, int layer = 0) const {
        int x0, y0;
        float fx, fy;
        Split(u, width, &x0, &fx);
        Split(v, height, &y0, &fy);
        const Vec4f a = Fetch(x0, y0, layer) * (1.0f - fx) + Fetch(x0 + 1, y0, layer) * fx;
        const Vec4f b = Fetch(x0, y0 + 1, layer) * (1.0f - fx) + Fetch(x0 + 1, y0 + 1, layer) * fx;
        return a * (1.0f - fy) + b * fy;
    }

    ATMOS_HD Vec4f SampleTrilinear(double u, double v, double w) const {
        int z0;
        float fz;
        Split(w, depth, &z0, &fz);
        return SampleBilinear(u, v, z0) * (1.0f - fz) + SampleBilinear(u, v, z0 + 1) * fz;
    }

    // Texture coordinate -> lower texel index and fraction toward the next one,
    // clamped to the edge texels.
    // Selects, not branches: a loop of it under ATMOS_SIMD vectorises
    // (Bruneton's precomputation rows).
    ATMOS_HD static void Split(double u, int size, int* i0, float* f) {
        double x = u * size - 0.5;
        x = x < 0.0 ? 0.0 : x;
        x = x > size - 1 ? size - 1 : x;
        int i = static_cast<int>(x);
        i = i > size - 2 ? (size > 1 ? size - 2 : 0) : i;
        *i0 = i;
        *f = size > 1 ? static_cast<float>(x - i) : 0.0f;
    }
};

// One axis of a filtered lookup: the two texels (the upper one clamped to the
// edge, as TableView::Fetch clamps it) and the fraction (TableView::Split).
struct TexelSpan {
    int i0 = 0, i1 = 0;
    float f = 0.0f;
};
ATMOS_HD inline TexelSpan SplitSpan(double u, int size) {
    TexelSpan s;
    TableView::Split(u, size, &s.i0, &s.f);
    s.i1 = Min(s.i0 + 1, size - 1);
    return s;
}

// TableView::SampleBilinear specialised for a table of C channels, from the
// spans of both axes (computed once for every table of the same size): the
// same operations in the same order, hence bit-identical; no per-texel clamps
// or channel tests. `row0` and `row1`: texel indices of (0, y0) and (0, y1).
template <int C>
ATMOS_HD inline float BilinearChannel(const float* data, size_t row0, size_t row1,
                                      const TexelSpan& x, float fy, int c) {
    const float a = data[(row0 + x.i0) * C + c] * (1.0f - x.f) + data[(row0 + x.i1) * C + c] * x.f;
    const float b = data[(row1 + x.i0) * C + c] * (1.0f - x.f) + data[(row1 + x.i1) * C + c] * x.f;
    return a * (1.0f - fy) + b * fy;
}
// A 2D table's (layer 0) bilinear lookup at the spans x, y: C channels to out.
template <int C>
ATMOS_HD inline void SampleBilinearFixed(const float* data, int width, const TexelSpan& x,
                                         const TexelSpan& y, float out[C]) {
    const size_t row0 = static_cast<size_t>(y.i0) * width;
    const size_t row1 = static_cast<size_t>(y.i1) * width;
    for (int c = 0; c < C; ++c) out[c] = BilinearChannel<C>(data, row0, row1, x, y.f, c);
}
// SampleBilinear(u, v).rgb() of a 3-channel 2D table, bit-identical.
ATMOS_HD inline Rgb SampleBilinearRgb(const TableView& t, double u, double v) {
    ATMOS_DASSERT(t.channels == 3);
    float o[3];
    SampleBilinearFixed<3>(t.data, t.width, SplitSpan(u, t.width), SplitSpan(v, t.height), o);
    return Rgb(o[0], o[1], o[2]);
}

// SampleTrilinear(u, v, w) of a C-channel table at the spans of its three
// axes (shared by tables of the same size), bit-identical.
template <int C>
ATMOS_HD inline void SampleTrilinearFixed(const float* data, int width, int height,
                                          const TexelSpan& x, const TexelSpan& y,
                                          const TexelSpan& z, float out[C]) {
    const size_t w = static_cast<size_t>(width), h = static_cast<size_t>(height);
    const size_t r00 = (z.i0 * h + y.i0) * w, r01 = (z.i0 * h + y.i1) * w;
    const size_t r10 = (z.i1 * h + y.i0) * w, r11 = (z.i1 * h + y.i1) * w;
    for (int c = 0; c < C; ++c) {
        out[c] = BilinearChannel<C>(data, r00, r01, x, y.f, c) * (1.0f - z.f) +
                 BilinearChannel<C>(data, r10, r11, x, y.f, c) * z.f;
    }
}

// A non-owning, trivially copyable, writable view of a table: what a
// precomputation stage (render/stages.h) writes its output through, on the host
// or (re-pointed to device memory) on the device.
struct TableOut {
    float* data = nullptr;
    int width = 0, height = 1, depth = 1;
    int channels = 4;
    uint64_t id = 0;  // as TableView::id
    // False (the default): the stage writes every texel of it and reads none,
    // so a device copy needs no upload. True: the stage reads it too
    // (accumulates into it).
    bool accumulate = false;

    ATMOS_HD size_t Offset(int x, int y, int z = 0) const {
        return ((static_cast<size_t>(z) * height + y) * width + x) * static_cast<size_t>(channels);
    }
    ATMOS_HD float* Texel(int x, int y, int z = 0) const { return data + Offset(x, y, z); }
    ATMOS_HD void Set(int x, int y, int z, const Vec4f& v) const {
        float* p = Texel(x, y, z);
        p[0] = v.x;
        if (channels > 1) p[1] = v.y;
        if (channels > 2) p[2] = v.z;
        if (channels > 3) p[3] = v.w;
    }
    ATMOS_HD size_t size() const {
        return static_cast<size_t>(width) * height * depth * static_cast<size_t>(channels);
    }
    // The same table, read-only.
    ATMOS_HD TableView view() const { return {data, width, height, depth, channels, id}; }
};

// A host-owned table. Its id() is unique in the process and changes whenever
// its storage is replaced (Resize, copy, assignment), never by writes through
// data() / Texel() / Set().
class Table {
  public:
    Table() = default;
    Table(int width, int height, int depth, int channels) {
        Resize(width, height, depth, channels);
    }
    void Resize(int width, int height, int depth, int channels) {
        view_.width = width;
        view_.height = height;
        view_.depth = depth;
        view_.channels = channels;
        data_.assign(static_cast<size_t>(width) * height * depth * channels, 0.0f);
        view_.data = data_.data();
        view_.id = NewId();
    }
    Table(const Table& o) : data_(o.data_), view_(o.view_) {
        view_.data = data_.data();
        view_.id = NewId();
    }
    Table& operator=(const Table& o) {
        data_ = o.data_;
        view_ = o.view_;
        view_.data = data_.data();
        view_.id = NewId();
        return *this;
    }
    // A move keeps the storage, hence the id; the source is left empty.
    Table(Table&& o) noexcept : data_(std::move(o.data_)), view_(o.view_) {
        view_.data = data_.data();
        o.view_ = TableView();
    }
    Table& operator=(Table&& o) noexcept {
        data_ = std::move(o.data_);
        view_ = o.view_;
        view_.data = data_.data();
        o.view_ = TableView();
        return *this;
    }

    const TableView& view() const { return view_; }
    // A writable view (valid until the next Resize or assignment); `accumulate`:
    // see TableOut.
    TableOut out(bool accumulate = false) {
        TableOut o;
        o.data = data_.data();
        o.width = view_.width;
        o.height = view_.height;
        o.depth = view_.depth;
        o.channels = view_.channels;
        o.id = view_.id;
        o.accumulate = accumulate;
        return o;
    }
    uint64_t id() const { return view_.id; }
    // The largest id() handed out so far (0 before the first table).
    static uint64_t LastId() { return NextId().load() - 1; }
    int width() const { return view_.width; }
    int height() const { return view_.height; }
    int depth() const { return view_.depth; }
    int channels() const { return view_.channels; }
    float* data() { return data_.data(); }
    const float* data() const { return data_.data(); }
    size_t size() const { return data_.size(); }
    float* Texel(int x, int y, int z = 0) {
        return data_.data() + ((static_cast<size_t>(z) * view_.height + y) * view_.width + x) *
                                  static_cast<size_t>(view_.channels);
    }
    void Set(int x, int y, int z, const Vec4f& v) {
        float* p = Texel(x, y, z);
        const float values[4] = {v.x, v.y, v.z, v.w};
        for (int c = 0; c < view_.channels; ++c) p[c] = values[c];
    }

  private:
    static std::atomic<uint64_t>& NextId() {
        static std::atomic<uint64_t> next{1};
        return next;
    }
    static uint64_t NewId() { return NextId().fetch_add(1); }
    std::vector<float, TableAllocator<float>> data_;
    TableView view_;
};

}  // namespace atmos
