// atonlab/runner/session/lru_cache.h: the renderer's LRU cache.
#include "atonlab/runner/session/lru_cache.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

using atonlab::runner::LruCache;

TEST(LruCache, FindsWhatWasPut) {
    LruCache<std::string, int> cache(3);
    EXPECT_EQ(cache.find("a"), nullptr);
    cache.put("a", 1);
    cache.put("b", 2);
    ASSERT_NE(cache.find("a"), nullptr);
    EXPECT_EQ(*cache.find("a"), 1);
    EXPECT_EQ(*cache.find("b"), 2);
    EXPECT_EQ(cache.size(), 2u);
}

TEST(LruCache, DropsTheLeastRecentlyUsed) {
    LruCache<std::string, int> cache(2);
    cache.put("a", 1);
    cache.put("b", 2);
    ASSERT_NE(cache.find("a"), nullptr);  // "a" now the most recent: "b" goes next
    cache.put("c", 3);
    EXPECT_TRUE(cache.contains("a"));
    EXPECT_FALSE(cache.contains("b"));
    EXPECT_TRUE(cache.contains("c"));
    EXPECT_EQ(cache.size(), 2u);
    cache.put("d", 4);  // "a" was used before "c" was put: "a" goes
    EXPECT_FALSE(cache.contains("a"));
    EXPECT_TRUE(cache.contains("c"));
    EXPECT_TRUE(cache.contains("d"));
}

TEST(LruCache, PutReplacesAndRefreshes) {
    LruCache<std::string, int> cache(2);
    cache.put("a", 1);
    cache.put("b", 2);
    EXPECT_EQ(cache.put("a", 10), 10);  // replaced, and now the most recent
    cache.put("c", 3);
    EXPECT_EQ(cache.size(), 2u);
    ASSERT_TRUE(cache.contains("a"));
    EXPECT_EQ(*cache.find("a"), 10);
    EXPECT_FALSE(cache.contains("b"));
}

TEST(LruCache, CapacityZeroKeepsOne) {
    LruCache<int, int> cache(0);
    EXPECT_EQ(cache.capacity(), 1u);
    cache.put(1, 1);
    cache.put(2, 2);
    EXPECT_EQ(cache.size(), 1u);
    EXPECT_FALSE(cache.contains(1));
    EXPECT_TRUE(cache.contains(2));
}

TEST(LruCache, ValuesStayValidUntilDropped) {
    LruCache<int, std::shared_ptr<const int>> cache(2);
    const int& one = *cache.put(1, std::make_shared<const int>(1));
    cache.put(2, std::make_shared<const int>(2));
    cache.find(1);
    cache.put(3, std::make_shared<const int>(3));  // drops 2, not 1
    EXPECT_EQ(one, 1);
    EXPECT_EQ(**cache.find(1), 1);
}
