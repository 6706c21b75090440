#include "job_store.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

#include "api/json_codec.h"

namespace remeshd {

namespace fs = std::filesystem;
using remesh::api::JobRecord;

namespace {

/// A job document holds text users sent (its filename, sanitised at upload): should any of it not
/// be UTF-8, the bad bytes become U+FFFD instead of an exception (a 500) when it is written.
constexpr auto kReplaceBadUtf8 = nlohmann::json::error_handler_t::replace;

[[noreturn]] void fail(const std::string& what, const fs::path& path) {
  throw std::runtime_error(what + " " + path.string() + ": " + std::strerror(errno));
}

void fsync_dir(const fs::path& dir) {
  int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

std::string random_suffix() {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  return std::to_string(rng());
}

}  // namespace

void write_file_atomic(const fs::path& path, std::string_view bytes) {
  fs::path tmp = path;
  tmp += ".tmp-" + random_suffix();
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail("cannot create", tmp);
  const char* p = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      int saved = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      errno = saved;
      fail("cannot write", tmp);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    ::unlink(tmp.c_str());
    fail("cannot sync", tmp);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    int saved = errno;
    ::unlink(tmp.c_str());
    errno = saved;
    fail("cannot rename to", path);
  }
  fsync_dir(path.parent_path());
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("cannot open", path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

JobStore::JobStore(fs::path data_dir) : root_(std::move(data_dir) / "jobs") {
  std::error_code ec;
  fs::create_directories(root_, ec);
  if (ec || !fs::is_directory(root_))
    throw std::runtime_error("cannot use data directory " + root_.parent_path().string() + ": " + ec.message());
  fs::path lock = root_.parent_path() / "lock";
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0) fail("cannot open", lock);
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock_fd_);
    throw std::runtime_error("data directory " + root_.parent_path().string() +
                             " is in use by another remeshd (lock held on " + lock.string() + ")");
  }
  for (const auto& entry : fs::directory_iterator(root_, ec)) {
    std::string name = entry.path().filename().string();
    if (name.rfind(".tmp-", 0) == 0) fs::remove_all(entry.path(), ec);
  }
  // Leftover temporary files inside job directories (a crash between write and rename).
  for (const auto& entry : fs::directory_iterator(root_, ec)) {
    if (!entry.is_directory()) continue;
    for (const auto& f : fs::directory_iterator(entry.path(), ec))
      if (f.path().filename().string().find(".tmp-") != std::string::npos) fs::remove(f.path(), ec);
  }
}

JobStore::~JobStore() {
  if (lock_fd_ >= 0) ::close(lock_fd_);
}

fs::path JobStore::dir(const std::string& id) const {
  if (!remesh::api::is_valid_job_id(id)) throw std::invalid_argument("invalid job id");
  return root_ / id;
}

void JobStore::create(const JobRecord& job, std::string_view upload) {
  fs::path final_dir = dir(job.id);
  fs::path tmp = root_ / (".tmp-" + job.id);
  std::error_code ec;
  try {
    fs::create_directories(tmp);
    write_file_atomic(tmp / "upload", upload);
    write_file_atomic(tmp / "state.json", remesh::api::job_to_json(job, "/api/v1", job.created_at).dump(-1, ' ', false, kReplaceBadUtf8));
    write_file_atomic(tmp / "stats.jsonl", "");
    fs::rename(tmp, final_dir);
    fsync_dir(root_);
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
}

void JobStore::save_state(const JobRecord& job) {
  write_file_atomic(dir(job.id) / "state.json",
                    remesh::api::job_to_json(job, "/api/v1", remesh::api::now_seconds()).dump(-1, ' ', false, kReplaceBadUtf8));
}

void JobStore::append_stats(const std::string& id, const remesh::IterationStats& row) {
  std::string line = nlohmann::json(row).dump() + "\n";
  fs::path p = dir(id) / "stats.jsonl";
  int fd = ::open(p.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) fail("cannot open", p);
  ssize_t n = ::write(fd, line.data(), line.size());
  int saved = errno;
  ::close(fd);
  errno = saved;
  if (n != static_cast<ssize_t>(line.size())) fail("cannot append to", p);
}

void JobStore::clear_stats(const std::string& id) { write_file_atomic(dir(id) / "stats.jsonl", ""); }

std::optional<double> JobStore::stats_written_at(const std::string& id) const {
  struct stat st {};
  if (::stat((dir(id) / "stats.jsonl").c_str(), &st) != 0) return std::nullopt;
  return static_cast<double>(st.st_mtim.tv_sec) + 1e-9 * static_cast<double>(st.st_mtim.tv_nsec);
}

std::vector<remesh::IterationStats> JobStore::load_stats(const std::string& id) const {
  std::vector<remesh::IterationStats> rows;
  std::ifstream in(dir(id) / "stats.jsonl");
  std::string line;
  while (std::getline(in, line)) {
    auto j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.is_object()) break;  // a torn last line after a crash
    try {
      rows.push_back(j.get<remesh::IterationStats>());
    } catch (const nlohmann::json::exception&) {
      break;
    }
  }
  return rows;
}

std::string JobStore::read_upload(const std::string& id) const {
  // Its message reaches the job's `error` (and a download's answer): the file's name, not the path
  // read_file's message gives.
  try {
    return read_file(dir(id) / "upload");
  } catch (const std::runtime_error&) {
    const int error = errno;  // read_file's, unchanged by the throw
    throw std::runtime_error("the job's stored upload cannot be read (" + std::string(std::strerror(error)) +
                             "): its files in the service's data directory were removed or damaged");
  }
}

fs::path JobStore::file_path(const std::string& id, const std::string& name) const { return dir(id) / name; }

void JobStore::write_file(const std::string& id, const std::string& name, std::string_view bytes) {
  write_file_atomic(dir(id) / name, bytes);
}

void JobStore::remove_results(const std::string& id) {
  std::error_code ec;
  for (const auto& f : fs::directory_iterator(dir(id), ec)) {
    const std::string name = f.path().filename().string();
    if (name.starts_with("remeshed.") || name.starts_with("dual.")) fs::remove(f.path(), ec);
  }
}

void JobStore::remove(const std::string& id) {
  // Renamed away in one step first, then removed: a file being made for the job meanwhile (a
  // download's conversion) can no longer land in its directory. remove_all alone raced with such a
  // write, which made it stop part-way: the directory stayed, at times with its state.json, and the
  // deleted job came back at the next start (QA: 9 of 25 deletes during conversions). What a late
  // writer leaves in the renamed directory (a ".tmp-" entry) goes at the next start.
  std::error_code ec;
  const fs::path gone = root_ / (".tmp-removed-" + id + "-" + random_suffix());
  fs::rename(dir(id), gone, ec);
  fs::remove_all(ec ? dir(id) : gone, ec);  // (when it could not be renamed: gone already, or as before)
}

std::uint64_t JobStore::job_bytes(const std::string& id) const {
  std::uint64_t total = 0;
  std::error_code ec;
  for (const auto& f : fs::directory_iterator(dir(id), ec))
    if (f.is_regular_file(ec)) total += f.file_size(ec);
  return total;
}

std::vector<JobStore::Loaded> JobStore::load_all(std::vector<std::string>& problems) const {
  std::vector<Loaded> jobs;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(root_, ec)) {
    std::string name = entry.path().filename().string();
    if (!entry.is_directory() || !remesh::api::is_valid_job_id(name)) continue;
    try {
      auto j = nlohmann::json::parse(read_file(entry.path() / "state.json"));
      Loaded l{remesh::api::job_from_json(j), load_stats(name)};
      if (l.record.id != name) throw std::runtime_error("id does not match the directory");
      jobs.push_back(std::move(l));
    } catch (const nlohmann::json::parse_error&) {
      // In words, not the JSON library's ("[json.exception.parse_error.101] ...").
      problems.push_back(name + ": its state.json does not parse as JSON (cut short or damaged); the job is not "
                                "loaded, its files are kept");
    } catch (const std::exception& e) {
      problems.push_back(name + ": " + e.what() + "; the job is not loaded, its files are kept");
    }
  }
  return jobs;
}

}  // namespace remeshd
