#include "atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <utility>

#include "errors.hpp"

namespace fl {

namespace {

[[noreturn]] void throwIo(const std::string& what, const std::string& path, int err) {
  throw IoError(what + " '" + path + "': " + std::strerror(err));
}

// Removes the temporary file and throws; errno of the failed call is passed in before cleanup can
// overwrite it.
[[noreturn]] void abandon(int fd, const std::string& tmp, const std::string& path, const char* step, int err) {
  if (fd >= 0) ::close(fd);
  ::unlink(tmp.c_str());
  throw IoError("cannot write '" + path + "': " + step + " of temporary file '" + tmp +
                "' failed: " + std::strerror(err));
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::string& contents) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) abandon(-1, tmp, path, "creation", errno);
  const char* data = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      abandon(fd, tmp, path, "write", errno);
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) abandon(fd, tmp, path, "fsync", errno);
  if (::close(fd) != 0) abandon(-1, tmp, path, "close", errno);
  if (::rename(tmp.c_str(), path.c_str()) != 0) abandon(-1, tmp, path, "rename", errno);

  // The new contents are in place; make the rename itself survive a power loss.
  const std::string parent = std::filesystem::path(path).parent_path().string();
  const std::string dir = parent.empty() ? std::string(".") : parent;
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) throwIo("wrote '" + path + "' but cannot open its directory", dir, errno);
  // Some file systems cannot fsync a directory (EINVAL); the rename is then as durable as they allow.
  if (::fsync(dfd) != 0 && errno != EINVAL) {
    const int err = errno;
    ::close(dfd);
    throwIo("wrote '" + path + "' but cannot fsync its directory", dir, err);
  }
  ::close(dfd);
}

AppendLog::AppendLog(std::string path, const std::string& header) : m_path(std::move(path)) {
  // "a+": writes always go to the end (O_APPEND), and we can read the last byte back.
  m_file = std::fopen(m_path.c_str(), "a+");
  if (!m_file) throwIo("cannot open for appending", m_path, errno);
  struct stat st {};
  if (::fstat(::fileno(m_file), &st) != 0) {
    const int err = errno;
    std::fclose(m_file);
    m_file = nullptr;
    throwIo("cannot stat", m_path, err);
  }
  try {
    // a record the last run did not finish (it was killed inside its write) is dropped: kept, it would be a
    // malformed row, or worse a well-formed one with a number cut short ("2.5" of "2.5e-3")
    const off_t whole = completeLength(st.st_size);
    if (whole < st.st_size && ::ftruncate(::fileno(m_file), whole) != 0) throwIo("cannot truncate", m_path, errno);
    std::fseek(m_file, 0, SEEK_END);  // switching from reading to writing needs a positioning call
    if (whole == 0) writeOrThrow(header.empty() || header.back() != '\n' ? header + '\n' : header);
  } catch (...) {
    std::fclose(m_file);
    m_file = nullptr;
    throw;
  }
}

off_t AppendLog::completeLength(off_t size) {
  // back from the end, a block at a time, to the last newline: the length of the file's complete lines
  char block[4096];
  for (off_t end = size; end > 0;) {
    const off_t begin = end > static_cast<off_t>(sizeof block) ? end - static_cast<off_t>(sizeof block) : 0;
    const auto len = static_cast<std::size_t>(end - begin);
    if (std::fseek(m_file, begin, SEEK_SET) != 0 || std::fread(block, 1, len, m_file) != len)
      throwIo("cannot read back", m_path, errno);
    for (std::size_t k = len; k > 0; --k)
      if (block[k - 1] == '\n') return begin + static_cast<off_t>(k);
    end = begin;
  }
  return 0;
}

AppendLog::~AppendLog() {
  if (m_file) std::fclose(m_file);
}

AppendLog::AppendLog(AppendLog&& other) noexcept
    : m_path(std::move(other.m_path)), m_file(std::exchange(other.m_file, nullptr)) {}

AppendLog& AppendLog::operator=(AppendLog&& other) noexcept {
  if (this != &other) {
    if (m_file) std::fclose(m_file);
    m_path = std::move(other.m_path);
    m_file = std::exchange(other.m_file, nullptr);
  }
  return *this;
}

void AppendLog::append(const std::string& line) {
  if (!m_file) throw IoError("append to a closed log '" + m_path + "'");
  writeOrThrow(!line.empty() && line.back() == '\n' ? line : line + '\n');
}

void AppendLog::writeOrThrow(const std::string& text) {
  // One fwrite per record, then fflush: one write(2). Killed inside it, the kernel may still keep the record's
  // head: it copies a write page by page and stops at a page boundary when a fatal signal is pending (seen in
  // tests/crash: a row cut at byte 237 568 = 58 x 4096). Readers ignore such an unfinished last line
  // (app/report_csv.hpp), and the next AppendLog on this file drops it.
  if (std::fwrite(text.data(), 1, text.size(), m_file) != text.size() || std::fflush(m_file) != 0)
    throwIo("cannot write to", m_path, errno);
}

}  // namespace fl
