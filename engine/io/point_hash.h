#pragma once
/// \file point_hash.h
/// The hash of a point's exact coordinates, for the corner welders (read_stl.cpp, build_mesh.cpp).
/// Keyed with a random number drawn once per process. An unkeyed mix can be inverted: pick x and
/// y, solve for the bits of z. A file whose corners all share one hash makes every insert walk one
/// bucket chain: an ASCII STL of 200 000 such corners (12 MB) took 67 s to read, quadratically,
/// in the daemon's request handler. Which corners the welders join does not depend on the hash,
/// only how long it takes.

#include <chrono>
#include <cstdint>
#include <exception>
#include <random>

namespace remesh::io {

/// splitmix64's finalizer: a bijection of 64 bits in which every input bit flips about half of
/// the output bits.
inline std::uint64_t mix64(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// The process's key, drawn on first use (from the clock, should the system have no random
/// device: a key an attacker cannot read off the source is all it needs to be).
inline std::uint64_t point_hash_key() {
  static const std::uint64_t key = [] {
    try {
      std::random_device device;
      return (static_cast<std::uint64_t>(device()) << 32) ^ device();
    } catch (const std::exception&) {
      return mix64(static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()));
    }
  }();
  return key;
}

/// The hash of three coordinates given as their bit patterns (normalise -0.0 to 0.0 first).
inline std::uint64_t point_hash(const std::uint64_t bits[3]) {
  std::uint64_t h = point_hash_key();
  for (int i = 0; i < 3; ++i) h = mix64(h ^ bits[i]);
  return h;
}

}  // namespace remesh::io
