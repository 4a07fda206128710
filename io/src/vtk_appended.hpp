#pragma once
// The appended raw-data section of VTK XML files (.vtp, .vtu): arrays declared one after another,
// each written as a UInt64 byte count and its values, through a bounded buffer (no copy of a
// whole field). Private to io/.

#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

namespace gpa::io::detail {

// Component c of the Cauchy stress s - P I as VTK's symmetric tensor, in the order ParaView reads
// six components: XX, YY, ZZ, XY, YZ, XZ. 2D snapshots draw (x, z) as VTK's (X, Y), so X = x,
// Y = z and Z is the out-of-plane direction (hoop in axisymmetric geometry); `s` holds the stored
// deviator in the order of geometry.hpp (2D: xx, zz, xz, out of plane; 3D: xx, yy, zz, yz, xz, xy).
inline double vtk_stress_component(const double* s, double pressure, int dim, int c) {
    if (dim == 2) {
        switch (c) {
            case 0: return s[0] - pressure;  // xx
            case 1: return s[1] - pressure;  // zz
            case 2: return s[3] - pressure;  // out of plane
            case 3: return s[2];             // xz
            default: return 0.0;             // the out-of-plane shears vanish
        }
    }
    switch (c) {
        case 0: return s[0] - pressure;  // xx
        case 1: return s[1] - pressure;  // yy
        case 2: return s[2] - pressure;  // zz
        case 3: return s[5];             // xy
        case 4: return s[3];             // yz
        default: return s[4];            // xz
    }
}

class AppendedBlocks {
public:
    // A Float64 array of `components` values for each of `count` entries, or Float32 (each value
    // rounded to the nearest float) with `float32`; returns its offset in the appended section (the
    // `offset` attribute of its DataArray).
    std::uint64_t add_float(std::size_t count, int components, std::function<double(std::size_t, int)> value, bool float32 = false) {
        if (float32) {
            return add(count, components, 4, [value = std::move(value)](std::size_t i, int c, char* out) {
                const float v = static_cast<float>(value(i, c));
                std::memcpy(out, &v, 4);
            });
        }
        return add(count, components, 8, [value = std::move(value)](std::size_t i, int c, char* out) {
            const double v = value(i, c);
            std::memcpy(out, &v, 8);
        });
    }
    // An Int32 array (body and material indices).
    std::uint64_t add_int32(std::size_t count, std::function<std::int32_t(std::size_t)> value) {
        return add(count, 1, 4, [value = std::move(value)](std::size_t i, int, char* out) {
            const std::int32_t v = value(i);
            std::memcpy(out, &v, 4);
        });
    }
    // An Int64 array (connectivity, offsets).
    std::uint64_t add_int64(std::size_t count, std::function<std::int64_t(std::size_t)> value) {
        return add(count, 1, 8, [value = std::move(value)](std::size_t i, int, char* out) {
            const std::int64_t v = value(i);
            std::memcpy(out, &v, 8);
        });
    }
    // A UInt8 array (cell types, flags).
    std::uint64_t add_uint8(std::size_t count, std::function<std::uint8_t(std::size_t)> value) {
        return add(count, 1, 1, [value = std::move(value)](std::size_t i, int, char* out) { *out = static_cast<char>(value(i)); });
    }

    // Writes every block, in the order declared.
    void write(std::ofstream& out) const {
        std::vector<char> buffer;
        const auto flush = [&] {
            out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
            buffer.clear();
        };
        for (const Block& b : blocks_) {
            const std::uint64_t bytes = static_cast<std::uint64_t>(b.count) * b.components * b.width;
            const char* p = reinterpret_cast<const char*>(&bytes);
            buffer.insert(buffer.end(), p, p + 8);
            char value[8];
            for (std::size_t i = 0; i < b.count; ++i) {
                for (int c = 0; c < b.components; ++c) {
                    b.put(i, c, value);
                    buffer.insert(buffer.end(), value, value + b.width);
                }
                if (buffer.size() >= (std::size_t{1} << 20)) flush();
            }
            flush();
        }
    }

    // The <DataArray> tags of arrays declared here, one per line at `indent`.
    struct Declared {
        std::string name;  // empty: no Name attribute (the Points array)
        const char* type;  // "Float64", "Float32", "Int64", "Int32", "UInt8"
        int components;
        std::uint64_t offset;
    };
    static void write_tags(std::ofstream& out, const char* indent, const std::vector<Declared>& arrays) {
        for (const Declared& a : arrays) {
            out << indent << "<DataArray type=\"" << a.type << '"';
            if (!a.name.empty()) out << " Name=\"" << a.name << '"';
            out << " NumberOfComponents=\"" << a.components << "\" format=\"appended\" offset=\"" << a.offset << "\"/>\n";
        }
    }

private:
    struct Block {
        std::size_t count;
        int components;
        int width;
        std::function<void(std::size_t, int, char*)> put;
    };
    std::uint64_t add(std::size_t count, int components, int width, std::function<void(std::size_t, int, char*)> put) {
        const std::uint64_t at = offset_;
        offset_ += 8 + static_cast<std::uint64_t>(count) * components * width;
        blocks_.push_back({count, components, width, std::move(put)});
        return at;
    }
    std::vector<Block> blocks_;
    std::uint64_t offset_ = 0;
};

}  // namespace gpa::io::detail
