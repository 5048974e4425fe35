// The slotted path store on its own (lib/trace/slotted_path_store.h): whatever rewrites, moves and
// compactions happen, every path reads back exactly the records it was last given, in order; a
// path that outgrows its room moves to the end with its head; generations tell a reference to a
// record still there from one to a record replaced, and renumbering keeps those answers; the
// layout depends on the order of the rewrites only, never on threads.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cstdint>
#include <vector>

#include "trace/counter_rng.h"
#include "trace/slotted_path_store.h"

using namespace qsgi;

namespace {

// A record whose value names the path, the rewrite and its place: any record read from the
// wrong place, or moved out of order, shows.
struct Record {
    uint32_t path, rewrite, place;
    bool operator==(const Record& o) const { return path == o.path && rewrite == o.rewrite && place == o.place; }
};
using Store = SlottedPathStore<Record, uint16_t>;

// Deterministic numbers for the sequence of rewrites (the same in every run).
uint32_t number(uint64_t i, uint32_t below) { return uint32_t(mix64(i * 0x9E3779B97F4A7C15ull + 17) % below); }

// Builds `slots` paths of 0..5 records, then applies `rounds` rounds of rewrites (each path with
// probability 1/3: keeps a head, gets a new tail of 0..9) with the records written in parallel
// after their places are given, compacting when wasteful. The model holds what each path must
// read back.
struct RewriteRun {
    Store store;
    std::vector<std::vector<Record>> model;
    size_t compactions = 0, relocations = 0;
};
RewriteRun runRewrites(uint32_t slots, int rounds) {
    RewriteRun run;
    run.store = Store(slots);
    run.model.resize(slots);
    for (uint32_t s = 0; s < slots; ++s) {
        const uint32_t count = number(s, 6);
        run.store.append(s, count);
        for (uint32_t j = 0; j < count; ++j) {
            run.model[s].push_back({s, 0, j});
            run.store.at<0>(s, j) = run.model[s].back();
            run.store.at<1>(s, j) = uint16_t(s + j);
        }
    }
    uint64_t n = 1000;
    for (int round = 1; round <= rounds; ++round) {
        std::vector<uint32_t> rewritten;
        for (uint32_t s = 0; s < slots; ++s)
            if (number(++n, 3) == 0) rewritten.push_back(s);
        std::vector<std::pair<uint32_t, uint32_t>> keepAndCount(rewritten.size());
        for (size_t i = 0; i < rewritten.size(); ++i) {
            const uint32_t s = rewritten[i];
            const uint32_t keep = number(++n, uint32_t(run.model[s].size()) + 1);
            const uint32_t count = keep + number(++n, 10);
            const uint32_t capacityBefore = run.store.slot(s).capacity;
            run.store.rewrite(s, keep, count);
            run.relocations += count > capacityBefore;
            keepAndCount[i] = {keep, count};
            run.model[s].resize(keep);
            for (uint32_t j = keep; j < count; ++j) run.model[s].push_back({s, uint32_t(round), j});
        }
        // Each path writes only its own places: in parallel.
        tbb::parallel_for(size_t(0), rewritten.size(), [&](size_t i) {
            const uint32_t s = rewritten[i];
            for (uint32_t j = keepAndCount[i].first; j < keepAndCount[i].second; ++j) {
                run.store.at<0>(s, j) = run.model[s][j];
                run.store.at<1>(s, j) = uint16_t(s + j);
            }
        });
        run.store.compactIfWasteful();
    }
    run.compactions = run.store.compactions();
    return run;
}

void expectModel(const RewriteRun& run) {
    for (uint32_t s = 0; s < run.model.size(); ++s) {
        ASSERT_EQ(run.store.slot(s).count, run.model[s].size()) << "path " << s;
        ASSERT_LE(run.store.slot(s).count, run.store.slot(s).capacity) << "path " << s;
        for (uint32_t j = 0; j < run.model[s].size(); ++j) {
            ASSERT_EQ(run.store.at<0>(s, j), run.model[s][j]) << "path " << s << " record " << j;
            ASSERT_EQ(run.store.at<1>(s, j), uint16_t(s + j)) << "path " << s << " record " << j;
        }
    }
}

}  // namespace

TEST(SlottedPathStore, CompactionKeepsEveryPathsRecordsInOrder) {
    const RewriteRun run = runRewrites(2000, 30);
    // The test is about compaction: it must have happened, and paths must have moved.
    EXPECT_GT(run.compactions, 0u);
    EXPECT_GT(run.relocations, 0u);
    expectModel(run);
    uint64_t live = 0, rooms = 0;
    for (uint32_t s = 0; s < run.model.size(); ++s) {
        live += run.model[s].size();
        rooms += run.store.slot(s).capacity;
    }
    EXPECT_EQ(run.store.records(), live);
    // Garbage never stays above a quarter of the rooms after a frame's compaction check.
    EXPECT_LE(4 * run.store.garbage(), rooms);
}

TEST(SlottedPathStore, APathThatOutgrowsItsRoomMovesToTheEndWithItsHead) {
    Store store(3);
    for (uint32_t s = 0; s < 3; ++s) {
        store.append(s, 2);
        for (uint32_t j = 0; j < 2; ++j) store.at<0>(s, j) = {s, 0, j};
    }
    // Fits its room: written in place.
    store.rewrite(1, 1, 2);
    EXPECT_EQ(store.slot(1).begin, 2u);
    EXPECT_EQ(store.garbage(), 0u);
    // Outgrows it: the whole path moves to the end, head first, with room to grow by an eighth.
    store.rewrite(1, 1, 16);
    EXPECT_EQ(store.slot(1).begin, 6u);
    EXPECT_EQ(store.slot(1).count, 16u);
    EXPECT_EQ(store.slot(1).capacity, 18u);
    EXPECT_EQ(store.garbage(), 2u);  // its old room
    EXPECT_EQ(store.at<0>(1, 0), (Record{1, 0, 0}));
    // Its neighbours did not move.
    EXPECT_EQ(store.at<0>(0, 1), (Record{0, 0, 1}));
    EXPECT_EQ(store.at<0>(2, 1), (Record{2, 0, 1}));
    // Shrinking keeps the room; growing within it stays put.
    store.rewrite(1, 0, 1);
    store.rewrite(1, 1, 18);
    EXPECT_EQ(store.slot(1).begin, 6u);
    EXPECT_EQ(store.records(), 2u + 18u + 2u);
}

TEST(SlottedPathStore, RenumberingResetsGenerationsAndKeepsLivenessAnswers) {
    struct Ref {
        uint32_t slot, place, generation;
    };
    SlottedPathStore<Record> store(2, {true}, 4);
    store.append(0, 3);
    store.append(1, 2);
    std::vector<Ref> refs;
    for (uint32_t j = 0; j < 3; ++j) refs.push_back({0, j, store.generation(0)});
    for (uint32_t j = 0; j < 2; ++j) refs.push_back({1, j, store.generation(1)});
    for (const Ref& r : refs) EXPECT_TRUE(store.isLive(r.slot, r.place, r.generation));

    // Path 0 keeps its first record and gets two new ones, then grows past its room: the kept
    // head's references stay live wherever it moves, the replaced records' do not.
    store.rewrite(0, 1, 3);
    EXPECT_EQ(store.generation(0), 1u);
    EXPECT_TRUE(store.isLive(0, 0, 0));
    EXPECT_FALSE(store.isLive(0, 1, 0));
    EXPECT_FALSE(store.isLive(0, 2, 0));
    EXPECT_TRUE(store.isLive(0, 1, 1));
    store.rewrite(0, 2, 6);
    EXPECT_TRUE(store.isLive(0, 0, 0));
    EXPECT_TRUE(store.isLive(0, 1, 1));
    EXPECT_FALSE(store.isLive(0, 2, 1));
    EXPECT_TRUE(store.isLive(0, 5, 2));
    EXPECT_FALSE(store.isLive(0, 6, 2));  // past its records
    // Path 1 shrinks: its second record is gone.
    store.rewrite(1, 1, 1);
    EXPECT_FALSE(store.isLive(1, 1, 0));
    EXPECT_TRUE(store.isLive(1, 0, 0));

    // Four generations: path 0 (at 2) may be rewritten once more, then must be renumbered.
    EXPECT_FALSE(store.wouldWrap(0));
    store.rewrite(0, 6, 6);
    EXPECT_TRUE(store.wouldWrap(0));
    EXPECT_THROW(store.rewrite(0, 6, 6), std::logic_error);

    // The owner's references: those still live move to generation 0, the rest are dropped.
    std::vector<Ref> all;
    for (uint32_t s = 0; s < 2; ++s)
        for (uint32_t j = 0; j < 8; ++j)
            for (uint32_t g = 0; g < 4; ++g) all.push_back({s, j, g});
    std::vector<Ref> kept;
    for (const Ref& r : all)
        if (store.isLive(r.slot, r.place, r.generation)) kept.push_back({r.slot, r.place, 0});
    EXPECT_EQ(kept.size(), store.records());  // one live reference per record
    store.renumber(4);
    EXPECT_EQ(store.renumberings(), 1u);
    EXPECT_EQ(store.generation(0), 0u);
    EXPECT_EQ(store.generation(1), 0u);
    EXPECT_FALSE(store.wouldWrap(0));
    for (const Ref& r : kept) EXPECT_TRUE(store.isLive(r.slot, r.place, r.generation)) << r.slot << " " << r.place;
    // After renumbering, rewrites count again from 0 and replace as before.
    store.rewrite(0, 3, 4);
    EXPECT_TRUE(store.isLive(0, 2, 0));
    EXPECT_FALSE(store.isLive(0, 3, 0));
    EXPECT_TRUE(store.isLive(0, 3, 1));
}

TEST(SlottedPathStore, LayoutDoesNotDependOnTheThreadCount) {
    std::vector<RewriteRun> runs;
    for (int threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        runs.push_back(runRewrites(500, 20));
    }
    for (uint32_t s = 0; s < 500; ++s) {
        EXPECT_EQ(runs[0].store.slot(s).begin, runs[1].store.slot(s).begin) << s;
        EXPECT_EQ(runs[0].store.slot(s).capacity, runs[1].store.slot(s).capacity) << s;
    }
    EXPECT_EQ(runs[0].store.garbage(), runs[1].store.garbage());
    EXPECT_EQ(runs[0].store.bytes(), runs[1].store.bytes());
    expectModel(runs[1]);
}

TEST(SlottedPathStore, AColumnSwitchedOffHoldsNothing) {
    Store both(10), first(10, {true, false});
    for (uint32_t s = 0; s < 10; ++s) {
        both.append(s, 3);
        first.append(s, 3);
    }
    EXPECT_GE(both.bytes() - first.bytes(), 30 * sizeof(uint16_t));
    first.rewrite(4, 1, 7);  // moves: only the column that is on is copied
    EXPECT_EQ(first.slot(4).count, 7u);
}

// A reserve that guessed high is given back down to a quarter over the records, and nothing
// moves: every path reads back what it was given.
TEST(SlottedPathStore, TrimmingAReserveKeepsEveryRecord) {
    Store store(100);
    store.reserve(100000);
    for (uint32_t s = 0; s < 100; ++s) {
        store.append(s, s % 7);
        for (uint32_t j = 0; j < s % 7; ++j) store.at<0>(s, j) = Record{s, 0, j};
    }
    const size_t reserved = store.bytes();
    store.trimReserve();
    EXPECT_LT(store.bytes(), reserved / 100);
    for (uint32_t s = 0; s < 100; ++s) {
        ASSERT_EQ(store.slot(s).count, s % 7);
        for (uint32_t j = 0; j < s % 7; ++j) ASSERT_EQ(store.at<0>(s, j), (Record{s, 0, j}));
    }
    const size_t trimmed = store.bytes();
    store.trimReserve();  // within a quarter already: nothing to give back
    EXPECT_EQ(store.bytes(), trimmed);
}
