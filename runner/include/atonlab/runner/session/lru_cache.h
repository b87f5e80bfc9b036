#pragma once
// A small least-recently-used cache: the renderer keeps its frame views, its
// code values and its lights-off backgrounds in three of them.
#include <algorithm>
#include <cstddef>
#include <functional>
#include <list>
#include <unordered_map>
#include <utility>

namespace atonlab::runner {

/// At most capacity() entries; find() and put() make an entry the most recent,
/// and put() drops the least recent beyond the capacity. Pointers and
/// references to a value stay valid until that entry is dropped or replaced.
template <class Key, class Value, class Hash = std::hash<Key>>
class LruCache {
public:
    /// capacity: at least 1 (0 is taken as 1).
    explicit LruCache(std::size_t capacity) : capacity_(std::max<std::size_t>(capacity, 1)) {}

    /// The value under `key`, now the most recent; nullptr when there is none.
    Value* find(const Key& key) {
        const auto it = index_.find(key);
        if (it == index_.end()) return nullptr;
        items_.splice(items_.begin(), items_, it->second);
        return &it->second->second;
    }

    /// Stores `value` under `key` as the most recent (replacing what was
    /// there), then drops the least recent entries beyond the capacity.
    Value& put(const Key& key, Value value) {
        if (const auto it = index_.find(key); it != index_.end()) {
            it->second->second = std::move(value);
            items_.splice(items_.begin(), items_, it->second);
            return it->second->second;
        }
        items_.emplace_front(key, std::move(value));
        index_.emplace(key, items_.begin());
        while (items_.size() > capacity_) {
            index_.erase(items_.back().first);
            items_.pop_back();
        }
        return items_.front().second;
    }

    bool contains(const Key& key) const { return index_.count(key) != 0; }
    std::size_t size() const noexcept { return items_.size(); }
    std::size_t capacity() const noexcept { return capacity_; }

private:
    using Items = std::list<std::pair<Key, Value>>;
    std::size_t capacity_;
    Items items_;  ///< the most recent at the front
    std::unordered_map<Key, typename Items::iterator, Hash> index_;
};

}  // namespace atonlab::runner
