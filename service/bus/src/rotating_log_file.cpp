#include "dh3/bus/rotating_log_file.hpp"

#include <fmt/format.h>
#include <stdio_ext.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <system_error>

namespace dh3::bus {
namespace {

constexpr std::string_view kSuffix = ".log";

}  // namespace

RotatingLogFile::RotatingLogFile(RotationOptions options) : options_(std::move(options)) {
  options_.max_files = std::max<std::size_t>(options_.max_files, 1);
}

RotatingLogFile::~RotatingLogFile() = default;

std::uint64_t RotatingLogFile::number_of(const std::filesystem::path& file) const {
  const std::string name = file.filename().string();
  const std::string head = options_.prefix + ".";
  if (name.size() <= head.size() + kSuffix.size() || name.rfind(head, 0) != 0 ||
      name.compare(name.size() - kSuffix.size(), kSuffix.size(), kSuffix) != 0) {
    return 0;
  }
  const char* begin = name.data() + head.size();
  const char* end = name.data() + name.size() - kSuffix.size();
  std::uint64_t number = 0;
  const auto [stop, error] = std::from_chars(begin, end, number);
  return (error == std::errc{} && stop == end) ? number : 0;
}

std::vector<std::filesystem::path> RotatingLogFile::files() const {
  std::vector<std::pair<std::uint64_t, std::filesystem::path>> numbered;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(options_.dir, error)) {
    if (const std::uint64_t number = number_of(entry.path()); number > 0) {
      numbered.emplace_back(number, entry.path());
    }
  }
  std::sort(numbered.begin(), numbered.end());
  std::vector<std::filesystem::path> out;
  for (auto& [number, path] : numbered) out.push_back(std::move(path));
  return out;
}

Result<void, std::string> RotatingLogFile::open_next() {
  file_.reset();
  std::error_code error;
  std::filesystem::create_directories(options_.dir, error);
  if (error) return fail("cannot create " + options_.dir.string() + ": " + error.message());
  if (next_number_ == 0) {
    const auto existing = files();
    next_number_ = existing.empty() ? 1 : number_of(existing.back()) + 1;
  }
  current_ = options_.dir / fmt::format("{}.{:06}{}", options_.prefix, next_number_++, kSuffix);
  // "x": a file that is there (a clock or a second recorder) is not overwritten.
  file_.reset(std::fopen(current_.c_str(), "wx"));
  if (!file_) return fail("cannot create " + current_.string() + ": " + std::strerror(errno));
  bytes_in_file_ = 0;
  bytes_flushed_ = 0;
  prune_due_ = true;
  ++files_opened_;
  return {};
}

Failure<std::string> RotatingLogFile::abandon_current(const std::string& what) {
  const std::string reason = std::strerror(errno);
  // What stdio still buffers would be written again at the close; the file
  // keeps the whole lines the last flush handed over, and a file with none
  // is ours and empty, no recording.
  __fpurge(file_.get());
  std::error_code ignored;
  if (bytes_flushed_ == 0) {
    std::filesystem::remove(current_, ignored);
  } else {
    // Should the cut fail, the file ends in part of a line, which readers of
    // candump logs skip; the lines before it stay.
    [[maybe_unused]] const int cut =
        ::ftruncate(::fileno(file_.get()), static_cast<off_t>(bytes_flushed_));
  }
  file_.reset();
  return fail(what + " " + current_.string() + ": " + reason);
}

void RotatingLogFile::delete_oldest() {
  auto existing = files();
  std::error_code error;
  for (std::size_t i = 0; i + options_.max_files < existing.size(); ++i) {
    std::filesystem::remove(existing[i], error);
  }
}

Result<void, std::string> RotatingLogFile::write(std::string_view line) {
  const bool full = bytes_in_file_ > 0 && bytes_in_file_ + line.size() > options_.max_file_bytes;
  if (file_ && full) {
    if (auto flushed = flush(); !flushed) return flushed;
  }
  if (!file_ || full) {
    if (auto opened = open_next(); !opened) return opened;
  }
  if (std::fwrite(line.data(), 1, line.size(), file_.get()) != line.size()) {
    return abandon_current("cannot write");
  }
  bytes_in_file_ += line.size();
  return {};
}

Result<void, std::string> RotatingLogFile::flush() {
  if (!file_) return {};
  if (std::fflush(file_.get()) != 0) return abandon_current("cannot write");
  bytes_flushed_ = bytes_in_file_;
  if (prune_due_ && bytes_flushed_ > 0) {
    prune_due_ = false;
    delete_oldest();
  }
  return {};
}

}  // namespace dh3::bus
