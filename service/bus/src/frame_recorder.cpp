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
/// Drops are logged at most this often (with their totals).
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
  out.stopped = stopped_.load(std::memory_order_relaxed);
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
  const TimePoint now = SteadyClock::now();
  // Stopped, the writer tries again only now and then: each try may open a file.
  const bool writing = !stopped_.load(std::memory_order_relaxed) ||
                       now - last_attempt_ >= options_.retry_interval;
  std::optional<std::string> failure;
  bool wrote = false;
  for (;;) {
    batch_.clear();
    if (queue_.pop(batch_, kBatch) == 0) break;
    std::size_t written = 0;
    if (writing && !failure) {
      written = write_batch(failure);
      wrote = true;
    }
    frames_unwritten_.fetch_add(batch_.size() - written, std::memory_order_relaxed);
  }
  if (writing && !failure) {
    if (auto flushed = file_.flush(); !flushed) failure = flushed.error();
  }
  // A stopped recorder resumes only on a write that succeeded, not on an idle bus.
  if (failure || (wrote && writing)) settle(failure, now);
  files_opened_.store(file_.files_opened(), std::memory_order_relaxed);
}

std::size_t FrameRecorder::write_batch(std::optional<std::string>& failure) {
  std::size_t written = 0;
  for (const LoggedFrame& frame : batch_) {
    const std::string line = format_log_line(frame, device_);
    if (auto done = file_.write(line); !done) {
      failure = done.error();
      break;
    }
    ++written;
    unflushed_bytes_ += line.size();
  }
  unflushed_frames_ += written;
  return written;
}

void FrameRecorder::settle(const std::optional<std::string>& failure, TimePoint now) {
  if (failure) {
    // The file was cut back to its last flush: what was written since is lost.
    frames_unwritten_.fetch_add(unflushed_frames_, std::memory_order_relaxed);
    write_errors_.fetch_add(1, std::memory_order_relaxed);
    last_attempt_ = now;
    if (!stopped_.exchange(true)) {
      spdlog::error(
          "bus {}: flight recorder stopped: {}; frames go unrecorded and no recording is "
          "deleted until a write succeeds again (tried every {} ms)",
          device_, *failure,
          std::chrono::duration_cast<std::chrono::milliseconds>(options_.retry_interval).count());
    }
  } else {
    frames_recorded_.fetch_add(unflushed_frames_, std::memory_order_relaxed);
    bytes_written_.fetch_add(unflushed_bytes_, std::memory_order_relaxed);
    if (stopped_.exchange(false)) {
      spdlog::info("bus {}: flight recorder records again, into {} ({} frames went unrecorded "
                   "in all)",
                   device_, file_.current().string(), figures().frames_dropped);
    }
  }
  unflushed_frames_ = 0;
  unflushed_bytes_ = 0;
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
