// The segment index on its own (lib/trace/segment_index.h): a reference packs into 4 bytes and back
// for any number of paths (banks take the slot bits an entry cannot hold); a query near a box
// hands out each live segment passing it once, whatever cells it spans, and none that does not
// pass; stale entries are never handed out, and renumbering into another layout keeps exactly the
// live ones.
#include <gtest/gtest.h>

#include <set>
#include <tuple>
#include <vector>

#include "trace/segment_index.h"

using namespace qsgi;

namespace {

bool sameRef(const SegmentRef& a, const SegmentRef& b) {
    return a.slot == b.slot && a.place == b.place && a.generation == b.generation;
}

// A segment along x at height y, from x0 to x1, through a 10 x 10 x 1 grid of unit cells.
struct Line {
    SegmentRef ref;
    float y, x0, x1;
};

}  // namespace

TEST(SegmentRefLayout, PacksEveryFieldWithBanksForTheSlotsAnEntryCannotHold) {
    for (size_t slots : {size_t(1), size_t(1000), size_t(1) << 20, size_t(1) << 26, size_t(1) << 31}) {
        SCOPED_TRACE(slots);
        const SegmentRefLayout layout(slots, 32);
        EXPECT_TRUE(layout.holds(64));  // twice the longest path
        EXPECT_FALSE(layout.holds(65));
        EXPECT_GE(layout.generations(), 16u);
        EXPECT_LE(layout.generations(), 256u);
        // Many paths: the slot's high bits pick a bank (2^26 slots, 6 place bits and 4 generation
        // bits leave 22 slot bits in an entry).
        if (slots == size_t(1) << 26) {
            EXPECT_EQ(layout.banks(), 16u);
        }
        for (uint32_t slot : {uint32_t(0), uint32_t(slots / 3), uint32_t(slots - 1)})
            for (uint32_t place : {0u, 1u, 63u})
                for (uint32_t generation : {0u, layout.generations() - 1}) {
                    const SegmentRef r{slot, place, generation};
                    ASSERT_TRUE(sameRef(layout.unpack(layout.pack(r), layout.bankOf(slot)), r))
                        << slot << " " << place << " " << generation;
                }
    }
}

TEST(SegmentIndex, VisitsEachLiveSegmentNearABoxOnceAndRenumberingKeepsExactlyTheLiveOnes) {
    Bounds3f bounds;
    bounds.extend(Vec3f(0, 0, 0));
    bounds.extend(Vec3f(10, 10, 1));
    const size_t slots = 40;
    SegmentIndex index(bounds, 1.0f, SegmentRefLayout(slots, 4), slots);
    std::vector<Line> lines;
    for (uint32_t s = 0; s < slots; ++s)
        for (uint32_t place = 0; place < 2; ++place)
            lines.push_back({{s, place, 0}, 0.25f + float(s % 10), float(s % 7), float(s % 7) + 1.5f + float(place * 3)});
    auto listAll = [&](const std::vector<Line>& batch) {
        std::vector<std::vector<uint32_t>> cells(batch.size());
        for (size_t i = 0; i < batch.size(); ++i) {
            const Line& l = batch[i];
            index.cellsOf(Vec3f(l.x0, l.y, 0.5f), Vec3f(1, 0, 0), double(l.x1 - l.x0), cells[i]);
        }
        index.list([&](auto&& emit) {
            for (size_t i = 0; i < batch.size(); ++i) emit(batch[i].ref, cells[i].data(), cells[i].size());
        });
    };
    listAll(lines);
    // Place 0 of every even slot is rewritten (generation 1), elsewhere along the same row.
    std::set<std::tuple<uint32_t, uint32_t, uint32_t>> live;
    std::vector<Line> rewritten;
    for (Line& l : lines) {
        if (l.ref.slot % 2 == 0 && l.ref.place == 0) {
            l.ref.generation = 1;
            l.x0 = 8.2f;
            l.x1 = 9.8f;
            rewritten.push_back(l);
        }
        live.insert({l.ref.slot, l.ref.place, l.ref.generation});
    }
    listAll(rewritten);
    auto isLive = [&](const SegmentRef& r) { return live.count({r.slot, r.place, r.generation}) > 0; };

    // A box over the cells x in [2, 4): what passes it, by the lines' own geometry.
    Bounds3f box;
    box.extend(Vec3f(2.1f, 0.1f, 0.1f));
    box.extend(Vec3f(3.9f, 9.9f, 0.9f));
    using Places = std::set<std::pair<uint32_t, uint32_t>>;  // (slot, place)
    Places expected;
    for (const Line& l : lines)
        if (l.x0 <= 4.0f && l.x1 >= 2.0f) expected.insert({l.ref.slot, l.ref.place});
    ASSERT_FALSE(expected.empty());
    auto near = [&] {
        std::vector<std::pair<uint32_t, uint32_t>> found;
        index.visitNear({box}, isLive, [&](const SegmentRef& r) {
            EXPECT_TRUE(isLive(r));
            found.push_back({r.slot, r.place});
        });
        return found;
    };
    std::vector<std::pair<uint32_t, uint32_t>> found = near();
    EXPECT_EQ(Places(found.begin(), found.end()), expected);
    EXPECT_EQ(found.size(), expected.size());  // each once

    // Into a layout with banks and fewer generation bits: the same answer, at generation 0.
    index.renumber(SegmentRefLayout(size_t(1) << 26, 4), isLive);
    std::set<std::tuple<uint32_t, uint32_t, uint32_t>> renumbered;
    for (const auto& [slot, place, generation] : live) renumbered.insert({slot, place, 0});
    live.swap(renumbered);
    found = near();
    EXPECT_EQ(Places(found.begin(), found.end()), expected);
    EXPECT_EQ(found.size(), expected.size());
}
