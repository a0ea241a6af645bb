#pragma once
// A bus's flight recorder: every frame the bus sends and receives, with its
// time and direction, in can-utils' candump log format (candump_log.hpp), into
// rotating files (rotating_log_file.hpp). The bus loop only pushes into a
// bounded lock-free queue (frame_queue.hpp); a writer thread of its own formats
// and writes. When the writer falls behind (a slow disk), frames are dropped,
// counted (figures()) and said in the log, never waited for. When a file
// cannot be written (a full disk), recording stops: said once in the log and
// in figures().stopped, frames counted as dropped, no recording deleted; the
// writer tries again every retry_interval and says when it records again.

#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "dh3/base/clock.hpp"
#include "dh3/base/result.hpp"
#include "dh3/bus/bus.hpp"
#include "dh3/bus/candump_log.hpp"
#include "dh3/bus/frame_queue.hpp"
#include "dh3/bus/rotating_log_file.hpp"

namespace dh3::bus {

struct RecorderOptions {
  std::filesystem::path dir;                ///< created if missing
  std::uint64_t max_file_bytes = 64 << 20;  ///< then the next file
  std::size_t max_files = 10;               ///< then the oldest is deleted
  /// Frames the queue holds for the writer: several seconds of a saturated
  /// 1 Mbit/s line (about 8000 frames/s) between two drains.
  std::size_t queue_capacity = 1 << 16;
  /// How often the writer drains the queue and flushes the file.
  Duration drain_interval = std::chrono::milliseconds(50);
  /// How often a recorder stopped by a write error tries to write again.
  Duration retry_interval = std::chrono::seconds(1);

  friend bool operator==(const RecorderOptions&, const RecorderOptions&) = default;
};

class FrameRecorder {
 public:
  /// Records bus `bus_name` into options.dir as BUS.000001.log, ... (the name
  /// made file- and log-safe by log_device_name()). Fails if the directory
  /// cannot be created or is not writable, so a wrong path stops the start.
  [[nodiscard]] static Result<std::unique_ptr<FrameRecorder>, std::string> start(
      const std::string& bus_name, RecorderOptions options);
  /// Writes what is queued, then stops the writer.
  ~FrameRecorder();
  FrameRecorder(const FrameRecorder&) = delete;
  FrameRecorder& operator=(const FrameRecorder&) = delete;

  /// The bus loop's thread only. Never blocks.
  void record(FrameDirection direction, const CanFrame& frame, WallTime time);

  /// Any thread.
  [[nodiscard]] RecorderFigures figures() const;
  /// The bus's name as the log and the file names have it.
  [[nodiscard]] const std::string& device() const { return device_; }

 private:
  FrameRecorder(std::string device, RecorderOptions options);
  void run();
  /// Writes what the queue holds; the writer thread only.
  void drain();
  /// Writes batch_ into the file; how many frames went in, `failure` set if not all.
  std::size_t write_batch(std::optional<std::string>& failure);
  /// After a drain that wrote: counts what the flush made safe or what the
  /// failure lost, and stops or resumes recording.
  void settle(const std::optional<std::string>& failure, TimePoint now);
  void report_drops(TimePoint now, bool force);

  std::string device_;
  RecorderOptions options_;
  FrameQueue queue_;
  RotatingLogFile file_;  // writer thread only
  std::vector<LoggedFrame> batch_;
  std::atomic<std::uint64_t> frames_recorded_{0};
  std::atomic<std::uint64_t> frames_unwritten_{0};  ///< lost to write errors
  std::atomic<std::uint64_t> bytes_written_{0};
  std::atomic<std::uint64_t> files_opened_{0};
  std::atomic<std::uint64_t> write_errors_{0};
  std::atomic<bool> stopped_{false};  ///< by a write error, until a write succeeds
  // Written into the file since its last flush: recorded once a flush succeeds.
  std::uint64_t unflushed_frames_ = 0;
  std::uint64_t unflushed_bytes_ = 0;
  TimePoint last_attempt_{};  ///< while stopped_: the last try to write
  std::uint64_t drops_reported_ = 0;
  std::optional<TimePoint> last_drop_report_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread writer_;
};

}  // namespace dh3::bus
