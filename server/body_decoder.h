#pragma once
/// \file body_decoder.h
/// A request body's Content-Encoding undone as it arrives, and its end checked. cpp-httplib 0.11
/// decodes gzip, deflate and br itself but never asks whether the coded stream ended: a body cut
/// off at a flush point was taken for a whole, smaller mesh (QA: a gzip body cut in two gave a job
/// of 100 of its 320 faces, with a hole). The service decodes a raw upload's body with this instead
/// and refuses one whose stream did not end (a multipart body cut off loses its closing boundary,
/// which httplib's parser refuses).

#include <cstddef>
#include <functional>
#include <memory>
#include <string_view>

namespace remeshd {

class BodyDecoder {
 public:
  /// Receives decoded bytes; returns false to stop decoding.
  using Sink = std::function<bool(const char*, std::size_t)>;

  /// `coding`: "gzip" (one or more members, zero bytes after them ignored) or "deflate" (zlib's format; either header is
  /// recognised, as by httplib), or "br". Throws std::invalid_argument for any other.
  explicit BodyDecoder(std::string_view coding);
  ~BodyDecoder();
  BodyDecoder(const BodyDecoder&) = delete;
  BodyDecoder& operator=(const BodyDecoder&) = delete;

  /// Decodes the next `n` coded bytes into `sink`. False when they are not valid for the coding
  /// (bytes after the end included) or the sink stopped.
  bool feed(const char* data, std::size_t n, const Sink& sink);
  /// Whether the coded stream has ended: its last member or block is complete.
  bool complete() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace remeshd
