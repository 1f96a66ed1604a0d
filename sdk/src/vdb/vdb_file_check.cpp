// The walk over an OpenVDB file (vdb_file_check.hpp). It follows OpenVDB
// 10's readers (io::File::open and readGridDescriptors, MetaMap::readMeta,
// DelayedLoadMetadata::readValue, Transform::read and the maps' read,
// RootNode/InternalNode/LeafNode readTopology and readBuffers,
// io::readCompressedValues) field by field, reading only fixed-size fields
// and skipping every run whose length it has checked against the bytes left.
// What OpenVDB would accept but never writes (a format older than 222, no
// grid offsets, instanced grids, unsorted or unaligned root entries, a tile
// that is also a child) is refused rather than followed.
#include "vdb_file_check.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <utility>

namespace splatfx::vdbfile {
namespace {

struct Bad {
    std::string what;
};

// Reads little-endian fixed-size fields; every length is checked against
// the end of the current section before anything is read or skipped.
class Reader {
public:
    Reader(std::istream& in, std::uint64_t size) : in_(in), size_(size), end_(size) {}

    std::uint64_t pos() const { return pos_; }
    std::uint64_t left() const { return end_ - pos_; }
    std::uint64_t size() const { return size_; }
    void limit(std::uint64_t end) { end_ = std::min(end, size_); }
    void seek(std::uint64_t to) {
        if (to > end_) fail("a position " + std::to_string(to) + " past the end (" + std::to_string(end_) + ")");
        pos_ = to;
        in_.seekg(std::streamoff(to));
    }
    [[noreturn]] void fail(const std::string& what) const { throw Bad{what + " at byte " + std::to_string(pos_)}; }

    void need(std::uint64_t n, const std::string& what) const {
        if (n > left())
            fail(what + " needs " + std::to_string(n) + " bytes, but only " + std::to_string(left()) + " are left" +
                 (end_ < size_ ? " in its section" : " in the file"));
    }
    void bytes(void* out, std::uint64_t n, const std::string& what) {
        need(n, what);
        in_.read(static_cast<char*>(out), std::streamsize(n));
        if (!in_) fail(what + ": the file could not be read");
        pos_ += n;
    }
    template <class T>
    T get(const std::string& what) {
        T v{};
        bytes(&v, sizeof v, what);
        return v;
    }
    void skip(std::uint64_t n, const std::string& what) {
        need(n, what);
        pos_ += n;
        in_.seekg(std::streamoff(pos_));
    }
    // OpenVDB's readString: a 32-bit length, then the bytes.
    std::string string(const std::string& what, std::uint64_t maxLength) {
        const std::uint32_t n = get<std::uint32_t>(what + "'s length");
        if (n > maxLength) fail(what + " claims " + std::to_string(n) + " bytes, more than the " + std::to_string(maxLength) + " a name may have");
        std::string s(n, '\0');
        bytes(s.data(), n, what);
        return s;
    }

private:
    std::istream& in_;
    std::uint64_t size_, end_, pos_ = 0;
};

constexpr std::uint32_t kOldestFormat = openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION; // 222: per-grid compression
constexpr std::uint64_t kMaxName = 4096;                                                     // names of grids, metadata, types and maps
constexpr std::uint32_t kZip = 0x1, kActiveMask = 0x2, kBlosc = 0x4;

// Metadata entries with a known layout (DelayedLoadMetadata's) check their
// element count against this many bytes per element in their section.
constexpr std::uint64_t kBytesPerLeafAtLeast = 64; // a leaf's value mask in the topology

// A Blosc chunk's header states its uncompressed and compressed sizes, and
// Blosc's decompressor reads as much as the header says. `padded`: OpenVDB's
// stream compression pads inputs under 128 bytes to 128.
void checkBlosc(Reader& r, std::uint64_t chunkBytes, std::uint64_t wantBytes, const std::string& what, bool padded = false) {
    if (chunkBytes < 16) r.fail(what + ": a Blosc chunk of " + std::to_string(chunkBytes) + " bytes, shorter than its 16-byte header");
    unsigned char h[16];
    r.bytes(h, 16, what);
    auto u32 = [&](int at) {
        return std::uint32_t(h[at]) | std::uint32_t(h[at + 1]) << 8 | std::uint32_t(h[at + 2]) << 16 | std::uint32_t(h[at + 3]) << 24;
    };
    const std::uint32_t nbytes = u32(4), cbytes = u32(12);
    if (nbytes != wantBytes && !(padded && nbytes == 128 && wantBytes <= 128))
        r.fail(what + ": a Blosc chunk that expands to " + std::to_string(nbytes) + " bytes where " + std::to_string(wantBytes) + " belong");
    if (cbytes > chunkBytes || cbytes < 16)
        r.fail(what + ": a Blosc chunk whose header claims " + std::to_string(cbytes) + " bytes in a chunk of " + std::to_string(chunkBytes));
    r.skip(chunkBytes - 16, what);
}

// DelayedLoadMetadata::readValue: per-leaf masks and compressed sizes, each
// stored raw or as a Blosc chunk. `maxCount` bounds the leaves its grid can hold.
void walkDelayedLoad(Reader& r, std::uint32_t numBytes, std::uint64_t maxCount, const std::string& what) {
    if (numBytes == 0) return;
    const std::uint64_t start = r.pos();
    const std::uint32_t count = r.get<std::uint32_t>(what);
    if (count > maxCount)
        r.fail(what + " claims " + std::to_string(count) + " leaves; its grid's " + std::to_string(maxCount * kBytesPerLeafAtLeast) +
               " bytes hold at most " + std::to_string(maxCount));
    for (int part = 0; part < 2; ++part) {
        const std::uint64_t elem = part == 0 ? 1 : 8; // int8 masks, int64 sizes
        const std::uint32_t bytes = r.get<std::uint32_t>(what);
        if (part == 1 && bytes == std::numeric_limits<std::uint32_t>::max()) break; // no sizes stored
        if (bytes > 0) checkBlosc(r, bytes, count * elem, what, true);
        else r.skip(count * elem, what);
    }
    const std::uint64_t used = r.pos() - start;
    if (used < numBytes) r.skip(numBytes - used, what); // OpenVDB skips a newer version's extra bytes
}

// MetaMap::readMeta. `sectionBytes`: the bytes of the file or grid it belongs to.
// A grid's tree is read with half floats when its metadata says so: Archive::readGrid takes
// GridBase::saveFloatAsHalf() (the entry "is_saved_as_half_float" as OpenVDB's asBool reads it,
// false without it) after MetaMap::readMeta, whatever the type name's "_HalfFloat" suffix says.
// savedAsHalf (when given) receives that value.
void walkMetaMap(Reader& r, const std::string& owner, std::uint64_t sectionBytes, bool* savedAsHalf = nullptr) {
    if (savedAsHalf) *savedAsHalf = false;
    const std::uint32_t count = r.get<std::uint32_t>(owner + "'s metadata count");
    if (count > r.left() / 12) // a name, a type name and a size: 12 bytes at least
        r.fail(owner + "'s metadata claims " + std::to_string(count) + " entries, more than its " + std::to_string(r.left()) +
               " bytes left can hold");
    for (std::uint32_t i = 0; i < count; ++i) {
        const std::string name = r.string(owner + "'s metadata name", kMaxName);
        const std::string what = owner + "'s metadata '" + name + "'";
        const std::string type = r.string(what + "'s type", kMaxName);
        const std::uint32_t numBytes = r.get<std::uint32_t>(what + "'s size");
        if (!openvdb::Metadata::isRegisteredType(type)) {
            r.skip(numBytes, what); // UnknownMetadata: raw bytes
        } else if (savedAsHalf && name == openvdb::GridBase::META_SAVE_HALF_FLOAT &&
                   type != openvdb::io::DelayedLoadMetadata::staticTypeName()) {
            // Read as OpenVDB reads it (its size checked against the bytes left first), so the flag
            // the tree is walked with is the one its reader will use.
            r.need(numBytes, what);
            std::string raw(sizeof numBytes, '\0');
            std::memcpy(raw.data(), &numBytes, sizeof numBytes);
            raw.resize(sizeof numBytes + numBytes);
            r.bytes(raw.data() + sizeof numBytes, numBytes, what);
            openvdb::Metadata::Ptr meta = openvdb::Metadata::createMetadata(type);
            std::istringstream in(raw);
            try {
                meta->read(in);
            } catch (const std::exception& e) {
                r.fail(what + " cannot be read: " + e.what());
            }
            if (!in || in.tellg() != std::streampos(std::streamoff(raw.size())))
                r.fail(what + " of type " + type + " states " + std::to_string(numBytes) + " bytes; the type holds " + std::to_string(meta->size()));
            *savedAsHalf = meta->asBool();
        } else if (type == openvdb::io::DelayedLoadMetadata::staticTypeName()) {
            walkDelayedLoad(r, numBytes, sectionBytes / kBytesPerLeafAtLeast, what);
        } else if (type == openvdb::StringMetadata::staticTypeName()) {
            r.skip(numBytes, what);
        } else {
            // TypedMetadata reads its type's size whatever the file says: the two must agree.
            const std::uint32_t size = openvdb::Metadata::createMetadata(type)->size();
            if (numBytes != size)
                r.fail(what + " of type " + type + " states " + std::to_string(numBytes) + " bytes; the type holds " + std::to_string(size));
            r.skip(size, what);
        }
    }
}

// Transform::read (format >= 219): the map's type name, then its fields.
void walkMap(Reader& r, const std::string& owner, int depth) {
    const std::string type = r.string(owner + "'s transform type", kMaxName);
    static const std::map<std::string, std::uint64_t> kFixed = {{"AffineMap", 128},
                                                                {"UnitaryMap", 128},
                                                                {"ScaleMap", 120},
                                                                {"UniformScaleMap", 120},
                                                                {"TranslationMap", 24},
                                                                {"ScaleTranslateMap", 144},
                                                                {"UniformScaleTranslateMap", 144}};
    if (auto it = kFixed.find(type); it != kFixed.end()) return r.skip(it->second, owner + "'s transform");
    if (type == "NonlinearFrustumMap" && depth == 0) {
        r.skip(48 + 16, owner + "'s frustum"); // box, taper, depth
        return walkMap(r, owner, 1);
    }
    r.fail(owner + " has a transform of unknown type '" + type + "'");
}

using Mask = std::vector<std::uint64_t>;

std::uint64_t countOn(const Mask& m) {
    std::uint64_t n = 0;
    for (std::uint64_t w : m) n += std::uint64_t(std::popcount(w));
    return n;
}

Mask loadMask(Reader& r, std::size_t words, const std::string& what) {
    Mask m(words);
    r.bytes(m.data(), words * 8, what);
    return m;
}

// The tree of one float or vec3s grid: topology, then (optionally) buffers.
struct TreeWalk {
    Reader& r;
    std::string owner;
    std::uint32_t compression = 0;
    bool half = false;
    std::uint64_t valueBytes = 4, halfBytes = 2;
    std::uint64_t leafBytes = 0, internal4Bytes = 0, internal5Bytes = 0;
    GridLayout& out;
    std::vector<std::uint16_t> leafOn; // active voxels per leaf, in the order OpenVDB reads their buffers

    // Saturating: a terabyte of root tiles would overflow 64 bits.
    static void add(std::uint64_t& to, std::uint64_t n) {
        to = n > std::numeric_limits<std::uint64_t>::max() - to ? std::numeric_limits<std::uint64_t>::max() : to + n;
    }
    void addVoxels(std::uint64_t n, const openvdb::CoordBBox& box, bool tile) {
        add(out.activeVoxels, n);
        if (tile) add(out.tileVoxels, n);
        out.activeBox.expand(box);
    }
    void addBytes(std::uint64_t n) { add(out.treeBytes, n); }

    // io::readCompressedValues, for a node of `count` values and this value mask.
    void values(std::uint64_t count, const Mask& valueMask, const std::string& what) {
        const std::uint8_t meta = r.get<std::uint8_t>(what + "'s compression flag");
        if (meta > 6) r.fail(what + " has compression flag " + std::to_string(meta) + "; OpenVDB writes 0 to 6");
        if (meta == 2 || meta == 4 || meta == 5) r.skip(valueBytes * (meta == 5 ? 2 : 1), what + "'s inactive values");
        if (meta == 3 || meta == 4 || meta == 5) r.skip(valueMask.size() * 8, what + "'s selection mask");
        const std::uint64_t n = (compression & kActiveMask) && meta != 6 ? countOn(valueMask) : count;
        if (half && n == 0) return;
        const std::uint64_t bytes = n * (half ? halfBytes : valueBytes);
        if (compression & (kBlosc | kZip)) {
            const std::int64_t stated = r.get<std::int64_t>(what + "'s chunk size");
            if (stated <= 0) {
                if (stated == std::numeric_limits<std::int64_t>::min() || std::uint64_t(-stated) != bytes)
                    r.fail(what + " holds an uncompressed chunk of " + std::to_string(stated) + " (minus) bytes where " + std::to_string(bytes) +
                           " belong");
                r.skip(bytes, what);
            } else if (std::uint64_t(stated) > r.left()) {
                r.fail(what + " claims a compressed chunk of " + std::to_string(stated) + " bytes; only " + std::to_string(r.left()) + " are left");
            } else if (compression & kBlosc) {
                checkBlosc(r, std::uint64_t(stated), bytes, what);
            } else {
                r.skip(std::uint64_t(stated), what);
            }
        } else {
            r.skip(bytes, what);
        }
    }

    void leaf(const openvdb::Coord& origin) {
        const Mask m = loadMask(r, 8, owner + "'s leaf mask");
        addBytes(leafBytes);
        const std::uint64_t on = countOn(m);
        leafOn.push_back(std::uint16_t(on));
        if (on == 0) return;
        openvdb::CoordBBox box;
        for (int w = 0; w < 8; ++w)
            for (std::uint64_t bits = m[std::size_t(w)]; bits; bits &= bits - 1) {
                const int n = w * 64 + std::countr_zero(bits);
                box.expand(origin + openvdb::Coord(n >> 6, (n >> 3) & 7, n & 7));
            }
        addVoxels(on, box, false);
    }

    // InternalNode::readTopology: child mask, value mask, the tile values, then the children.
    // level 2: 32^3 entries of 128^3 voxels; level 1: 16^3 entries of 8^3 voxels.
    void internal(int level, const openvdb::Coord& origin) {
        const int log2 = level == 2 ? 5 : 4, childLog2 = level == 2 ? 7 : 3;
        const std::size_t words = (std::size_t(1) << (3 * log2)) / 64;
        const std::string what = owner + "'s level-" + std::to_string(level) + " node at (" + std::to_string(origin.x()) + ", " +
                                 std::to_string(origin.y()) + ", " + std::to_string(origin.z()) + ")";
        const Mask child = loadMask(r, words, what + "'s child mask");
        const Mask value = loadMask(r, words, what + "'s value mask");
        addBytes(level == 2 ? internal5Bytes : internal4Bytes);
        for (std::size_t w = 0; w < words; ++w)
            if (child[w] & value[w]) r.fail(what + " has entries that are both a child and an active tile");
        values(std::uint64_t(words) * 64, value, what + "'s tile values");
        auto at = [&](int n) {
            const int m = (1 << log2) - 1;
            return origin + openvdb::Coord((n >> (2 * log2)) << childLog2, ((n >> log2) & m) << childLog2, (n & m) << childLog2);
        };
        const std::uint64_t tileVoxels = std::uint64_t(1) << (3 * childLog2);
        for (std::size_t w = 0; w < words; ++w)
            for (std::uint64_t bits = value[w]; bits; bits &= bits - 1) {
                const openvdb::Coord o = at(int(w * 64) + std::countr_zero(bits));
                addVoxels(tileVoxels, openvdb::CoordBBox(o, o.offsetBy((1 << childLog2) - 1)), true);
            }
        for (std::size_t w = 0; w < words; ++w)
            for (std::uint64_t bits = child[w]; bits; bits &= bits - 1) {
                const openvdb::Coord o = at(int(w * 64) + std::countr_zero(bits));
                if (level == 2) internal(1, o);
                else leaf(o);
            }
    }

    openvdb::Coord rootOrigin(const std::string& what) {
        std::int32_t v[3];
        r.bytes(v, sizeof v, what);
        for (std::int32_t c : v)
            // Aligned to the root's 4096-voxel entries, and far enough from the ends of int32
            // that every box and lattice computed from it stays in range.
            if (c % 4096 != 0 || c < -(1 << 29) || c > (1 << 29))
                r.fail(what + " at (" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) +
                       ") is not a multiple of 4096 within +-2^29");
        return openvdb::Coord(v[0], v[1], v[2]);
    }

    // TreeBase::readTopology, then RootNode::readTopology (format >= 213).
    void topology() {
        r.skip(4, owner + "'s buffer count");
        r.skip(valueBytes, owner + "'s background");
        const std::uint32_t numTiles = r.get<std::uint32_t>(owner + "'s root tile count");
        const std::uint32_t numChildren = r.get<std::uint32_t>(owner + "'s root child count");
        if (numTiles > r.left() / (13 + valueBytes))
            r.fail(owner + "'s root claims " + std::to_string(numTiles) + " tiles, more than its " + std::to_string(r.left()) +
                   " bytes left can hold");
        if (numChildren > r.left() / (12 + 2 * 4096))
            r.fail(owner + "'s root claims " + std::to_string(numChildren) + " children, more than its " + std::to_string(r.left()) +
                   " bytes left can hold");
        std::set<openvdb::Coord> seen;
        for (std::uint32_t i = 0; i < numTiles; ++i) {
            const openvdb::Coord o = rootOrigin(owner + "'s root tile");
            r.skip(valueBytes, owner + "'s root tile value");
            const std::uint8_t active = r.get<std::uint8_t>(owner + "'s root tile state");
            if (active > 1) r.fail(owner + "'s root tile has state " + std::to_string(active) + "; expected 0 or 1");
            if (!seen.insert(o).second) r.fail(owner + "'s root has two entries at one place");
            addBytes(64);
            if (active) addVoxels(std::uint64_t(1) << 36, openvdb::CoordBBox(o, o.offsetBy(4095)), true);
        }
        // OpenVDB reads the children's buffers in the order of their origins (its root is a
        // std::map), not in the file's order: each child's leaves are kept apart, then joined.
        std::vector<std::pair<openvdb::Coord, std::vector<std::uint16_t>>> children;
        for (std::uint32_t i = 0; i < numChildren; ++i) {
            const openvdb::Coord o = rootOrigin(owner + "'s root child");
            if (!seen.insert(o).second) r.fail(owner + "'s root has two entries at one place");
            std::vector<std::uint16_t> before;
            before.swap(leafOn);
            internal(2, o);
            before.swap(leafOn);
            children.emplace_back(o, std::move(before));
        }
        std::sort(children.begin(), children.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
        for (auto& c : children) leafOn.insert(leafOn.end(), c.second.begin(), c.second.end());
    }

    // Tree::readBuffers: each leaf's value mask (skipped: the file is seekable), then its values.
    void buffers() {
        Mask mask(8);
        for (std::uint16_t on : leafOn) {
            r.skip(64, owner + "'s leaf buffer mask");
            // readCompressedValues counts the topology's mask; only its count matters here.
            std::fill(mask.begin(), mask.end(), 0);
            for (std::uint16_t i = 0; i < on; ++i) mask[i / 64] |= std::uint64_t(1) << (i % 64);
            values(512, mask, owner + "'s leaf values");
        }
    }
};

struct Descriptor {
    std::string uniqueName, gridName, type, parent;
    std::int64_t gridPos = 0, blockPos = 0, endPos = 0;
};

} // namespace

Result<std::vector<GridLayout>> walk(const std::string& path, const std::vector<std::string>& gridNames, bool buffers) {
    std::vector<GridLayout> out(gridNames.size());
    for (std::size_t i = 0; i < gridNames.size(); ++i) out[i].name = gridNames[i];
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) return makeError("cannot be read: " + ec.message());
    std::ifstream in(path, std::ios::binary);
    if (!in) return makeError("cannot be opened");
    Reader r(in, size);
    try {
        // Archive::readHeader.
        if (r.get<std::int64_t>("the magic number") != openvdb::OPENVDB_MAGIC) r.fail("not a VDB file (no magic number)");
        const std::uint32_t version = r.get<std::uint32_t>("the format version");
        if (version < kOldestFormat || version > openvdb::OPENVDB_FILE_VERSION)
            r.fail("file format " + std::to_string(version) + "; splatfx reads formats " + std::to_string(kOldestFormat) + " to " +
                   std::to_string(openvdb::OPENVDB_FILE_VERSION) + " (re-save it with a current OpenVDB)");
        r.skip(8, "the library version");
        if (r.get<std::uint8_t>("the grid offsets flag") == 0) r.fail("a VDB stream without grid offsets; splatfx reads VDB files");
        char uuid[36];
        r.bytes(uuid, 36, "the file's UUID");
        for (int i = 0; i < 36; ++i) {
            const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
            if (dash ? uuid[i] != '-' : !std::isxdigit(static_cast<unsigned char>(uuid[i]))) r.fail("a malformed file UUID");
        }
        walkMetaMap(r, "the file", size);
        // File::readGridDescriptors: each descriptor, then a seek to its grid's end.
        const std::int32_t count = r.get<std::int32_t>("the grid count");
        if (count < 0 || std::uint64_t(count) > r.left() / 36)
            r.fail("the file claims " + std::to_string(count) + " grids, more than its " + std::to_string(r.left()) + " bytes left can hold");
        std::vector<Descriptor> grids;
        for (std::int32_t i = 0; i < count; ++i) {
            Descriptor d;
            d.uniqueName = r.string("a grid name", kMaxName);
            d.gridName = d.uniqueName.substr(0, d.uniqueName.find('\x1e')); // GridDescriptor::stripSuffix
            d.type = r.string("grid '" + d.gridName + "''s type", kMaxName);
            static const std::string kHalf = "_HalfFloat";
            if (d.type.size() >= kHalf.size() && d.type.compare(d.type.size() - kHalf.size(), kHalf.size(), kHalf) == 0)
                d.type.resize(d.type.size() - kHalf.size()); // GridDescriptor::read strips it; the metadata decides (walkMetaMap)
            d.parent = r.string("grid '" + d.gridName + "''s instance parent", kMaxName);
            if (!openvdb::GridBase::isRegistered(d.type)) r.fail("grid '" + d.gridName + "' has the unknown type '" + d.type + "'");
            d.gridPos = r.get<std::int64_t>("grid '" + d.gridName + "''s offsets");
            d.blockPos = r.get<std::int64_t>("grid '" + d.gridName + "''s offsets");
            d.endPos = r.get<std::int64_t>("grid '" + d.gridName + "''s offsets");
            if (!(std::int64_t(r.pos()) <= d.gridPos && d.gridPos <= d.blockPos && d.blockPos <= d.endPos && std::uint64_t(d.endPos) <= size))
                r.fail("grid '" + d.gridName + "' has offsets " + std::to_string(d.gridPos) + ", " + std::to_string(d.blockPos) + ", " +
                       std::to_string(d.endPos) + " out of order or past the file's " + std::to_string(size) + " bytes");
            r.seek(std::uint64_t(d.endPos));
            grids.push_back(std::move(d));
        }
        // File::readAllGridMetadata reads every grid's metadata and transform, in name order
        // (a multimap); the order does not change what each holds.
        std::map<std::string, std::size_t> first; // File::findDescriptor: the first grid of a name
        for (std::size_t g = 0; g < grids.size(); ++g) first.emplace(grids[g].gridName, g);
        for (std::size_t g = 0; g < grids.size(); ++g) {
            const Descriptor& d = grids[g];
            const std::string owner = "grid '" + d.gridName + "'";
            r.limit(size);
            r.seek(std::uint64_t(d.gridPos));
            r.limit(std::uint64_t(d.endPos));
            const std::uint32_t compression = r.get<std::uint32_t>(owner + "'s compression");
            bool half = false;
            walkMetaMap(r, owner, std::uint64_t(d.endPos - d.gridPos), &half);
            walkMap(r, owner, 0);
            GridLayout walked;
            bool isWanted = false;
            for (const GridLayout& want : out) {
                auto it = first.find(want.name);
                isWanted = isWanted || (it != first.end() && it->second == g);
            }
            if (!isWanted) continue;
            walked.found = true;
            walked.type = d.type;
            walked.instanceOf = d.parent;
            const bool isFloat = d.type == openvdb::FloatGrid::gridType(), isVec = d.type == openvdb::Vec3SGrid::gridType();
            walked.supported = (isFloat || isVec) && d.parent.empty(); // otherwise refused by the importer, its tree never read
            if (walked.supported) {
                using FloatRoot = openvdb::FloatTree::RootNodeType;
                using VecRoot = openvdb::Vec3STree::RootNodeType;
                TreeWalk t{.r = r, .owner = owner, .compression = compression, .half = half, .out = walked, .leafOn = {}};
                t.valueBytes = isFloat ? 4 : 12;
                t.halfBytes = isFloat ? 2 : 6;
                t.internal5Bytes = isFloat ? sizeof(FloatRoot::ChildNodeType) : sizeof(VecRoot::ChildNodeType);
                t.internal4Bytes = isFloat ? sizeof(FloatRoot::ChildNodeType::ChildNodeType) : sizeof(VecRoot::ChildNodeType::ChildNodeType);
                t.leafBytes = isFloat ? sizeof(openvdb::FloatTree::LeafNodeType) + 512 * 4 : sizeof(openvdb::Vec3STree::LeafNodeType) + 512 * 12;
                t.topology();
                if (buffers) t.buffers();
            }
            for (GridLayout& want : out) {
                auto it = first.find(want.name);
                if (it != first.end() && it->second == g) {
                    const std::string name = want.name;
                    want = walked;
                    want.name = name;
                }
            }
        }
    } catch (const Bad& b) { return makeError(b.what); } catch (const std::exception& e) {
        return makeError(std::string("cannot be checked: ") + e.what());
    }
    return out;
}

} // namespace splatfx::vdbfile
