// Reading .pvd collections and VTK XML snapshot files back (snapshot_reader.hpp). The XML is read
// by a small scanner that knows the few elements VTK files use; it stops at <AppendedData>, after
// which the file is binary.

#include "gpa/io/snapshot_reader.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <system_error>

#include <fmt/format.h>

#include "toml_include.hpp"
#include "toml_reading.hpp"

namespace gpa::io {

namespace fs = std::filesystem;

namespace {

// Messages quote names out of the file (tags, attributes): a damaged or foreign file would put
// its raw bytes on the terminal, so bytes outside printable ASCII are shown as \xNN and a long
// message is cut.
std::string printable_message(const std::string& what) {
    constexpr std::size_t most = 300;
    std::string out;
    for (const char c : what) {
        const auto u = static_cast<unsigned char>(c);
        if (u >= 0x20 && u < 0x7f) out += c;
        else out += fmt::format("\\x{:02x}", u);
        if (out.size() >= most) return out + "...";
    }
    return out;
}

[[noreturn]] void fail(const fs::path& file, const std::string& what) {
    throw SnapshotError(fmt::format("{}: {}", file.string(), printable_message(what)));
}

std::string read_whole_file(const fs::path& file, const char* kind) {
    std::error_code ec;
    if (!fs::exists(file, ec)) fail(file, fmt::format("no such file (the {} is missing)", kind));
    if (fs::is_directory(file, ec)) fail(file, fmt::format("is a folder, not a {}", kind));
    std::ifstream in(file, std::ios::binary);
    if (!in) fail(file, fmt::format("cannot be opened for reading: {}", std::strerror(errno)));
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) fail(file, "reading failed");
    return std::move(text).str();
}

// --- A scanner for the XML of VTK files ------------------------------------------------------

struct Tag {
    std::string name;
    std::map<std::string, std::string> attributes;
    bool closing = false;       // </name>
    bool self_closing = false;  // <name ... />
    std::size_t begin = 0;      // the '<'
    std::size_t end = 0;        // first byte after '>'
};

std::string decode_entities(std::string_view text) {
    std::string out;
    for (std::size_t i = 0; i < text.size(); ++i) {
        if (text[i] != '&') {
            out += text[i];
            continue;
        }
        static const std::array<std::pair<std::string_view, char>, 5> entities{
            {{"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}}};
        bool known = false;
        for (const auto& [entity, c] : entities) {
            if (text.substr(i, entity.size()) == entity) {
                out += c;
                i += entity.size() - 1;
                known = true;
                break;
            }
        }
        if (!known) out += '&';
    }
    return out;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// A VTK XML file (and a .pvd) opens with the XML declaration or its root element; anything else
// is refused as `kind` ("not a VTK XML file") before its bytes are scanned as XML.
void require_xml_start(const std::string& text, const fs::path& file, const std::string& kind) {
    std::size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;  // a UTF-8 byte order mark
    while (start < text.size() && is_space(text[start])) ++start;
    if (text.compare(start, 5, "<?xml") == 0 || text.compare(start, 8, "<VTKFile") == 0) return;
    fail(file, text.empty() ? fmt::format("the file is empty: {}", kind)
                            : fmt::format("{} (it does not start with <?xml or <VTKFile): the file is damaged or of another kind", kind));
}

class XmlScanner {
public:
    XmlScanner(const std::string& text, fs::path file) : text_(text), file_(std::move(file)) {}

    // The next tag from `at` on (declarations and comments skipped), or nullopt at the end.
    std::optional<Tag> next() {
        for (;;) {
            const std::size_t open = text_.find('<', at_);
            if (open == std::string::npos) return std::nullopt;
            if (text_.compare(open, 4, "<!--") == 0) {
                const std::size_t close = text_.find("-->", open);
                if (close == std::string::npos) fail(file_, "an XML comment is not closed (file cut short?)");
                at_ = close + 3;
                continue;
            }
            if (text_.compare(open, 2, "<?") == 0) {
                const std::size_t close = text_.find("?>", open);
                if (close == std::string::npos) fail(file_, "the XML declaration is not closed (file cut short?)");
                at_ = close + 2;
                continue;
            }
            return read_tag(open);
        }
    }
    std::size_t position() const { return at_; }

private:
    Tag read_tag(std::size_t open) {
        Tag tag;
        tag.begin = open;
        std::size_t i = open + 1;
        if (i < text_.size() && text_[i] == '/') {
            tag.closing = true;
            ++i;
        }
        const std::size_t name_start = i;
        while (i < text_.size() && !is_space(text_[i]) && text_[i] != '>' && text_[i] != '/') ++i;
        tag.name = text_.substr(name_start, i - name_start);
        if (tag.name.empty()) fail(file_, fmt::format("malformed XML at byte {}: '<' without an element name", open));
        for (;;) {
            while (i < text_.size() && is_space(text_[i])) ++i;
            if (i >= text_.size()) fail(file_, fmt::format("the XML element <{}> is not closed (file cut short?)", tag.name));
            if (text_[i] == '>') {
                ++i;
                break;
            }
            if (text_[i] == '/' && i + 1 < text_.size() && text_[i + 1] == '>') {
                tag.self_closing = true;
                i += 2;
                break;
            }
            const std::size_t key_start = i;
            while (i < text_.size() && !is_space(text_[i]) && text_[i] != '=' && text_[i] != '>') ++i;
            const std::string key = text_.substr(key_start, i - key_start);
            while (i < text_.size() && is_space(text_[i])) ++i;
            // The text ends inside the tag: a file cut short, not a malformed attribute.
            if (i >= text_.size()) fail(file_, fmt::format("the XML element <{}> is not closed (file cut short?)", tag.name));
            if (text_[i] != '=') {
                fail(file_, fmt::format("malformed XML in <{}>: attribute '{}' has no value", tag.name, key));
            }
            ++i;
            while (i < text_.size() && is_space(text_[i])) ++i;
            if (i >= text_.size()) fail(file_, fmt::format("the XML element <{}> is not closed (file cut short?)", tag.name));
            if (text_[i] != '"' && text_[i] != '\'') {
                fail(file_, fmt::format("malformed XML in <{}>: the value of '{}' is not quoted", tag.name, key));
            }
            const char quote = text_[i++];
            const std::size_t close = text_.find(quote, i);
            if (close == std::string::npos) {
                fail(file_, fmt::format("malformed XML in <{}>: the value of '{}' is not closed (file cut short?)", tag.name, key));
            }
            tag.attributes[key] = decode_entities(std::string_view(text_).substr(i, close - i));
            i = close + 1;
        }
        tag.end = i;
        at_ = i;
        return tag;
    }

    const std::string& text_;
    fs::path file_;
    std::size_t at_ = 0;
};

std::string attribute(const Tag& tag, const std::string& key, const std::string& fallback = {}) {
    const auto it = tag.attributes.find(key);
    return it == tag.attributes.end() ? fallback : it->second;
}

std::optional<std::size_t> parse_count(const std::string& text) {
    std::size_t value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
    return value;
}

std::optional<double> parse_double(const std::string& text) {
    double value = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size() || text.empty() || !std::isfinite(value)) return std::nullopt;
    return value;
}

// --- Base64 ------------------------------------------------------------------------------------

int base64_digit(char c) {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}

// Base64 text without white space, from `text`.
std::string base64_characters(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (char c : text) {
        if (!is_space(c)) out += c;
    }
    return out;
}

// Decodes `chars` (a multiple of 4, '=' padding only at the end); false on anything else.
bool decode_base64(std::string_view chars, std::vector<unsigned char>& out) {
    if (chars.size() % 4 != 0) return false;
    for (std::size_t g = 0; g < chars.size(); g += 4) {
        int d[4];
        int padding = 0;
        for (int k = 0; k < 4; ++k) {
            const char c = chars[g + k];
            if (c == '=') {
                if (g + 4 != chars.size() || k < 2) return false;
                d[k] = 0;
                ++padding;
            } else {
                if (padding > 0) return false;
                d[k] = base64_digit(c);
                if (d[k] < 0) return false;
            }
        }
        const unsigned v = (unsigned(d[0]) << 18) | (unsigned(d[1]) << 12) | (unsigned(d[2]) << 6) | unsigned(d[3]);
        out.push_back(static_cast<unsigned char>(v >> 16));
        if (padding < 2) out.push_back(static_cast<unsigned char>((v >> 8) & 0xff));
        if (padding < 1) out.push_back(static_cast<unsigned char>(v & 0xff));
    }
    return true;
}

std::size_t base64_length(std::size_t bytes) { return (bytes + 2) / 3 * 4; }

// --- Value types -------------------------------------------------------------------------------

struct ValueType {
    std::string_view name;
    std::size_t width;
    bool floating;
    bool is_signed;
};
constexpr std::array<ValueType, 10> value_types{{{"Int8", 1, false, true},
                                                 {"UInt8", 1, false, false},
                                                 {"Int16", 2, false, true},
                                                 {"UInt16", 2, false, false},
                                                 {"Int32", 4, false, true},
                                                 {"UInt32", 4, false, false},
                                                 {"Int64", 8, false, true},
                                                 {"UInt64", 8, false, false},
                                                 {"Float32", 4, true, true},
                                                 {"Float64", 8, true, true}}};

const ValueType* find_type(std::string_view name) {
    for (const auto& t : value_types) {
        if (t.name == name) return &t;
    }
    return nullptr;
}

// The value at `p` (width bytes, file byte order) as double / as int64.
template <class T>
T load(const unsigned char* p, bool swap) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (swap) std::reverse(b, b + sizeof(T));
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
}

double load_double(const ValueType& t, const unsigned char* p, bool swap) {
    switch (t.width) {
        case 1: return t.is_signed ? double(load<std::int8_t>(p, swap)) : double(load<std::uint8_t>(p, swap));
        case 2: return t.is_signed ? double(load<std::int16_t>(p, swap)) : double(load<std::uint16_t>(p, swap));
        case 4:
            if (t.floating) return double(load<float>(p, swap));
            return t.is_signed ? double(load<std::int32_t>(p, swap)) : double(load<std::uint32_t>(p, swap));
        default:
            if (t.floating) return load<double>(p, swap);
            return t.is_signed ? double(load<std::int64_t>(p, swap)) : double(load<std::uint64_t>(p, swap));
    }
}

bool host_is_big_endian() {
    const std::uint16_t one = 1;
    unsigned char first;
    std::memcpy(&first, &one, 1);
    return first == 0;
}

std::string location_phrase(DataLocation l) { return l == DataLocation::Point ? "point data" : "cell data"; }

}  // namespace

// --- The .pvd ----------------------------------------------------------------------------------

SnapshotIndex read_pvd(const fs::path& pvd) {
    const std::string text = read_whole_file(pvd, "time-series index (.pvd)");
    require_xml_start(text, pvd, "not a VTK time-series collection");
    XmlScanner xml(text, pvd);
    SnapshotIndex index{pvd, {}};
    bool collection = false;
    int last_part = -1;
    std::size_t dataset = 0;
    while (auto tag = xml.next()) {
        if (tag->closing) continue;
        if (tag->name == "VTKFile") {
            if (attribute(*tag, "type") != "Collection") {
                fail(pvd, fmt::format("not a VTK time-series collection (VTKFile type '{}', expected 'Collection')",
                                      attribute(*tag, "type")));
            }
            collection = true;
            continue;
        }
        if (tag->name != "DataSet") continue;
        ++dataset;
        if (!collection) fail(pvd, "a DataSet outside <VTKFile type=\"Collection\">");
        const std::string file = attribute(*tag, "file");
        if (file.empty()) fail(pvd, fmt::format("DataSet {} has no file attribute", dataset));
        const auto time = parse_double(attribute(*tag, "timestep"));
        if (!time) {
            fail(pvd, fmt::format("DataSet {} ({}): timestep '{}' is not a number", dataset, file, attribute(*tag, "timestep")));
        }
        const auto part = parse_count(attribute(*tag, "part", "0"));
        if (!part) fail(pvd, fmt::format("DataSet {} ({}): part '{}' is not a whole number", dataset, file, attribute(*tag, "part")));
        const fs::path path = pvd.parent_path() / file;
        const bool joins = *part > 0 && !index.snapshots.empty() && static_cast<int>(*part) > last_part &&
                           index.snapshots.back().time == *time;
        if (joins) {
            index.snapshots.back().files.push_back(path);
        } else {
            index.snapshots.push_back({*time, {path}, attribute(*tag, "name")});
        }
        last_part = static_cast<int>(*part);
    }
    if (!collection) fail(pvd, "not a VTK time-series collection (no <VTKFile type=\"Collection\"> element)");
    if (index.snapshots.empty()) fail(pvd, "the collection lists no snapshots (no DataSet elements)");
    return index;
}

fs::path find_pvd(const fs::path& target) {
    std::error_code ec;
    if (target.extension() == ".pvd" && !fs::is_directory(target, ec)) return target;
    if (!fs::exists(target, ec)) {
        fs::path partial = target;
        partial += ".partial";
        if (fs::is_directory(partial, ec)) {
            throw SnapshotError(fmt::format("{}: no such folder; {} is there (a run that is going on, failed or was "
                                            "interrupted): render that",
                                            target.string(), partial.string()));
        }
        throw SnapshotError(fmt::format("{}: no such folder (expected a run's output folder or a .pvd file)", target.string()));
    }
    if (!fs::is_directory(target, ec)) {
        throw SnapshotError(fmt::format("{}: not a folder or a .pvd file (expected a run's output folder)", target.string()));
    }
    if (fs::exists(target / "particles.pvd", ec)) return target / "particles.pvd";
    std::vector<fs::path> found;
    for (const auto& entry : fs::directory_iterator(target, ec)) {
        if (entry.path().extension() == ".pvd") found.push_back(entry.path());
    }
    if (ec) throw SnapshotError(fmt::format("{}: cannot list the folder: {}", target.string(), ec.message()));
    std::sort(found.begin(), found.end());
    if (found.empty()) {
        throw SnapshotError(fmt::format("{}: no snapshots here (no particles.pvd or other .pvd file; a run writes "
                                        "particles.pvd in its output folder)",
                                        target.string()));
    }
    if (found.size() > 1) {
        std::string names;
        for (const auto& f : found) names += (names.empty() ? "" : ", ") + f.filename().string();
        throw SnapshotError(fmt::format("{}: several .pvd files and no particles.pvd ({}): name one", target.string(), names));
    }
    return found.front();
}

// --- VTK XML files -----------------------------------------------------------------------------

struct VtkFile::ArrayRef {
    VtkArrayInfo info;
    std::string role;  // "point data", "cell data", "Points", "connectivity", "offsets", "types"
    const ValueType* type = nullptr;
    std::string format;         // "appended", "binary", "ascii"
    std::size_t offset = 0;     // appended: from the first byte after '_'
    std::size_t text_begin = 0, text_end = 0;  // inline: the element's content
};

VtkFile::~VtkFile() = default;
VtkFile::VtkFile(const VtkFile&) = default;
VtkFile::VtkFile(VtkFile&&) noexcept = default;
VtkFile& VtkFile::operator=(const VtkFile&) = default;
VtkFile& VtkFile::operator=(VtkFile&&) noexcept = default;

VtkFile::VtkFile(fs::path path) : path_(std::move(path)) {
    bytes_ = read_whole_file(path_, "snapshot file");
    parse();
}

VtkFile::VtkFile(fs::path name, std::string bytes) : path_(std::move(name)), bytes_(std::move(bytes)) { parse(); }

void VtkFile::parse() {
    require_xml_start(bytes_, path_, "not a VTK XML file");
    XmlScanner xml(bytes_, path_);
    std::vector<std::string> open;  // the elements we are inside
    bool root = false;
    int pieces = 0;
    constexpr std::size_t none = static_cast<std::size_t>(-1);
    std::size_t open_inline = none;  // the array whose inline content is being read
    while (auto tag = xml.next()) {
        if (tag->closing) {
            if (open_inline != none && tag->name == "DataArray") {
                refs_[open_inline].text_end = tag->begin;  // the content ends where this tag begins
                open_inline = none;
            }
            if (!open.empty() && open.back() == tag->name) open.pop_back();
            continue;
        }
        const std::string parent = open.empty() ? "" : open.back();
        if (tag->name == "VTKFile") {
            root = true;
            type_ = attribute(*tag, "type");
            if (type_ != "PolyData" && type_ != "UnstructuredGrid") {
                fail(path_, fmt::format("VTK file of type '{}': expected PolyData (.vtp) or UnstructuredGrid (.vtu)", type_));
            }
            const std::string order = attribute(*tag, "byte_order", "LittleEndian");
            if (order != "LittleEndian" && order != "BigEndian") fail(path_, fmt::format("unknown byte_order '{}'", order));
            big_endian_ = order == "BigEndian";
            const std::string header = attribute(*tag, "header_type", "UInt32");
            if (header != "UInt32" && header != "UInt64") {
                fail(path_, fmt::format("header_type '{}': expected UInt32 or UInt64", header));
            }
            header_bytes_ = header == "UInt64" ? 8 : 4;
            if (!attribute(*tag, "compressor").empty()) {
                fail(path_, fmt::format("compressed data ({}) is not supported: save the file uncompressed",
                                        attribute(*tag, "compressor")));
            }
        } else if (tag->name == "Piece") {
            if (++pieces > 1) fail(path_, "more than one <Piece>: only files of one piece are read");
            const auto number = [&](const char* key) -> std::size_t {
                const std::string v = attribute(*tag, key, "0");
                const auto n = parse_count(v);
                if (!n) fail(path_, fmt::format("<Piece> {} '{}' is not a whole number", key, v));
                return *n;
            };
            points_ = number("NumberOfPoints");
            if (type_ == "UnstructuredGrid") cells_ = number("NumberOfCells");
        } else if (tag->name == "DataArray") {
            ArrayRef ref;
            ref.info.name = attribute(*tag, "Name");
            if (parent == "PointData" || parent == "CellData") {
                ref.role = parent == "PointData" ? "point data" : "cell data";
                ref.info.location = parent == "PointData" ? DataLocation::Point : DataLocation::Cell;
                if (ref.info.name.empty()) fail(path_, fmt::format("an array of the {} has no Name", ref.role));
            } else if (parent == "Points") {
                ref.role = "Points";
            } else if (parent == "Cells" && type_ == "UnstructuredGrid") {
                ref.role = ref.info.name;
                ref.info.location = DataLocation::Cell;
            } else {
                ref.role = "";  // Verts, Lines, Polys, Strips, FieldData: not read, not checked
            }
            if (ref.role.empty()) {
                if (!tag->self_closing) open.push_back(tag->name);
                continue;
            }
            const std::string type = attribute(*tag, "type");
            ref.type = find_type(type);
            const std::string shown = ref.info.name.empty() ? ref.role : ref.info.name;
            if (!ref.type) fail(path_, fmt::format("array '{}' has the unknown type '{}'", shown, type));
            const std::string comps = attribute(*tag, "NumberOfComponents", "1");
            const auto c = parse_count(comps);
            if (!c || *c < 1 || *c > 64) fail(path_, fmt::format("array '{}': NumberOfComponents '{}' is not 1 to 64", shown, comps));
            ref.info.components = static_cast<int>(*c);
            ref.format = attribute(*tag, "format", "ascii");
            if (ref.format == "appended") {
                const auto off = parse_count(attribute(*tag, "offset"));
                if (!off) fail(path_, fmt::format("array '{}': offset '{}' is not a whole number", shown, attribute(*tag, "offset")));
                ref.offset = *off;
            } else if (ref.format == "binary" || ref.format == "ascii") {
                if (tag->self_closing) fail(path_, fmt::format("array '{}' ({}) has no values", shown, ref.format));
                ref.text_begin = tag->end;
                open_inline = refs_.size();
            } else {
                fail(path_, fmt::format("array '{}': unknown format '{}'", shown, ref.format));
            }
            if (ref.role == "point data" || ref.role == "cell data") {
                const bool duplicate = std::any_of(refs_.begin(), refs_.end(), [&](const ArrayRef& r) {
                    return r.role == ref.role && r.info.name == ref.info.name;
                });
                if (duplicate) fail(path_, fmt::format("two arrays named '{}' in the {}", ref.info.name, ref.role));
            }
            refs_.push_back(ref);
        } else if (tag->name == "AppendedData") {
            appended_encoding_ = attribute(*tag, "encoding", "raw");
            if (appended_encoding_ != "raw" && appended_encoding_ != "base64") {
                fail(path_, fmt::format("<AppendedData> encoding '{}': expected raw or base64", appended_encoding_));
            }
            std::size_t i = tag->end;
            while (i < bytes_.size() && is_space(bytes_[i])) ++i;
            if (i >= bytes_.size() || bytes_[i] != '_') {
                fail(path_, "<AppendedData> does not start with '_' (file cut short or not a VTK file)");
            }
            appended_start_ = i + 1;
            break;  // binary from here on
        }
        if (!tag->self_closing) open.push_back(tag->name);
    }
    if (!root) fail(path_, "not a VTK XML file (no <VTKFile> element)");
    if (pieces == 0) fail(path_, fmt::format("no <Piece> in the {}", type_));
    if (open_inline != none) fail(path_, fmt::format("array '{}' is not closed (file cut short?)", refs_[open_inline].info.name));
    const bool has_points = std::any_of(refs_.begin(), refs_.end(), [](const ArrayRef& r) { return r.role == "Points"; });
    if (points_ > 0 && !has_points) fail(path_, "no <Points> array");
    for (const auto& r : refs_) {
        if (r.format == "appended" && appended_start_ == 0) {
            fail(path_, fmt::format("array '{}' is appended but the file has no <AppendedData> (file cut short?)",
                                    r.info.name.empty() ? r.role : r.info.name));
        }
        if (r.role == "Points" && r.info.components != 3) fail(path_, "the Points array does not have 3 components");
        if (r.role == "point data" || r.role == "cell data") infos_.push_back(r.info);
    }
    // Check every block now, so that a truncated or garbled file is refused before it is drawn.
    for (const auto& r : refs_) {
        const std::size_t tuples = r.role == "point data" || r.role == "Points" ? points_
                                   : r.role == "cell data" || r.role == "offsets" || r.role == "types"
                                       ? cells_
                                       : 0;
        if (r.role == "connectivity") continue;  // its length is the last offset, checked in cells()
        if (r.format != "ascii") block(r, tuples, r.type->width);
    }
}

const VtkArrayInfo* VtkFile::find(std::string_view name, DataLocation location) const {
    for (const auto& i : infos_) {
        if (i.name == name && i.location == location) return &i;
    }
    return nullptr;
}

const VtkFile::ArrayRef& VtkFile::array(std::string_view name, DataLocation location) const {
    for (const auto& r : refs_) {
        if ((r.role == "point data" || r.role == "cell data") && r.info.name == name && r.info.location == location) return r;
    }
    fail(path_, fmt::format("no array '{}' in the {}", name, location_phrase(location)));
}

// The bytes of a binary (appended or inline base64) array: tuples x components x width of them,
// after the block's length header, which must say exactly that many.
std::vector<unsigned char> VtkFile::block(const ArrayRef& a, std::size_t tuples, std::size_t width) const {
    const std::string shown = a.info.name.empty() ? a.role : a.info.name;
    const std::size_t per_tuple = static_cast<std::size_t>(a.info.components) * width;
    const bool known_size = tuples > 0 || a.role != "connectivity";
    const auto header_value = [&](const unsigned char* p) -> std::uint64_t {
        return header_bytes_ == 8 ? load<std::uint64_t>(p, big_endian_ != host_is_big_endian())
                                  : load<std::uint32_t>(p, big_endian_ != host_is_big_endian());
    };
    const auto check_length = [&](std::uint64_t bytes) {
        if (known_size && bytes != static_cast<std::uint64_t>(tuples) * per_tuple) {
            fail(path_, fmt::format("array '{}' holds {} bytes, expected {} ({} x {} components of {} bytes)", shown, bytes,
                                    static_cast<std::uint64_t>(tuples) * per_tuple, tuples, a.info.components, width));
        }
        if (bytes % per_tuple != 0) fail(path_, fmt::format("array '{}' holds {} bytes, not whole values", shown, bytes));
    };
    std::vector<unsigned char> out;
    if (a.format == "appended" && appended_encoding_ == "raw") {
        const std::size_t at = appended_start_ + a.offset;
        if (at + header_bytes_ > bytes_.size() || at < appended_start_) {
            fail(path_, fmt::format("array '{}' at offset {} starts past the end of the appended data (file cut short?)", shown,
                                    a.offset));
        }
        const std::uint64_t bytes = header_value(reinterpret_cast<const unsigned char*>(bytes_.data() + at));
        if (bytes > bytes_.size() - at - header_bytes_) {
            fail(path_, fmt::format("array '{}' at offset {} runs past the end of the file ({} bytes declared; file cut short?)",
                                    shown, a.offset, bytes));
        }
        check_length(bytes);
        const auto* p = reinterpret_cast<const unsigned char*>(bytes_.data() + at + header_bytes_);
        out.assign(p, p + bytes);
        return out;
    }
    // Base64: appended (from the offset to the next array's or the end) or inline content. VTK
    // encodes the length header on its own and then the data, so the header's characters end in
    // padding; a writer that encodes both in one stream is read as well.
    std::string chars;
    if (a.format == "appended") {
        if (appended_start_ + a.offset > bytes_.size()) {
            fail(path_, fmt::format("array '{}' at offset {} starts past the end of the appended data", shown, a.offset));
        }
        std::size_t end = bytes_.find('<', appended_start_ + a.offset);
        if (end == std::string::npos) end = bytes_.size();
        chars = base64_characters(std::string_view(bytes_).substr(appended_start_ + a.offset, end - appended_start_ - a.offset));
    } else {
        chars = base64_characters(std::string_view(bytes_).substr(a.text_begin, a.text_end - a.text_begin));
    }
    const std::size_t header_chars = base64_length(header_bytes_);
    std::vector<unsigned char> header;
    if (chars.size() < header_chars || !decode_base64(std::string_view(chars).substr(0, header_chars), header)) {
        fail(path_, fmt::format("array '{}': its base64 length header is malformed", shown));
    }
    const bool separate = chars[header_chars - 1] == '=';
    if (separate) {
        const std::uint64_t bytes = header_value(header.data());
        if (bytes > chars.size()) fail(path_, fmt::format("array '{}' declares {} bytes, more than the file holds", shown, bytes));
        check_length(bytes);
        const std::size_t data_chars = base64_length(static_cast<std::size_t>(bytes));
        if (chars.size() < header_chars + data_chars ||
            !decode_base64(std::string_view(chars).substr(header_chars, data_chars), out) || out.size() != bytes) {
            fail(path_, fmt::format("array '{}': its base64 data is malformed or cut short", shown));
        }
        return out;
    }
    std::vector<unsigned char> first;
    if (!decode_base64(std::string_view(chars).substr(0, base64_length(header_bytes_ + 1)), first) ||
        first.size() < header_bytes_) {
        fail(path_, fmt::format("array '{}': its base64 length header is malformed", shown));
    }
    const std::uint64_t bytes = header_value(first.data());
    if (bytes > chars.size()) fail(path_, fmt::format("array '{}' declares {} bytes, more than the file holds", shown, bytes));
    check_length(bytes);
    std::vector<unsigned char> all;
    const std::size_t total_chars = base64_length(header_bytes_ + static_cast<std::size_t>(bytes));
    if (chars.size() < total_chars || !decode_base64(std::string_view(chars).substr(0, total_chars), all) ||
        all.size() != header_bytes_ + bytes) {
        fail(path_, fmt::format("array '{}': its base64 data is malformed or cut short", shown));
    }
    out.assign(all.begin() + static_cast<std::ptrdiff_t>(header_bytes_), all.end());
    return out;
}

std::vector<double> VtkFile::decode(const ArrayRef& a, std::size_t tuples) const {
    const std::string shown = a.info.name.empty() ? a.role : a.info.name;
    const std::size_t count = tuples * static_cast<std::size_t>(a.info.components);
    std::vector<double> out;
    if (a.format == "ascii") {
        std::istringstream in(bytes_.substr(a.text_begin, a.text_end - a.text_begin));
        std::string word;
        while (in >> word) {
            double v = 0.0;
            const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
            if (ec == std::errc::result_out_of_range) {
                v = std::strtod(word.c_str(), nullptr);
            } else if (ec != std::errc() || end != word.data() + word.size()) {
                if (word == "nan" || word == "-nan") {
                    v = std::nan("");
                } else {
                    fail(path_, fmt::format("array '{}': '{}' is not a number", shown, word.substr(0, 40)));
                }
            }
            out.push_back(v);
        }
        if (tuples == 0 && a.role == "connectivity") return out;
        if (out.size() != count) fail(path_, fmt::format("array '{}' has {} values, expected {}", shown, out.size(), count));
        return out;
    }
    const auto bytes = block(a, tuples, a.type->width);
    const bool swap = big_endian_ != host_is_big_endian();
    out.resize(bytes.size() / a.type->width);
    for (std::size_t k = 0; k < out.size(); ++k) out[k] = load_double(*a.type, bytes.data() + k * a.type->width, swap);
    return out;
}

std::vector<std::int64_t> VtkFile::decode_integers(const ArrayRef& a, std::size_t tuples) const {
    if (a.type->floating) fail(path_, fmt::format("the cells' '{}' array is of type {}, not an integer type", a.role, a.type->name));
    const auto values = decode(a, tuples);
    std::vector<std::int64_t> out(values.size());
    for (std::size_t k = 0; k < values.size(); ++k) out[k] = static_cast<std::int64_t>(values[k]);
    return out;
}

std::vector<double> VtkFile::values(std::string_view name, DataLocation location) const {
    const ArrayRef& a = array(name, location);
    return decode(a, location == DataLocation::Point ? points_ : cells_);
}

std::vector<double> VtkFile::points() const {
    for (const auto& r : refs_) {
        if (r.role == "Points") return decode(r, points_);
    }
    return {};
}

VtkCells VtkFile::cells() const {
    VtkCells c;
    if (type_ != "UnstructuredGrid" || cells_ == 0) return c;
    const ArrayRef *connectivity = nullptr, *offsets = nullptr, *types = nullptr;
    for (const auto& r : refs_) {
        if (r.role == "connectivity") connectivity = &r;
        if (r.role == "offsets") offsets = &r;
        if (r.role == "types") types = &r;
    }
    if (!connectivity || !offsets || !types) fail(path_, "<Cells> lacks its connectivity, offsets or types array");
    c.offsets = decode_integers(*offsets, cells_);
    const auto type_values = decode(*types, cells_);
    c.types.resize(type_values.size());
    for (std::size_t k = 0; k < type_values.size(); ++k) c.types[k] = static_cast<std::uint8_t>(type_values[k]);
    std::int64_t previous = 0;
    for (std::size_t k = 0; k < c.offsets.size(); ++k) {
        if (c.offsets[k] < previous) fail(path_, fmt::format("cell {}: its offset {} is below the one before it", k, c.offsets[k]));
        previous = c.offsets[k];
    }
    c.connectivity = decode_integers(*connectivity, 0);
    if (static_cast<std::size_t>(previous) != c.connectivity.size()) {
        fail(path_, fmt::format("the cells' connectivity has {} entries, the offsets end at {}", c.connectivity.size(), previous));
    }
    for (std::size_t k = 0; k < c.connectivity.size(); ++k) {
        if (c.connectivity[k] < 0 || static_cast<std::size_t>(c.connectivity[k]) >= points_) {
            fail(path_, fmt::format("connectivity entry {} names point {}, outside 0 to {}", k, c.connectivity[k], points_ - 1));
        }
    }
    return c;
}

// --- The geometry of a run ---------------------------------------------------------------------

namespace {

std::optional<GeometryKind> geometry_named(std::string_view text) {
    if (text == "axisymmetric") return GeometryKind::Axisymmetric;
    if (text == "plane-strain" || text == "plane strain") return GeometryKind::PlaneStrain;
    if (text == "3d" || text == "3D") return GeometryKind::ThreeD;
    return std::nullopt;
}

}  // namespace

std::optional<RunGeometry> read_run_geometry(const fs::path& folder) {
    std::error_code ec;
    const fs::path scene = folder / "scene.toml";
    if (fs::is_regular_file(scene, ec)) {
        std::string name;
        try {
            const toml::table table = detail::read_guarded_toml(scene);
            if (const auto* g = table.get_as<std::string>("geometry")) name = g->get();
        } catch (const InputError& e) {
            throw SnapshotError(fmt::format("{}; give the geometry with --geometry", e.what()));  // e names the file
        }
        if (const auto g = geometry_named(name)) return RunGeometry{*g, "scene.toml"};
        fail(scene, fmt::format("geometry '{}' is none of axisymmetric, plane-strain, 3d", name));
    }
    const fs::path summary = folder / "summary.json";
    if (fs::is_regular_file(summary, ec)) {
        std::ifstream in(summary);
        std::ostringstream text;
        text << in.rdbuf();
        const std::string s = std::move(text).str();
        static const std::regex key(R"re("geometry"\s*:\s*"([^"]*)")re");
        std::smatch m;
        if (std::regex_search(s, m, key)) {
            if (const auto g = geometry_named(m[1].str())) return RunGeometry{*g, "summary.json"};
        }
    }
    return std::nullopt;
}

}  // namespace gpa::io
