// scene/ply_loader.cpp: a strict PLY reader. Every count comes from the file, so none is trusted
// for an allocation: elements are read one at a time and the data running out is an error.
#include "scene/ply_loader.h"

#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

namespace shadowlab::scene {
namespace {

enum class Format { Ascii, BinaryLittle, BinaryBig };

// The PLY scalar types (both spellings: "uchar" and "uint8", ...), by size and kind.
struct Type {
    int size = 0;
    bool integer = false, isSigned = false;
};

std::optional<Type> typeNamed(const std::string& name) {
    if (name == "char" || name == "int8") return Type{1, true, true};
    if (name == "uchar" || name == "uint8") return Type{1, true, false};
    if (name == "short" || name == "int16") return Type{2, true, true};
    if (name == "ushort" || name == "uint16") return Type{2, true, false};
    if (name == "int" || name == "int32") return Type{4, true, true};
    if (name == "uint" || name == "uint32") return Type{4, true, false};
    if (name == "float" || name == "float32") return Type{4, false, true};
    if (name == "double" || name == "float64") return Type{8, false, true};
    return std::nullopt;
}

struct Property {
    std::string name;
    Type type;                  // the value's (a list's entries')
    std::optional<Type> count;  // a list: the type of its length
};

struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> properties;
};

// Values from the body, in the file's format; `where` says which element and property for
// messages.
class Body {
public:
    Body(const std::string& bytes, std::size_t start, Format format) : bytes_(bytes), at_(start), format_(format) {}

    double read(const Type& t, const std::string& where) {
        if (format_ == Format::Ascii) return readText(t, where);
        if (bytes_.size() - at_ < std::size_t(t.size))
            throw PlyError("the data ends inside " + where + " (the header promises more)");
        unsigned char raw[8];
        std::memcpy(raw, bytes_.data() + at_, std::size_t(t.size));
        at_ += std::size_t(t.size);
        const bool swap = (format_ == Format::BinaryBig) == (std::endian::native == std::endian::little);
        if (swap)
            for (int i = 0; i < t.size / 2; ++i) std::swap(raw[i], raw[t.size - 1 - i]);
        if (!t.integer) {
            if (t.size == 4) {
                float f;
                std::memcpy(&f, raw, 4);
                return f;
            }
            double d;
            std::memcpy(&d, raw, 8);
            return d;
        }
        std::uint64_t u = 0;
        for (int i = t.size - 1; i >= 0; --i) u = (u << 8) | raw[i];  // raw is little-endian now
        if (t.isSigned && (u >> (8 * t.size - 1)) & 1u)
            return double(std::int64_t(u) - (std::int64_t(1) << (8 * t.size)));
        return double(u);
    }

    std::size_t remaining() const { return bytes_.size() - at_; }

private:
    double readText(const Type& t, const std::string& where) {
        while (at_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[at_]))) ++at_;
        if (at_ == bytes_.size()) throw PlyError("the data ends inside " + where + " (the header promises more)");
        std::size_t end = at_;
        while (end < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[end]))) ++end;
        const bool tooLong = end - at_ > 64;  // no number is written with more characters
        const std::string token = bytes_.substr(at_, std::min<std::size_t>(end - at_, 64));
        at_ = end;
        char* stop = nullptr;
        const double v = std::strtod(token.c_str(), &stop);
        if (tooLong || *stop != '\0') throw PlyError(where + ": '" + token + "' is not a number");
        if (t.integer && v != std::floor(v)) throw PlyError(where + ": '" + token + "' is not an integer");
        return !t.integer && t.size == 4 ? double(float(v)) : v;  // as a binary file would hold it
    }

    const std::string& bytes_;
    std::size_t at_;
    Format format_;
};

// The header's lines up to "end_header"; sets `bodyStart` just after it.
std::vector<std::string> headerLines(const std::string& bytes, std::size_t& bodyStart) {
    constexpr std::size_t kMaxHeader = 1 << 16;  // far beyond any real header; bounds the scan
    std::vector<std::string> lines;
    std::size_t at = 0;
    while (at < bytes.size() && at < kMaxHeader) {
        std::size_t end = bytes.find('\n', at);
        if (end == std::string::npos) break;
        std::string line = bytes.substr(at, end - at);
        if (!line.empty() && line.back() == '\r') line.pop_back();
        at = end + 1;
        if (line == "end_header") {
            bodyStart = at;
            return lines;
        }
        lines.push_back(std::move(line));
    }
    throw PlyError("has no 'end_header' line within its first 64 KiB");
}

std::vector<std::string> words(const std::string& line) {
    std::istringstream in(line);
    std::vector<std::string> out;
    for (std::string w; in >> w;) out.push_back(w);
    return out;
}

}  // namespace

void loadPly(const std::string& bytes, TriangleMesh& mesh) {
    if (bytes.compare(0, 4, "ply\n") != 0 && bytes.compare(0, 5, "ply\r\n") != 0)
        throw PlyError("is not a PLY file (it does not begin with the line 'ply')");
    std::size_t bodyStart = 0;
    const std::vector<std::string> lines = headerLines(bytes, bodyStart);
    std::optional<Format> format;
    std::vector<Element> elements;
    for (std::size_t i = 1; i < lines.size(); ++i) {
        const std::vector<std::string> w = words(lines[i]);
        const std::string at = "header line " + std::to_string(i + 1);
        if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
        if (w[0] == "format") {
            if (w.size() != 3 || w[2].rfind("1.", 0) != 0)
                throw PlyError(at + ": expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
            if (w[1] == "ascii")
                format = Format::Ascii;
            else if (w[1] == "binary_little_endian")
                format = Format::BinaryLittle;
            else if (w[1] == "binary_big_endian")
                format = Format::BinaryBig;
            else
                throw PlyError(at + ": unknown format '" + w[1].substr(0, 40) + "'");
        } else if (w[0] == "element") {
            if (w.size() != 3) throw PlyError(at + ": expected 'element NAME COUNT'");
            Element e;
            e.name = w[1].substr(0, 40);
            char* stop = nullptr;
            errno = 0;
            e.count = std::strtoull(w[2].c_str(), &stop, 10);
            if (*stop != '\0' || w[2][0] == '-' || errno == ERANGE)
                throw PlyError(at + ": element count '" + w[2].substr(0, 40) + "' is not a count");
            elements.push_back(std::move(e));
        } else if (w[0] == "property") {
            if (elements.empty()) throw PlyError(at + ": a property before any element");
            Property p;
            const bool list = w.size() >= 2 && w[1] == "list";
            if (list ? w.size() != 5 : w.size() != 3)
                throw PlyError(at + ": expected 'property TYPE NAME' or 'property list COUNTTYPE TYPE NAME'");
            const auto type = typeNamed(w[list ? 3 : 1]);
            if (!type) throw PlyError(at + ": unknown type '" + w[list ? 3 : 1].substr(0, 40) + "'");
            p.type = *type;
            if (list) {
                p.count = typeNamed(w[2]);
                if (!p.count || !p.count->integer)
                    throw PlyError(at + ": a list's count type must be an integer type, got '" + w[2].substr(0, 40) +
                                   "'");
            }
            p.name = w.back().substr(0, 40);
            elements.back().properties.push_back(std::move(p));
        } else {
            throw PlyError(at + ": unknown keyword '" + w[0].substr(0, 40) + "'");
        }
    }
    if (!format) throw PlyError("the header has no 'format' line");

    const std::size_t base = mesh.positions.size();
    std::vector<Vec3> positions, normals;
    std::vector<std::uint32_t> indices;
    bool sawVertices = false, sawFaces = false, hasNormals = false;
    Body body(bytes, bodyStart, *format);
    for (const Element& e : elements) {
        // Where each property of interest sits in the element (-1: absent).
        auto find = [&](const char* name) {
            for (std::size_t k = 0; k < e.properties.size(); ++k)
                if (e.properties[k].name == name) return int(k);
            return -1;
        };
        const bool isVertex = e.name == "vertex", isFace = e.name == "face";
        int x = -1, y = -1, z = -1, nx = -1, ny = -1, nz = -1, list = -1;
        if (isVertex) {
            sawVertices = true;
            x = find("x"), y = find("y"), z = find("z");
            if (x < 0 || y < 0 || z < 0) throw PlyError("element vertex has no x, y and z properties");
            for (int k : {x, y, z})
                if (e.properties[std::size_t(k)].count) throw PlyError("element vertex: x, y and z must not be lists");
            nx = find("nx"), ny = find("ny"), nz = find("nz");
            hasNormals = nx >= 0 && ny >= 0 && nz >= 0 && !e.properties[std::size_t(nx)].count &&
                         !e.properties[std::size_t(ny)].count && !e.properties[std::size_t(nz)].count;
        }
        if (isFace) {
            sawFaces = true;
            list = find("vertex_indices");
            if (list < 0) list = find("vertex_index");
            if (list < 0 || !e.properties[std::size_t(list)].count || !e.properties[std::size_t(list)].type.integer)
                throw PlyError("element face has no integer list property vertex_indices");
        }
        if (e.properties.empty()) continue;  // nothing to read, however many it counts
        std::vector<double> corners;
        for (std::uint64_t i = 0; i < e.count; ++i) {
            // A binary element is at least a byte a property: a count past the data fails here
            // instead of looping over nothing.
            if (*format != Format::Ascii && body.remaining() < e.properties.size())
                throw PlyError("the data ends at " + e.name + " " + std::to_string(i) + " of " +
                               std::to_string(e.count) + " (the header promises more)");
            double v[6] = {0, 0, 0, 0, 0, 0};
            for (std::size_t k = 0; k < e.properties.size(); ++k) {
                const Property& p = e.properties[k];
                const std::string where = e.name + " " + std::to_string(i) + " property " + p.name;
                if (!p.count) {
                    const double value = body.read(p.type, where);
                    const int ki = int(k);
                    if (ki == x)
                        v[0] = value;
                    else if (ki == y)
                        v[1] = value;
                    else if (ki == z)
                        v[2] = value;
                    else if (ki == nx)
                        v[3] = value;
                    else if (ki == ny)
                        v[4] = value;
                    else if (ki == nz)
                        v[5] = value;
                    continue;
                }
                const double n = body.read(*p.count, where + " (its length)");
                if (n < 0) throw PlyError(where + ": a list of negative length " + std::to_string(std::int64_t(n)));
                if (*format != Format::Ascii && n * p.type.size > double(body.remaining()))
                    throw PlyError(where + ": the data ends inside its list of " + std::to_string(std::uint64_t(n)) +
                                   " entries (the header promises more)");
                corners.clear();
                for (std::uint64_t c = 0; c < std::uint64_t(n); ++c) corners.push_back(body.read(p.type, where));
                if (int(k) != list) continue;
                if (corners.size() < 3)
                    throw PlyError(where + ": a face of " + std::to_string(corners.size()) + " corners (at least 3)");
                for (double c : corners)
                    if (c < 0 || c > double(std::numeric_limits<std::uint32_t>::max()))
                        throw PlyError(where + ": vertex index " + std::to_string(std::int64_t(c)) +
                                       " is out of range");
                // A convex polygon as a fan from its first corner.
                for (std::size_t c = 1; c + 1 < corners.size(); ++c)
                    for (double index : {corners[0], corners[c], corners[c + 1]})
                        indices.push_back(std::uint32_t(index));
                if (indices.size() > std::size_t(std::numeric_limits<std::uint32_t>::max()))
                    throw PlyError("has more face corners than 32-bit indices hold");
            }
            if (isVertex) {
                const Vec3 p(v[0], v[1], v[2]);
                if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                    throw PlyError("vertex " + std::to_string(i) + " is not finite");
                positions.push_back(p);
                if (hasNormals) normals.emplace_back(v[3], v[4], v[5]);
            }
        }
    }
    if (!sawVertices) throw PlyError("has no vertex element");
    if (!sawFaces || indices.empty()) throw PlyError("has no faces (a point cloud casts no shadow)");
    for (std::size_t i = 0; i < indices.size(); ++i)
        if (indices[i] >= positions.size())
            throw PlyError("face " + std::to_string(i / 3) + ": vertex index " + std::to_string(indices[i]) +
                           " is out of range (" + std::to_string(positions.size()) + " vertices)");
    if (base + positions.size() > std::size_t(std::numeric_limits<std::uint32_t>::max()))
        throw PlyError("has more vertices than 32-bit indices hold");
    // Normals only where every vertex of the mesh has one (as for OBJ): a mesh appended to
    // one without normals stays without.
    const bool keepNormals = hasNormals && mesh.normals.size() == base;
    if (!keepNormals) mesh.normals.clear();
    for (std::uint32_t i : indices) mesh.indices.push_back(std::uint32_t(base) + i);
    mesh.positions.insert(mesh.positions.end(), positions.begin(), positions.end());
    if (keepNormals) mesh.normals.insert(mesh.normals.end(), normals.begin(), normals.end());
}

}  // namespace shadowlab::scene
