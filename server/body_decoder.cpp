#include "body_decoder.h"

#include <brotli/decode.h>
#include <zlib.h>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace remeshd {

struct BodyDecoder::Impl {
  enum class Kind { Gzip, Deflate, Brotli } kind;
  z_stream z{};
  BrotliDecoderState* brotli = nullptr;
  bool ended = false;  ///< the current stream (gzip: member) is complete
  std::array<unsigned char, 16384> out{};

  bool feed_zlib(const char* data, std::size_t n, const Sink& sink) {
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data));
    z.avail_in = static_cast<uInt>(n);
    bool full = false;  // the last call filled the output: inflate may hold more back
    for (;;) {
      if (ended && z.avail_in > 0) {
        // Bytes after the end: another gzip member (RFC 1952 2.2), or zeros padding it (as GNU gzip
        // takes them: tape blocks); else not the coding.
        if (kind != Kind::Gzip) return false;
        while (z.avail_in > 0 && *z.next_in == 0) ++z.next_in, --z.avail_in;
        if (z.avail_in > 0) {
          if (inflateReset(&z) != Z_OK) return false;
          ended = false;
        }
      }
      if (ended || (z.avail_in == 0 && !full)) return true;
      z.next_out = out.data();
      z.avail_out = static_cast<uInt>(out.size());
      const uInt before = z.avail_in;
      const int r = inflate(&z, Z_NO_FLUSH);
      if (r != Z_OK && r != Z_STREAM_END && r != Z_BUF_ERROR) return false;  // data, dictionary, memory
      const std::size_t made = out.size() - z.avail_out;
      if (made > 0 && !sink(reinterpret_cast<const char*>(out.data()), made)) return false;
      ended = r == Z_STREAM_END;
      full = z.avail_out == 0;
      // No progress: all input taken and nothing held back (more input needed), else never.
      if (!ended && made == 0 && z.avail_in == before) return z.avail_in == 0;
    }
  }

  bool feed_brotli(const char* data, std::size_t n, const Sink& sink) {
    const std::uint8_t* in = reinterpret_cast<const std::uint8_t*>(data);
    std::size_t available = n;
    if (ended) return n == 0;
    for (;;) {
      std::uint8_t* next = out.data();
      std::size_t room = out.size();
      const BrotliDecoderResult r = BrotliDecoderDecompressStream(brotli, &available, &in, &room, &next, nullptr);
      const std::size_t made = out.size() - room;
      if (made > 0 && !sink(reinterpret_cast<const char*>(out.data()), made)) return false;
      switch (r) {
        case BROTLI_DECODER_RESULT_ERROR: return false;
        case BROTLI_DECODER_RESULT_SUCCESS: ended = true; return available == 0;
        case BROTLI_DECODER_RESULT_NEEDS_MORE_INPUT: return true;
        case BROTLI_DECODER_RESULT_NEEDS_MORE_OUTPUT: break;
      }
    }
  }
};

BodyDecoder::BodyDecoder(std::string_view coding) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  if (coding == "gzip" || coding == "deflate") {
    m.kind = coding == "gzip" ? Impl::Kind::Gzip : Impl::Kind::Deflate;
    if (inflateInit2(&m.z, 32 + MAX_WBITS) != Z_OK) throw std::runtime_error("zlib: inflateInit2 failed");
  } else if (coding == "br") {
    m.kind = Impl::Kind::Brotli;
    m.brotli = BrotliDecoderCreateInstance(nullptr, nullptr, nullptr);
    if (!m.brotli) throw std::runtime_error("brotli: no decoder");
  } else {
    throw std::invalid_argument("no decoder for Content-Encoding '" + std::string(coding) + "'");
  }
}

BodyDecoder::~BodyDecoder() {
  if (impl_->kind == Impl::Kind::Brotli) BrotliDecoderDestroyInstance(impl_->brotli);
  else inflateEnd(&impl_->z);
}

bool BodyDecoder::feed(const char* data, std::size_t n, const Sink& sink) {
  return impl_->kind == Impl::Kind::Brotli ? impl_->feed_brotli(data, n, sink) : impl_->feed_zlib(data, n, sink);
}

bool BodyDecoder::complete() const { return impl_->ended; }

}  // namespace remeshd
