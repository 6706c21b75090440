#include "open_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

namespace remeshd {

std::shared_ptr<OpenFile> OpenFile::open(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return nullptr;
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return nullptr;
  }
  return std::shared_ptr<OpenFile>(new OpenFile(fd, static_cast<std::size_t>(st.st_size)));
}

OpenFile::~OpenFile() { ::close(fd_); }

long OpenFile::read(std::size_t offset, char* out, std::size_t n) const {
  ssize_t got;
  do got = ::pread(fd_, out, n, static_cast<off_t>(offset));
  while (got < 0 && errno == EINTR);
  return static_cast<long>(got);
}

}  // namespace remeshd
