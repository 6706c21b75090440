// Reading from several threads at once gives the same meshes as reading alone.
#include <catch2/catch.hpp>

#include <atomic>
#include <thread>

#include "io/mesh_io.h"
#include "io_test_util.h"
#include "support/mesh_generators.h"

using namespace remesh;

TEST_CASE("PLY, OBJ and glTF are read from 4 threads at once") {
  const PolygonSoup soup = to_soup(test::make_icosphere(4));
  const std::vector<std::string> files = {write_mesh(soup, Format::Ply), test::write_ply_ascii(soup),
                                          write_mesh(soup, Format::Obj), write_mesh(soup, Format::Glb)};
  std::vector<PolygonSoup> expected;
  for (const auto& f : files) expected.push_back(to_soup(read_mesh(f).mesh));
  std::atomic<int> mismatches{0}, failures{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int round = 0; round < 6; ++round) {
        const std::size_t i = static_cast<std::size_t>(t + round) % files.size();
        try {
          PolygonSoup got = to_soup(read_mesh(files[i]).mesh);
          if (got.points != expected[i].points || got.indices != expected[i].indices) ++mismatches;
        } catch (...) {
          ++failures;
        }
      }
    });
  for (auto& th : threads) th.join();
  CHECK(failures == 0);
  CHECK(mismatches == 0);
}
