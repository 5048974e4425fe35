// Per-path records in one array (docs/design.md §6.3–§6.4): the tracked paths' segments, and DETP's
// remembered crossings. Each path has a slot, fixed for the store's life; its records sit in one
// run of the array, [begin, begin + count), in a room of `capacity`. Rewriting a path's tail
// writes the new records over the old ones where they fit (the kept head stays where it is) and
// moves the whole path to the end of the array, with room to grow, where they do not; the room it
// left is garbage until the store is compacted, in place: once garbage is a quarter of the rooms
// (compactIfWasteful), and before the arrays would grow when an eighth is garbage. A long run
// rewrites some paths every frame: these arrays are most of its memory.
//
// Generations (optional): each slot counts its rewrites and each record keeps the generation it
// was written in, so that a reference (slot, j, generation) taken when record j was written is
// live exactly while that record is (isLive), wherever the path has moved since. Before a slot's
// generation would reach the limit (its references' bits), the owner renumbers: every generation
// back to 0, after rewriting the references it keeps.
//
// A record may have several columns (one array each, moved together); a column can be switched
// off, and then holds nothing. Writing is serial; reading from several threads is safe. Positions
// (slot(s).begin + j) and pointers into a column stay valid until the next rewrite or compaction.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "util/modest_growth.h"

namespace qsgi {

template <class... Columns>
class SlottedPathStore {
public:
    static constexpr size_t kColumns = sizeof...(Columns);
    static constexpr uint32_t kMaxGenerations = 256;  // a record's generation is one byte

    struct Slot {
        uint32_t begin = 0;     // position of its first record
        uint32_t count = 0;     // its records
        uint32_t capacity = 0;  // its room: positions [begin, begin + capacity) are its own
    };

    SlottedPathStore() = default;
    // slots: how many paths; on: which columns hold records; generations: rewrites a slot can
    // count before a renumbering (0: the store keeps no generations).
    explicit SlottedPathStore(size_t slots, std::array<bool, kColumns> on = allOn(), uint32_t generations = 0)
        : slots_(slots), on_(on) {
        setGenerations(generations);
        if (generations_) generation_.assign(slots, 0);
    }

    size_t slotCount() const { return slots_.size(); }
    const Slot& slot(uint32_t s) const { return slots_[s]; }
    uint64_t records() const { return live_; }  // Σ count
    uint64_t garbage() const { return garbage_; }

    // Column C: record j of slot s, and the whole array (by position).
    template <size_t C>
    const auto& at(uint32_t s, uint32_t j) const { return std::get<C>(columns_)[slots_[s].begin + j]; }
    template <size_t C>
    auto& at(uint32_t s, uint32_t j) { return std::get<C>(columns_)[slots_[s].begin + j]; }
    template <size_t C>
    const auto* column() const { return std::get<C>(columns_).data(); }
    template <size_t C>
    auto* column() { return std::get<C>(columns_).data(); }

    // Building: slot s gets a room of exactly `count` records at the end of the array (written
    // by the caller at slot(s).begin on). Each slot once, before any rewrite.
    void append(uint32_t s, uint32_t count) {
        Slot& slot = slots_[s];
        slot.begin = end();
        slot.count = slot.capacity = count;
        live_ += count;
        resize(uint64_t(slot.begin) + count);
    }
    void reserve(uint64_t records) {
        forEachColumn([&](auto& c) { c.reserve(records); });
        if (generations_) recordGeneration_.reserve(records);
    }
    // Gives back room reserved beyond a quarter more than the positions in use (a reserve that
    // guessed high).
    void trimReserve() {
        auto trim = [&](auto& c) {
            if (c.capacity() > c.size() + c.size() / 4) c.shrink_to_fit();
        };
        forEachColumn(trim);
        if (generations_) trim(recordGeneration_);
    }

    // Slot s keeps its first `keep` records and will hold `count`; the caller writes records
    // [keep, count) at slot(s).begin + keep on. The records it replaces must have been read
    // before. With generations, the slot's generation goes up by one (wouldWrap must be false)
    // and the new records carry it. Rewrites in the same order give the same layout.
    void rewrite(uint32_t s, uint32_t keep, uint32_t count) {
        Slot& slot = slots_[s];
        if (keep > slot.count || keep > count) throw std::logic_error("SlottedPathStore::rewrite: keeps more than it has");
        if (wouldWrap(s)) throw std::logic_error("SlottedPathStore::rewrite: the generation would wrap; renumber first");
        if (count > slot.capacity) {
            // Room to grow by a few records, so that the next rewrites fit where they land.
            const uint32_t capacity = count + count / 8;
            // Reclaiming garbage is cheaper than holding arrays a quarter larger for good.
            if (uint64_t(end()) + capacity > reserved() && 8 * garbage_ >= end() - garbage_) compact();
            const uint32_t begin = end();
            resize(uint64_t(begin) + capacity);
            forEachColumn([&](auto& c) { std::copy_n(c.begin() + slot.begin, keep, c.begin() + begin); });
            if (generations_)
                std::copy_n(recordGeneration_.begin() + slot.begin, keep, recordGeneration_.begin() + begin);
            garbage_ += slot.capacity;
            slot.begin = begin;
            slot.capacity = capacity;
        }
        live_ = live_ - slot.count + count;
        slot.count = count;
        if (generations_) {
            const uint8_t g = ++generation_[s];
            std::fill(recordGeneration_.begin() + slot.begin + keep, recordGeneration_.begin() + slot.begin + count, g);
        }
    }

    // Generations.
    uint32_t generations() const { return generations_; }
    uint32_t generation(uint32_t s) const { return generation_[s]; }
    bool wouldWrap(uint32_t s) const { return generations_ && generation_[s] + 1u >= generations_; }
    bool isLive(uint32_t s, uint32_t j, uint32_t generation) const {
        const Slot& slot = slots_[s];
        return j < slot.count && recordGeneration_[slot.begin + j] == generation;
    }
    // Every generation back to 0, with a new limit. References taken before name nothing now:
    // the owner rewrites those it keeps (at generation 0) first.
    void renumber(uint32_t generations) {
        if (!generations_ || !generations) throw std::logic_error("SlottedPathStore::renumber: a store without generations");
        setGenerations(generations);
        std::fill(generation_.begin(), generation_.end(), uint8_t(0));
        std::fill(recordGeneration_.begin(), recordGeneration_.end(), uint8_t(0));
        ++renumberings_;
    }
    uint64_t renumberings() const { return renumberings_; }
    uint64_t compactions() const { return compactions_; }

    // Compacts in place once the garbage is a quarter of the rooms: returns whether it did.
    // Taking the slots in the order they sit, each moves down or stays, so nothing is
    // overwritten before it has moved and no second array is needed. Each slot keeps its room
    // (the array grows by rewrites that outgrow theirs only).
    bool compactIfWasteful() {
        if (!(4 * garbage_ > end() - garbage_)) return false;
        compact();
        return true;
    }

    // Memory held: the slots, every column's array and the generations.
    size_t bytes() const {
        size_t total = slots_.capacity() * sizeof(Slot) + generation_.capacity() + recordGeneration_.capacity();
        std::apply([&](const auto&... c) { ((total += c.capacity() * sizeof(c[0])), ...); }, columns_);
        return total;
    }

    static constexpr std::array<bool, kColumns> allOn() {
        std::array<bool, kColumns> on{};
        on.fill(true);
        return on;
    }

private:
    void compact() {
        std::vector<uint32_t> byPlace(slots_.size());
        std::iota(byPlace.begin(), byPlace.end(), 0u);
        std::sort(byPlace.begin(), byPlace.end(), [&](uint32_t a, uint32_t b) { return slots_[a].begin < slots_[b].begin; });
        uint32_t to = 0;
        for (uint32_t s : byPlace) {
            Slot& slot = slots_[s];
            if (slot.begin != to) {
                forEachColumn([&](auto& c) { std::copy_n(c.begin() + slot.begin, slot.count, c.begin() + to); });
                if (generations_)
                    std::copy_n(recordGeneration_.begin() + slot.begin, slot.count, recordGeneration_.begin() + to);
                slot.begin = to;
            }
            to += slot.capacity;
        }
        resize(to);
        garbage_ = 0;
        ++compactions_;
    }
    uint32_t end() const { return size_; }
    // Records the arrays hold room for without growing.
    uint64_t reserved() {
        uint64_t room = UINT64_MAX;
        forEachColumn([&](auto& c) { room = std::min<uint64_t>(room, c.capacity()); });
        return room;
    }
    void setGenerations(uint32_t generations) {
        generations_ = generations ? std::clamp<uint32_t>(generations, 2, kMaxGenerations) : 0;
    }
    template <class F>
    void forEachColumn(F&& f) {
        size_t i = 0;
        std::apply([&](auto&... c) { ((on_[i++] ? f(c) : void()), ...); }, columns_);
    }
    // Positions are 32 bits: checked, not assumed (2^32 records is far beyond any tracked run).
    void resize(uint64_t size) {
        if (size > UINT32_MAX) throw std::length_error("SlottedPathStore: more than 2^32 records");
        forEachColumn([&](auto& c) {
            reserveModestly(c, size > c.size() ? size - c.size() : 0);
            c.resize(size);
        });
        if (generations_) {
            reserveModestly(recordGeneration_, size > recordGeneration_.size() ? size - recordGeneration_.size() : 0);
            recordGeneration_.resize(size);
        }
        size_ = uint32_t(size);
    }

    std::vector<Slot> slots_;
    std::array<bool, kColumns> on_{};
    std::tuple<std::vector<Columns>...> columns_;
    uint32_t size_ = 0;  // positions in use, garbage included
    uint64_t live_ = 0;
    uint64_t garbage_ = 0;
    uint32_t generations_ = 0;
    std::vector<uint8_t> generation_;        // per slot: its rewrites since the last renumbering
    std::vector<uint8_t> recordGeneration_;  // per position: the generation its record was written in
    uint64_t renumberings_ = 0, compactions_ = 0;
};

}  // namespace qsgi
