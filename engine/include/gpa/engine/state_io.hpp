#pragma once
// The binary encoding of checkpoints (Simulation::save_checkpoint): values and arrays as their
// bytes in this machine's order, each array after its length, sections marked by four-letter
// tags, and a running FNV-1a checksum of everything written. The reader checks every length
// against the bytes left in the file before it allocates, every tag, and the checksum, so that
// a damaged or foreign file is refused with a message and never read past its end.

#include <cstddef>
#include <cstdint>
#include <istream>
#include <ostream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "gpa/engine/errors.hpp"

namespace gpa {

// A checkpoint that cannot be used: damaged, of another format version, written by another
// build or for another scene. what() is one line naming the file and the mismatch.
class CheckpointError : public InputError {
public:
    using InputError::InputError;
};

// 64-bit FNV-1a, fed in pieces.
class Checksum {
public:
    void add(const void* data, std::size_t bytes) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < bytes; ++i) value_ = (value_ ^ p[i]) * 0x100000001b3ull;
    }
    std::uint64_t value() const { return value_; }

private:
    std::uint64_t value_ = 0xcbf29ce484222325ull;
};

class StateWriter {
public:
    explicit StateWriter(std::ostream& out) : out_(out) {}

    // Where each value, array, text, tag and field begins (bytes from the first one written), for
    // a test that compares two checkpoints field by field; not recorded unless asked for.
    void record_field_starts(std::vector<std::uint64_t>* starts) { starts_ = starts; }

    void bytes(const void* data, std::size_t count) {
        checksum_.add(data, count);
        out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(count));
        written_ += count;
    }
    template <class T>
    void value(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        const FieldStart start(*this);
        bytes(&v, sizeof v);
    }
    template <class T>
    void array(const std::vector<T>& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        const FieldStart start(*this);
        value<std::uint64_t>(v.size());
        bytes(v.data(), v.size() * sizeof(T));
    }
    void text(std::string_view s) {
        const FieldStart start(*this);
        value<std::uint64_t>(s.size());
        bytes(s.data(), s.size());
    }
    // A section mark: four letters.
    void tag(std::string_view name) {
        const FieldStart start(*this);
        bytes(name.data(), 4);
    }

    // The calls below are StateReader's too, so that a part lists its state once for both
    // directions: template <class IO, class Self> void fields(IO& io, Self& s) { io.field(s.x); },
    // Self const when writing. `reading` tells a list's read-only checks apart (if constexpr).
    static constexpr bool reading = false;
    void field(double v) { value(v); }
    void field(std::size_t v) { value<std::uint64_t>(v); }
    void field(std::uint32_t v) { value(v); }
    void field(std::int32_t v) { value(v); }
    void field(bool v) { value<std::uint8_t>(v ? 1 : 0); }
    void field(const std::string& s) { text(s); }
    // An array, its length first (StateReader: at most `max_count` elements).
    template <class T>
    void field(const std::vector<T>& v, std::uint64_t /*max_count*/ = UINT64_MAX) {
        array(v);
    }
    // A sequence's length, ahead of its elements (StateReader::sequence checks it).
    template <class Vector>
    void sequence(const Vector& v, std::size_t /*expected*/, std::string_view /*what*/) {
        value<std::uint64_t>(v.size());
    }
    // A count that the reader must find equal to its own (StateReader::expect).
    void expect(std::size_t count, std::string_view /*what*/) { value<std::uint64_t>(count); }

    std::uint64_t checksum() const { return checksum_.value(); }
    bool good() const { return static_cast<bool>(out_); }

private:
    // Records the start of the outermost call only (an array's length is not a field of its own).
    class FieldStart {
    public:
        explicit FieldStart(StateWriter& w) : w_(w) {
            if (w_.depth_++ == 0 && w_.starts_) w_.starts_->push_back(w_.written_);
        }
        ~FieldStart() { --w_.depth_; }
        FieldStart(const FieldStart&) = delete;
        FieldStart& operator=(const FieldStart&) = delete;

    private:
        StateWriter& w_;
    };

    std::ostream& out_;
    Checksum checksum_;
    std::uint64_t written_ = 0;
    std::vector<std::uint64_t>* starts_ = nullptr;
    int depth_ = 0;
};

class StateReader {
public:
    // `size`: the bytes that may be read from `in`; `source` names the file in messages.
    StateReader(std::istream& in, std::uint64_t size, std::string source)
        : in_(in), left_(size), source_(std::move(source)) {}

    void bytes(void* data, std::size_t count) {
        if (count > left_) fail("it ends early (a damaged or truncated checkpoint)");
        in_.read(static_cast<char*>(data), static_cast<std::streamsize>(count));
        if (!in_) fail("reading it failed");
        left_ -= count;
        checksum_.add(data, count);
    }
    template <class T>
    T value() {
        static_assert(std::is_trivially_copyable_v<T>);
        T v;
        bytes(&v, sizeof v);
        return v;
    }
    // Reads an array; its length must fit in what is left of the file (and at most `max_count`).
    template <class T>
    void array(std::vector<T>& v, std::uint64_t max_count = UINT64_MAX) {
        static_assert(std::is_trivially_copyable_v<T>);
        const auto n = value<std::uint64_t>();
        if (n > max_count || n > left_ / sizeof(T)) fail("an array is longer than the file (a damaged checkpoint)");
        v.resize(static_cast<std::size_t>(n));
        bytes(v.data(), v.size() * sizeof(T));
    }
    template <class T>
    std::vector<T> array() {
        std::vector<T> v;
        array(v);
        return v;
    }
    std::string text() {
        const auto n = value<std::uint64_t>();
        if (n > left_) fail("a text is longer than the file (a damaged checkpoint)");
        std::string s(static_cast<std::size_t>(n), '\0');
        bytes(s.data(), s.size());
        return s;
    }
    void tag(std::string_view name) {
        char got[4];
        bytes(got, 4);
        if (std::string_view(got, 4) != name.substr(0, 4)) {
            fail("section \"" + std::string(name) + "\" is missing (a damaged checkpoint, or one of another format)");
        }
    }

    // The fields StateWriter::field wrote, read into place.
    static constexpr bool reading = true;
    void field(double& v) { v = value<double>(); }
    void field(std::size_t& v) { v = static_cast<std::size_t>(value<std::uint64_t>()); }
    void field(std::uint32_t& v) { v = value<std::uint32_t>(); }
    void field(std::int32_t& v) { v = value<std::int32_t>(); }
    void field(bool& v) { v = value<std::uint8_t>() != 0; }
    void field(std::string& s) { s = text(); }
    template <class T>
    void field(std::vector<T>& v, std::uint64_t max_count = UINT64_MAX) {
        array(v, max_count);
    }
    // The count StateWriter::expect wrote: it must be `count`, else the checkpoint is refused
    // naming `what` ("its planes are not the scene's").
    void expect(std::size_t count, std::string_view what) {
        if (value<std::uint64_t>() != count) fail(std::string(what));
    }
    // A sequence's length: it must be `expected` (the scene's count), else the checkpoint is
    // refused naming `what` ("its planes are not the scene's"); the sequence is resized to it.
    template <class Vector>
    void sequence(Vector& v, std::size_t expected, std::string_view what) {
        if (value<std::uint64_t>() != expected) fail(std::string(what));
        v.resize(expected);
    }

    [[noreturn]] void fail(const std::string& what) const { throw CheckpointError("checkpoint " + source_ + ": " + what); }
    std::uint64_t left() const { return left_; }
    std::uint64_t checksum() const { return checksum_.value(); }
    const std::string& source() const { return source_; }

private:
    std::istream& in_;
    std::uint64_t left_;
    std::string source_;
    Checksum checksum_;
};

// Compressed rows: write_rows stores them; read_rows reads `rows_expected` rows (SIZE_MAX: any
// number) whose entries must all be below `index_limit`, or fails.
struct CompressedRows;
void write_rows(StateWriter& out, const CompressedRows& rows);
void read_rows(StateReader& in, CompressedRows& rows, std::size_t rows_expected, std::size_t index_limit);
// Both directions, for a part's one list of fields.
inline void rows_field(StateWriter& out, const CompressedRows& rows, std::size_t /*rows_expected*/, std::size_t /*index_limit*/) {
    write_rows(out, rows);
}
inline void rows_field(StateReader& in, CompressedRows& rows, std::size_t rows_expected, std::size_t index_limit) {
    read_rows(in, rows, rows_expected, index_limit);
}

}  // namespace gpa
