#include <catch2/catch.hpp>

#include <atomic>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "core/parallel.h"

using remesh::parallel_blocks;
using remesh::parallel_for;

TEST_CASE("parallel_for visits every index exactly once", "[core][parallel]") {
  for (unsigned threads : {1u, 2u, 7u}) {
    for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1023}, std::size_t{5000}}) {
      std::vector<std::atomic<int>> hits(n);
      parallel_for(n, threads, [&](std::size_t i) { hits[i]++; }, 64);
      for (std::size_t i = 0; i < n; ++i) REQUIRE(hits[i] == 1);
    }
  }
}

TEST_CASE("block boundaries do not depend on the thread count", "[core][parallel]") {
  const std::size_t n = 10'000, block = 333;
  std::vector<double> values(n);
  for (std::size_t i = 0; i < n; ++i) values[i] = 1.0 / double(i + 1);
  auto blocked_sum = [&](unsigned threads) {
    std::vector<double> partial(remesh::block_count(n, block), 0.0);
    parallel_blocks(n, block, threads, [&](std::size_t b, std::size_t e, std::size_t k) {
      for (std::size_t i = b; i < e; ++i) partial[k] += values[i];
    });
    return std::accumulate(partial.begin(), partial.end(), 0.0);
  };
  const double one = blocked_sum(1);
  REQUIRE(blocked_sum(2) == one);  // bit-identical, not approximately equal
  REQUIRE(blocked_sum(5) == one);
}

TEST_CASE("an exception in a body reaches the caller", "[core][parallel]") {
  REQUIRE_THROWS_AS(parallel_for(100, 2, [](std::size_t i) {
                      if (i == 57) throw std::runtime_error("boom");
                    }, 8),
                    std::runtime_error);
}
