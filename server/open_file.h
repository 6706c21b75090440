#pragma once
/// \file open_file.h
/// A file opened for a download, read piece by piece as the client takes it. Serving a result from
/// a copy in memory cost its whole size per download while the client read (QA: 40 downloads of a
/// 20 MB dual opened and not read took the daemon from 27 to 764 MB, and 178 MB stayed after they
/// closed). The open file also keeps its bytes when the job is removed meanwhile (its files are
/// unlinked, not overwritten: every file is written to a temporary name and renamed).

#include <cstddef>
#include <filesystem>
#include <memory>

namespace remeshd {

class OpenFile {
 public:
  /// The file opened for reading, or nullptr when it cannot be (missing, a directory, no access).
  static std::shared_ptr<OpenFile> open(const std::filesystem::path& path);
  ~OpenFile();
  OpenFile(const OpenFile&) = delete;
  OpenFile& operator=(const OpenFile&) = delete;

  /// Its size when opened.
  std::size_t size() const { return size_; }
  /// Reads up to `n` bytes from `offset` into `out`; the count read (0 at or past the end), or -1
  /// on an error.
  long read(std::size_t offset, char* out, std::size_t n) const;

 private:
  OpenFile(int fd, std::size_t size) : fd_(fd), size_(size) {}
  int fd_;
  std::size_t size_;
};

}  // namespace remeshd
