#pragma once
// The files a flight recorder writes: DIR/PREFIX.000001.log, .000002.log, ...
// A file is closed before a line would take it over max_file_bytes and the
// next one opened; beyond max_files the oldest are deleted, but only once the
// newest holds flushed lines: a file that cannot be written (a full disk)
// never pushes a recording out. Numbering goes on from the highest file
// already there, so a restart never overwrites a recording. Lines are never
// split across files. Used by one thread.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/result.hpp"

namespace dh3::bus {

struct RotationOptions {
  std::filesystem::path dir;
  std::string prefix;                       ///< e.g. the bus's name
  std::uint64_t max_file_bytes = 64 << 20;  ///< a single longer line still gets a file
  std::size_t max_files = 10;               ///< at least 1
};

class RotatingLogFile {
 public:
  explicit RotatingLogFile(RotationOptions options);
  ~RotatingLogFile();
  RotatingLogFile(const RotatingLogFile&) = delete;
  RotatingLogFile& operator=(const RotatingLogFile&) = delete;

  /// Appends one line (with its '\n'), opening or rotating files as needed.
  /// Fails with the OS's reason when a file cannot be opened or written: the
  /// file is then cut back to what the last flush() handed over (removed if
  /// that was nothing), and the next call tries again with a fresh file.
  [[nodiscard]] Result<void, std::string> write(std::string_view line);
  /// Hands what was written to the OS, then deletes files beyond max_files;
  /// fails like write().
  [[nodiscard]] Result<void, std::string> flush();

  /// This recorder's files in the directory, oldest first.
  [[nodiscard]] std::vector<std::filesystem::path> files() const;
  /// The file being written; empty before the first line.
  [[nodiscard]] const std::filesystem::path& current() const { return current_; }
  [[nodiscard]] std::uint64_t files_opened() const { return files_opened_; }

 private:
  struct Closer {
    void operator()(std::FILE* file) const { std::fclose(file); }
  };
  [[nodiscard]] Result<void, std::string> open_next();
  /// Gives up the current file after a failed write or flush (see write()).
  [[nodiscard]] Failure<std::string> abandon_current(const std::string& what);
  void delete_oldest();
  /// The number in PREFIX.NUMBER.log, or 0 for other names.
  [[nodiscard]] std::uint64_t number_of(const std::filesystem::path& file) const;

  RotationOptions options_;
  std::unique_ptr<std::FILE, Closer> file_;
  std::filesystem::path current_;
  std::uint64_t bytes_in_file_ = 0;
  std::uint64_t bytes_flushed_ = 0;  ///< of the current file, by the last flush()
  bool prune_due_ = false;           ///< a new file was opened: delete beyond max_files
  std::uint64_t next_number_ = 0;  ///< 0: not yet looked up
  std::uint64_t files_opened_ = 0;
};

}  // namespace dh3::bus
