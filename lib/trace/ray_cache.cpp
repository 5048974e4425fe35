#include "trace/ray_cache.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <iterator>

#include "trace/photon_source.h"

namespace qsgi {

void RayCache::BlockWriter::clear() {
    first_.clear();
    later_.clear();
    laterBegin_.clear();
    hits_.clear();
    hitsBegin_.clear();
    segments_ = 0;
}

RayCache::BlockWriter RayCache::BlockWriter::exactCopy() const {
    BlockWriter copy;
    copy.first_.assign(first_.begin(), first_.end());
    copy.later_.assign(later_.begin(), later_.end());
    copy.laterBegin_.assign(laterBegin_.begin(), laterBegin_.end());
    copy.hits_.assign(hits_.begin(), hits_.end());
    copy.hitsBegin_.assign(hitsBegin_.begin(), hitsBegin_.end());
    copy.segments_ = segments_;
    return copy;
}

void RayCache::BlockWriter::beginPath() {
    if (laterBegin_.empty()) laterBegin_.push_back(0);
    first_.push_back({0.0f, kNoSegment});
    laterBegin_.push_back(uint32_t(later_.size()));
    if (!hitsBegin_.empty()) hitsBegin_.push_back(uint32_t(hits_.size()));
}

void RayCache::BlockWriter::add(const Segment& s) {
    First& first = first_.back();
    if (first.triangle == kNoSegment) {
        first = {s.length, s.triangle};
    } else {
        later_.push_back({s.origin, s.direction, s.length, s.triangle});
        laterBegin_.back() = uint32_t(later_.size());
    }
    if (s.impactVaries) {
        if (hitsBegin_.empty()) hitsBegin_.assign(first_.size() + 1, 0);  // the block's first such impact
        hits_.push_back({s.b1, s.b2});
        hitsBegin_.back() = uint32_t(hits_.size());
    }
    ++segments_;
}

RayCache RayCache::ofSegments(std::vector<Segment> segments, float maxPhotonPower, std::vector<uint64_t> pathBegin) {
    RayCache cache;
    cache.maxPhotonPower = maxPhotonPower;
    cache.segments_ = segments.size();
    cache.paths_ = pathBegin.empty() ? 0 : pathBegin.size() - 1;
    Block block;
    block.verbatim = std::move(segments);
    block.verbatimPathBegin = std::move(pathBegin);
    cache.blocks_.push_back(std::move(block));
    return cache;
}

RayCache RayCache::ofBlocks(std::vector<BlockWriter> blocks, uint64_t firstPathPerBlock,
                            std::shared_ptr<const PhotonSource> source, float maxPhotonPower) {
    RayCache cache;
    cache.maxPhotonPower = maxPhotonPower;
    cache.source_ = std::move(source);
    cache.blocks_.resize(blocks.size());
    for (size_t b = 0; b < blocks.size(); ++b) {
        Block& block = cache.blocks_[b];
        block.firstPath = b * firstPathPerBlock;
        block.firstSegment = cache.segments_;
        block.records = std::move(blocks[b]);
        if (block.records.laterBegin_.empty()) block.records.laterBegin_.push_back(0);
        cache.segments_ += block.records.segments_;
        cache.paths_ += block.records.first_.size();
    }
    return cache;
}

size_t RayCache::bytes() const {
    size_t total = 0;
    for (const Block& b : blocks_)
        total += b.records.first_.capacity() * sizeof(BlockWriter::First) +
                 b.records.later_.capacity() * sizeof(BlockWriter::Later) +
                 b.records.laterBegin_.capacity() * sizeof(uint32_t) + b.verbatim.capacity() * sizeof(Segment) +
                 b.records.hits_.capacity() * sizeof(b.records.hits_[0]) + b.records.hitsBegin_.capacity() * sizeof(uint32_t) +
                 b.verbatimPathBegin.capacity() * sizeof(uint64_t);
    return total;
}

uint64_t RayCache::pathsMissingScene() const {
    uint64_t missed = 0;
    for (const Block& b : blocks_) {
        for (const BlockWriter::First& f : b.records.first_) missed += f.triangle == kNoTriangle || f.triangle == kNoSegment;
        const auto& begin = b.verbatimPathBegin;
        for (size_t p = 0; p + 1 < begin.size(); ++p)
            missed += begin[p] == begin[p + 1] || !b.verbatim[begin[p]].hasImpact();
    }
    return missed;
}

namespace {

// Where an impact on a triangle whose albedo varies took place: the path's kept barycentrics, in
// order.
void placeImpact(const PhotonSource& source, Segment& s, const std::array<float, 2>*& hit) {
    s.impactDynamic = s.hasImpact() ? source.surface(s.triangle).dynamic : 0;
    s.impactVaries = s.hasImpact() ? source.surface(s.triangle).varies : 0;
    s.b1 = s.impactVaries ? (*hit)[0] : 0.0f;
    s.b2 = s.impactVaries ? (*hit++)[1] : 0.0f;
}

// Appends path `path`'s segments from its records: the first from the emission, the later ones
// from their records, power carried on with the tracer's own arithmetic.
template <class First, class Later, class Out>
void decodeRecords(const PhotonSource& source, uint64_t path, const First& first, const Later* later, const Later* end,
                   const std::array<float, 2>* hit, Out out) {
    const PhotonEmission e = source.emission(path);
    // What each impact did is the tracer's decision from the path's own numbers: asked again
    // where some surface lets photons through.
    const bool transmits = source.anyTransmits();
    const PathNumbers numbers = transmits ? source.numbersFor(path) : PathNumbers(0, 0);
    Segment s;
    s.origin = e.origin;
    s.direction = e.direction;
    s.power = e.power;
    s.length = first.length;
    s.triangle = first.triangle;
    s.path = uint32_t(path);
    s.bounce = 0;
    s.scattered = 0;
    placeImpact(source, s, hit);
    *out++ = s;
    for (; later != end; ++later) {
        const PhotonSource::Surface at = source.surfaceAt(s.triangle, s.b1, s.b2);
        const PhotonSource::Impact what =
            transmits ? PhotonSource::impact(at, numbers.uniform(s.bounce + 1u, rng_dim::kSurvival)) : PhotonSource::Impact::Reflects;
        s.power = PhotonSource::powerAfter(s.power, at, what);
        s.scattered = s.scattered || what == PhotonSource::Impact::Reflects;
        s.origin = later->origin;
        s.direction = later->direction;
        s.length = later->length;
        s.triangle = later->triangle;
        ++s.bounce;
        placeImpact(source, s, hit);
        *out++ = s;
    }
}

}  // namespace

void RayCache::decodeBlock(size_t b, std::vector<Segment>& out) const {
    out.resize(blocks_[b].verbatim.empty() && source_ ? blocks_[b].records.segments_ : blocks_[b].verbatim.size());
    decodeBlockInto(b, out.data());
}

void RayCache::decodeBlockInto(size_t b, Segment* out) const {
    const Block& block = blocks_[b];
    if (!block.verbatim.empty() || !source_) {
        std::copy(block.verbatim.begin(), block.verbatim.end(), out);
        return;
    }
    const BlockWriter& r = block.records;
    for (size_t p = 0; p < r.first_.size(); ++p) {
        if (r.first_[p].triangle == kNoSegment) continue;
        const size_t count = 1 + r.laterBegin_[p + 1] - r.laterBegin_[p];
        decodeRecords(*source_, block.firstPath + p, r.first_[p], r.later_.data() + r.laterBegin_[p],
                      r.later_.data() + r.laterBegin_[p + 1], r.hitsBegin_.empty() ? nullptr : r.hits_.data() + r.hitsBegin_[p],
                      out);
        out += count;
    }
}

void RayCache::appendPath(uint64_t path, std::vector<Segment>& out) const {
    // The last block that starts at or before the path.
    const auto after = std::upper_bound(blocks_.begin(), blocks_.end(), path,
                                        [](uint64_t p, const Block& b) { return p < b.firstPath; });
    if (after == blocks_.begin()) return;
    const Block& block = *(after - 1);
    const uint64_t local = path - block.firstPath;
    if (!block.verbatimPathBegin.empty()) {
        if (local + 1 >= block.verbatimPathBegin.size()) return;
        out.insert(out.end(), block.verbatim.begin() + int64_t(block.verbatimPathBegin[local]),
                   block.verbatim.begin() + int64_t(block.verbatimPathBegin[local + 1]));
        return;
    }
    const BlockWriter& r = block.records;
    if (!source_ || local >= r.first_.size() || r.first_[local].triangle == kNoSegment) return;
    decodeRecords(*source_, path, r.first_[local], r.later_.data() + r.laterBegin_[local],
                  r.later_.data() + r.laterBegin_[local + 1],
                  r.hitsBegin_.empty() ? nullptr : r.hits_.data() + r.hitsBegin_[local], std::back_inserter(out));
}

void RayCache::forEachBlock(const std::function<void(size_t, const std::vector<Segment>&)>& visit) const {
    tbb::parallel_for(size_t(0), blocks_.size(), [&](size_t b) {
        std::vector<Segment> block;
        decodeBlock(b, block);
        visit(b, block);
    });
}

std::vector<Segment> RayCache::decodeBlocks(size_t beginBlock, size_t endBlock) const {
    const uint64_t first = beginBlock < blocks_.size() ? blocks_[beginBlock].firstSegment : segments_;
    const uint64_t end = endBlock < blocks_.size() ? blocks_[endBlock].firstSegment : segments_;
    std::vector<Segment> segments(end - first);
    tbb::parallel_for(beginBlock, endBlock,
                      [&](size_t b) { decodeBlockInto(b, segments.data() + (blocks_[b].firstSegment - first)); });
    return segments;
}

}  // namespace qsgi
