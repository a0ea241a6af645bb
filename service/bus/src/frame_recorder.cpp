#include "dh3/bus/frame_recorder.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

namespace dh3::bus {
namespace {

/// Frames the writer formats between two looks at the stop flag.
constexpr std::size_t kBatch = 4096;
/// Drops and write errors are logged at most this often (with their totals).
constexpr Duration kReportInterval = std::chrono::seconds(10);

bool due(const std::optional<TimePoint>& last, TimePoint now) {
  return !last || now - *last >= kReportInterval;
}

}  // namespace

Result<std::unique_ptr<FrameRecorder>, std::string> FrameRecorder::start(
    const std::string& bus_name, RecorderOptions options) {
  if (options.dir.empty()) return fail(std::string("no directory to record into"));
  std::error_code error;
  std::filesystem::create_directories(options.dir, error);
  if (error) return fail("cannot create " + options.dir.string() + ": " + error.message());
  if (::access(options.dir.c_str(), W_OK | X_OK) != 0) {
    return fail("cannot write into " + options.dir.string() + ": " + std::strerror(errno));
  }
  std::unique_ptr<FrameRecorder> recorder(
      new FrameRecorder(log_device_name(bus_name), std::move(options)));
  recorder->writer_ = std::thread([raw = recorder.get()] { raw->run(); });
  return recorder;
}

FrameRecorder::FrameRecorder(std::string device, RecorderOptions options)
    : device_(std::move(device)),
      options_(std::move(options)),
      queue_(options_.queue_capacity),
      file_(RotationOptions{options_.dir, device_, options_.max_file_bytes, options_.max_files}) {
  batch_.reserve(kBatch);
}

FrameRecorder::~FrameRecorder() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (writer_.joinable()) writer_.join();
}

void FrameRecorder::record(FrameDirection direction, const CanFrame& frame, WallTime time) {
  queue_.push(LoggedFrame{time, direction, frame});
}

RecorderFigures FrameRecorder::figures() const {
  RecorderFigures out;
  out.frames_recorded = frames_recorded_.load(std::memory_order_relaxed);
  out.frames_dropped = queue_.dropped() + frames_unwritten_.load(std::memory_order_relaxed);
  out.bytes_written = bytes_written_.load(std::memory_order_relaxed);
  out.files_opened = files_opened_.load(std::memory_order_relaxed);
  out.write_errors = write_errors_.load(std::memory_order_relaxed);
  return out;
}

void FrameRecorder::run() {
  for (;;) {
    bool stop = false;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, options_.drain_interval, [this] { return stopping_; });
      stop = stopping_;
    }
    drain();  // also after the stop: what the bus handed over is written
    report_drops(SteadyClock::now(), stop);  // the last total is always said
    if (stop) return;
  }
}

void FrameRecorder::drain() {
  for (;;) {
    batch_.clear();
    if (queue_.pop(batch_, kBatch) == 0) break;
    std::size_t written = 0;
    std::string failure;
    for (const LoggedFrame& frame : batch_) {
      const std::string line = format_log_line(frame, device_);
      if (auto done = file_.write(line); !done) {
        failure = done.error();
        break;
      }
      ++written;
      bytes_written_.fetch_add(line.size(), std::memory_order_relaxed);
    }
    frames_recorded_.fetch_add(written, std::memory_order_relaxed);
    if (written < batch_.size()) {
      // The rest of the batch is lost with the file; the next batch tries a new one.
      frames_unwritten_.fetch_add(batch_.size() - written, std::memory_order_relaxed);
      write_errors_.fetch_add(1, std::memory_order_relaxed);
      const TimePoint now = SteadyClock::now();
      if (due(last_error_report_, now)) {
        spdlog::error("bus {}: flight recorder: {}; {} frames lost", device_, failure,
                      batch_.size() - written);
        last_error_report_ = now;
      }
    }
  }
  if (auto flushed = file_.flush(); !flushed) {
    write_errors_.fetch_add(1, std::memory_order_relaxed);
    const TimePoint now = SteadyClock::now();
    if (due(last_error_report_, now)) {
      spdlog::error("bus {}: flight recorder: {}", device_, flushed.error());
      last_error_report_ = now;
    }
  }
  files_opened_.store(file_.files_opened(), std::memory_order_relaxed);
}

void FrameRecorder::report_drops(TimePoint now, bool force) {
  const std::uint64_t dropped = queue_.dropped();
  if (dropped == drops_reported_ || !(force || due(last_drop_report_, now))) return;
  spdlog::warn("bus {}: flight recorder dropped {} frames: its writer fell behind the bus ({} "
               "in all)",
               device_, dropped - drops_reported_, dropped);
  drops_reported_ = dropped;
  last_drop_report_ = now;
}

}  // namespace dh3::bus
