// Crash-safe file output.
// writeFileAtomically: a reader (ParaView, a restart, a user's script) sees either the old file or the
// complete new one, never a half-written file, even if the run is killed or the node loses power:
// the contents go to "<path>.tmp.<pid>" in the same directory (rename is atomic only within one file
// system), the file is fsync'ed, renamed over <path>, and the directory is fsync'ed so the rename
// itself is durable. On failure the temporary file is removed and IoError names the path and cause.
// AppendLog: a record-by-record time series. Each append() writes one whole line and fflush'es it, so a
// killed process loses at most its last record, which may be left as an unfinished last line (the kernel
// keeps what was flushed); readers ignore that line and the next AppendLog on the file drops it. No fsync per
// record, which would cost a disk round trip every sample.
#pragma once

#include <sys/types.h>  // off_t

#include <cstdio>
#include <string>

namespace fl {

// Replace <path> by <contents> atomically (see above). Throws IoError naming the path and strerror.
void writeFileAtomically(const std::string& path, const std::string& contents);

class AppendLog {
 public:
  // Opens <path> for appending; a new or empty file first gets <header> as its first line. If an
  // existing file ends in an unfinished line (a run killed inside a write), that line is removed, so every
  // line holds one whole record.
  // Throws IoError naming the path if the file cannot be opened or written.
  AppendLog(std::string path, const std::string& header);
  ~AppendLog();
  AppendLog(const AppendLog&) = delete;
  AppendLog& operator=(const AppendLog&) = delete;
  AppendLog(AppendLog&& other) noexcept;
  AppendLog& operator=(AppendLog&& other) noexcept;

  // Writes <line> plus a newline (unless it already ends in one) and flushes. Throws IoError.
  void append(const std::string& line);
  const std::string& path() const { return m_path; }

 private:
  void writeOrThrow(const std::string& text);
  off_t completeLength(off_t size);  // bytes up to and including the file's last newline

  std::string m_path;
  std::FILE* m_file = nullptr;
};

}  // namespace fl
