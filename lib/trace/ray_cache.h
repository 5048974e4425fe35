// The ray cache (docs/design.md §4): every segment of every photon path, in (path, bounce) order, stored
// in about 23 bytes a segment instead of the 52 of a Segment, and decoded to exactly the segments
// the tracer followed.
//
// What it leaves out is what the photon source can say again (photon_source.h): a path's first
// segment starts where its emission does, power follows from the emission's and the albedo and
// survival of the triangles hit before (the tracer's own arithmetic: the same bits), and path,
// bounce and the dynamic flag from where a record sits and which triangle it hit. A first
// segment keeps its length and triangle (8 bytes); a later one its origin, direction, length and
// triangle (32 bytes: a bounce's origin is lifted along the normal of the triangle it left, which
// may move, so it is stored rather than rebuilt from the current pose). An n-segment path costs
// 12 + 32(n − 1) bytes with its 4-byte index entry: under 32 per segment for any n.
//
// The tracer writes one block per chunk of paths, in parallel, and the cache keeps them as they
// are (no concatenation copy). Caches made by hand (tests) keep their segments verbatim.
// Consumers read segments only through the accessors below, never by field.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

class PhotonSource;

constexpr uint32_t kNoTriangle = 0xFFFFFFFFu;

// One segment, decoded.
struct Segment {
    Vec3f origin;
    Vec3f direction;    // unit
    float length = 0;   // to the impact; for an escaping photon, to where it leaves the scene bounds
    Vec3f power;        // W, RGB, carried along this segment
    uint32_t triangle = kNoTriangle;  // impacted triangle, or kNoTriangle if the photon escaped
    uint32_t path = 0;
    uint16_t bounce = 0;
    uint8_t impactDynamic = 0;        // impacted dynamic geometry
    // Impacted a triangle whose albedo varies over it (a texture, vertex colours): the bounce's
    // power depends on where, so the records keep the hit's barycentrics (b1, b2) for it.
    uint8_t impactVaries = 0;
    // The light it carries was reflected diffusely before (at bounce > 0, unless it only passed
    // through panes, KHR_materials_transmission): what "after the first bounce" counts when
    // direct light is computed apart (--direct exact).
    uint8_t scattered = 0;
    float b1 = 0, b2 = 0;

    bool hasImpact() const { return triangle != kNoTriangle; }
    Vec3f impactPoint() const { return origin + direction * length; }
};

class RayCache {
public:
    RayCache() = default;
    // A cache holding these segments as they are. `pathBegin` groups them by path as the
    // tracer's do (path i owns [pathBegin[i], pathBegin[i+1])); empty, the cache has no paths,
    // only segments.
    static RayCache ofSegments(std::vector<Segment> segments, float maxPhotonPower,
                               std::vector<uint64_t> pathBegin = {});

    // Largest RGB component any photon starts with: the scale of fixed-point power sums.
    float maxPhotonPower = 0;
    // What decodes the traced blocks (null for a cache of segments kept as they are): the
    // tracked paths decode their own records with it too.
    const std::shared_ptr<const PhotonSource>& source() const { return source_; }

    // What a traced path costs at the least (its first segment's record and its index entry), and
    // each segment after the first.
    static constexpr size_t kBytesPerPath = 12, kBytesPerLaterSegment = 32;

    size_t pathCount() const { return paths_; }
    uint64_t segmentCount() const { return segments_; }
    size_t bytes() const;  // memory the records and the path index hold

    // Photons whose first segment hit nothing (lights pointing away from, or far from, the scene),
    // and photons with no segment (an aimed spot light's outside its cone).
    uint64_t pathsMissingScene() const;

    // The segments, block by block: blocks hold consecutive paths and can be decoded in
    // parallel. decodeBlock replaces `out` with block b's segments in (path, bounce) order;
    // blockFirstSegment(b) is the index of its first in the whole cache's order.
    size_t blockCount() const { return blocks_.size(); }
    uint64_t blockFirstSegment(size_t b) const { return blocks_[b].firstSegment; }
    void decodeBlock(size_t b, std::vector<Segment>& out) const;

    // Appends the segments of `path`, in bounce order.
    void appendPath(uint64_t path, std::vector<Segment>& out) const;
    // visit(b, segments of block b) for every block, in parallel (each call with its own
    // decoded copy): the way to read the whole cache fast; results gathered per block and joined
    // in block order are in (path, bounce) order.
    void forEachBlock(const std::function<void(size_t, const std::vector<Segment>&)>& visit) const;
    // Every segment in (path, bounce) order, decoded block by block (serial: tests and small
    // caches; whole-cache passes use forEachBlock).
    template <class Visit>
    void forEachSegment(Visit&& visit) const {
        std::vector<Segment> block;
        for (size_t b = 0; b < blocks_.size(); ++b) {
            decodeBlock(b, block);
            for (const Segment& s : block) visit(s);
        }
    }
    // The segments of blocks [beginBlock, endBlock), decoded in parallel into one vector in
    // (path, bounce) order: for consumers that reorder or index the segments.
    std::vector<Segment> decodeBlocks(size_t beginBlock, size_t endBlock) const;
    std::vector<Segment> decodeAll() const { return decodeBlocks(0, blocks_.size()); }

    // Written by the tracer: block b holds the paths [firstPath, firstPath + paths). Segments are
    // added path by path, each path's in bounce order, from `source`'s emissions.
    class BlockWriter {
    public:
        void beginPath();
        void add(const Segment& s);  // the current path's next segment
        size_t segments() const { return segments_; }
        // Empties it, keeping its memory: a tracer thread writes every chunk into one writer and
        // keeps an exact-size copy of each (no slack held for the cache's lifetime).
        void clear();
        BlockWriter exactCopy() const;

    private:
        friend class RayCache;
        struct First {
            float length;
            uint32_t triangle;  // kNoTriangle if it escaped, kNoSegment if the path sent nothing
        };
        struct Later {
            Vec3f origin, direction;
            float length;
            uint32_t triangle;
        };
        std::vector<First> first_;           // per path
        std::vector<Later> later_;           // bounces ≥ 1, path after path
        std::vector<uint32_t> laterBegin_;   // per path and one more: its first later record
        // The barycentrics of the impacts on varying triangles (Segment::impactVaries), in order,
        // and per path (and one more) its first: both empty while a block has none, so a scene of
        // plain colours pays nothing.
        std::vector<std::array<float, 2>> hits_;
        std::vector<uint32_t> hitsBegin_;
        size_t segments_ = 0;
    };
    static_assert(sizeof(BlockWriter::First) + sizeof(uint32_t) == kBytesPerPath, "the record sizes named above");
    static_assert(sizeof(BlockWriter::Later) == kBytesPerLaterSegment, "the record sizes named above");
    static RayCache ofBlocks(std::vector<BlockWriter> blocks, uint64_t firstPathPerBlock,
                             std::shared_ptr<const PhotonSource> source, float maxPhotonPower);

private:
    static constexpr uint32_t kNoSegment = 0xFFFFFFFEu;
    void decodeBlockInto(size_t b, Segment* out) const;  // writes the block's segmentCount segments
    struct Block {
        uint64_t firstPath = 0;
        uint64_t firstSegment = 0;
        BlockWriter records;                // traced paths
        std::vector<Segment> verbatim;      // or segments kept as they are
        std::vector<uint64_t> verbatimPathBegin;
    };
    std::vector<Block> blocks_;
    std::shared_ptr<const PhotonSource> source_;  // what decoding traced blocks needs
    size_t paths_ = 0;
    uint64_t segments_ = 0;
};

}  // namespace qsgi
