// The flight recorder's parts: the queue between a bus loop and the writer
// (drops counted, never waits), the rotating files, the recorder writing candump
// lines, and RecordingBus taking every frame a backend sends and receives.

#include <gtest/gtest.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "dh3/bus/frame_queue.hpp"
#include "dh3/bus/frame_recorder.hpp"
#include "dh3/bus/recording_bus.hpp"
#include "dh3/bus/rotating_log_file.hpp"

namespace dh3::bus {
namespace {

namespace fs = std::filesystem;

LoggedFrame numbered(std::uint32_t n) {
  return LoggedFrame{WallTime(std::chrono::seconds(n)), FrameDirection::sent,
                     CanFrame{n & 0xFF, 8, {}}};
}

/// A fresh directory under the test's temporary directory, removed at the end.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "dh3-recorder-XXXXXX").string();
    path_ = ::mkdtemp(pattern.data());
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::vector<std::string> lines_of(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(FrameQueue, FramesComeOutInTheOrderTheyWentIn) {
  FrameQueue queue(8);
  for (std::uint32_t n = 1; n <= 5; ++n) ASSERT_TRUE(queue.push(numbered(n)));
  std::vector<LoggedFrame> out;
  EXPECT_EQ(queue.pop(out, 3), 3u);
  EXPECT_EQ(queue.pop(out, 100), 2u);
  ASSERT_EQ(out.size(), 5u);
  for (std::uint32_t n = 1; n <= 5; ++n) EXPECT_EQ(out[n - 1].frame.id, n);
  EXPECT_EQ(queue.dropped(), 0u);
}

TEST(FrameQueue, AFullQueueDropsAndCountsInsteadOfWaiting) {
  FrameQueue queue(4);
  ASSERT_EQ(queue.capacity(), 4u);
  for (std::uint32_t n = 1; n <= 4; ++n) EXPECT_TRUE(queue.push(numbered(n)));
  EXPECT_FALSE(queue.push(numbered(5)));
  EXPECT_FALSE(queue.push(numbered(6)));
  EXPECT_EQ(queue.dropped(), 2u);
  std::vector<LoggedFrame> out;
  EXPECT_EQ(queue.pop(out, 1), 1u);
  EXPECT_TRUE(queue.push(numbered(7)));  // room again after a pop
  out.clear();
  queue.pop(out, 100);
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out.front().frame.id, 2u);
  EXPECT_EQ(out.back().frame.id, 7u);
  EXPECT_EQ(queue.dropped(), 2u);
}

TEST(FrameQueue, CapacityIsRoundedUpToAPowerOfTwo) {
  EXPECT_EQ(FrameQueue(5).capacity(), 8u);
  EXPECT_EQ(FrameQueue(0).capacity(), 2u);
}

TEST(FrameQueue, OneProducerAndOneConsumerLoseNothingThatFits) {
  FrameQueue queue(1024);
  constexpr std::uint32_t kFrames = 200000;
  std::uint64_t pushed = 0;
  std::thread producer([&] {
    for (std::uint32_t n = 0; n < kFrames; ++n) pushed += queue.push(numbered(n)) ? 1 : 0;
  });
  std::vector<LoggedFrame> out;
  std::uint64_t popped = 0;
  std::int64_t last = -1;
  bool ordered = true;
  while (popped + queue.dropped() < kFrames) {
    out.clear();
    popped += queue.pop(out, 256);
    for (const LoggedFrame& frame : out) {
      const std::int64_t n = frame.time.time_since_epoch() / std::chrono::seconds(1);
      if (n <= last) ordered = false;
      last = n;
    }
  }
  producer.join();
  EXPECT_EQ(popped, pushed);
  EXPECT_EQ(pushed + queue.dropped(), kFrames);
  EXPECT_TRUE(ordered);
}

TEST(RotatingLogFile, StartsANewFileBeforeALineWouldPassTheCap) {
  TempDir dir;
  RotatingLogFile file({dir.path(), "bus0", 30, 10});
  const std::string line = "0123456789\n";  // 11 bytes: two fit in 30, three do not
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(file.write(line));
  ASSERT_TRUE(file.flush());
  const auto files = file.files();
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(files[0].filename(), "bus0.000001.log");
  EXPECT_EQ(files[2].filename(), "bus0.000003.log");
  EXPECT_EQ(file.current(), files[2]);
  EXPECT_EQ(lines_of(files[0]).size(), 2u);
  EXPECT_EQ(lines_of(files[1]).size(), 2u);
  EXPECT_EQ(lines_of(files[2]).size(), 1u);
  EXPECT_EQ(file.files_opened(), 3u);
}

TEST(RotatingLogFile, KeepsOnlyTheNewestFiles) {
  TempDir dir;
  RotatingLogFile file({dir.path(), "bus0", 10, 2});
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(file.write("line " + std::to_string(i) + "\n"));
  ASSERT_TRUE(file.flush());
  const auto files = file.files();
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0].filename(), "bus0.000004.log");
  EXPECT_EQ(lines_of(files[1]), std::vector<std::string>{"line 4"});
}

TEST(RotatingLogFile, ARestartGoesOnAfterTheLastFileAndLeavesOtherBusesAlone) {
  TempDir dir;
  {
    RotatingLogFile first({dir.path(), "bus0", 1000, 10});
    ASSERT_TRUE(first.write("first run\n"));
    RotatingLogFile other({dir.path(), "bus1", 1000, 1});
    ASSERT_TRUE(other.write("other bus\n"));
  }
  RotatingLogFile second({dir.path(), "bus0", 1000, 10});
  ASSERT_TRUE(second.write("second run\n"));
  ASSERT_TRUE(second.flush());
  const auto files = second.files();
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(lines_of(files[0]), std::vector<std::string>{"first run"});
  EXPECT_EQ(lines_of(files[1]), std::vector<std::string>{"second run"});
  EXPECT_TRUE(fs::exists(dir.path() / "bus1.000001.log"));
}

TEST(RotatingLogFile, AnUnwritableDirectoryFailsWithItsName) {
  RotatingLogFile file({"/proc/dh3-no-such-dir", "bus0", 1000, 10});
  const auto written = file.write("x\n");
  ASSERT_FALSE(written);
  EXPECT_NE(written.error().find("/proc/dh3-no-such-dir"), std::string::npos) << written.error();
}

TEST(FrameRecorder, WritesEveryFrameAsACandumpLineInOrder) {
  TempDir dir;
  auto recorder = FrameRecorder::start("left bus", RecorderOptions{dir.path()});
  ASSERT_TRUE(recorder) << recorder.error();
  const CanFrame frame{1, 8, {0x06, 0x02, 0x01, 0, 0x3C, 0, 0, 0}};
  (*recorder)->record(FrameDirection::sent, frame, WallTime(std::chrono::microseconds(1'500'000)));
  (*recorder)->record(FrameDirection::received, frame,
                      WallTime(std::chrono::microseconds(1'500'900)));
  EXPECT_EQ((*recorder)->device(), "left_bus");
  recorder->reset();  // writes what is queued
  const RotatingLogFile written({dir.path(), "left_bus", 1000, 10});
  const auto files = written.files();
  ASSERT_EQ(files.size(), 1u);
  EXPECT_EQ(lines_of(files[0]),
            (std::vector<std::string>{"(0000000001.500000) left_bus 001#060201003C000000 T",
                                      "(0000000001.500900) left_bus 001#060201003C000000 R"}));
}

TEST(FrameRecorder, FiguresCountWhatWasWrittenAndWhatTheQueueDropped) {
  TempDir dir;
  RecorderOptions options{dir.path()};
  options.queue_capacity = 4;
  options.drain_interval = std::chrono::hours(1);  // the writer drains only at the stop
  auto recorder = FrameRecorder::start("bus0", options);
  ASSERT_TRUE(recorder) << recorder.error();
  for (std::uint32_t n = 1; n <= 10; ++n) {
    (*recorder)->record(FrameDirection::sent, CanFrame{n, 8, {}}, WallTime{});
  }
  EXPECT_EQ((*recorder)->figures().frames_dropped, 6u);
  const fs::path file = dir.path() / "bus0.000001.log";
  recorder->reset();
  EXPECT_EQ(lines_of(file).size(), 4u);
}

TEST(FrameRecorder, ADirectoryThatCannotBeMadeStopsTheStart) {
  const auto recorder = FrameRecorder::start("bus0", RecorderOptions{"/proc/dh3-no-such-dir"});
  ASSERT_FALSE(recorder);
  EXPECT_NE(recorder.error().find("/proc/dh3-no-such-dir"), std::string::npos);
}

/// A tmpfs of a few KiB mounted on a fresh directory, unmounted at the end.
class SmallTmpfs {
 public:
  explicit SmallTmpfs(const std::string& size) {
    const std::string options = "size=" + size;
    if (::mount("tmpfs", dir_.path().c_str(), "tmpfs", 0, options.c_str()) == 0) {
      mounted_ = true;
    } else {
      refused_ = std::strerror(errno);
    }
  }
  ~SmallTmpfs() {
    if (mounted_) ::umount2(dir_.path().c_str(), MNT_DETACH);
  }
  SmallTmpfs(const SmallTmpfs&) = delete;
  SmallTmpfs& operator=(const SmallTmpfs&) = delete;
  [[nodiscard]] bool mounted() const { return mounted_; }
  [[nodiscard]] const std::string& refused() const { return refused_; }
  [[nodiscard]] const fs::path& path() const { return dir_.path(); }

 private:
  TempDir dir_;
  bool mounted_ = false;
  std::string refused_;
};

/// Every recording file with its size, by name.
std::map<fs::path, std::uintmax_t> recordings(const fs::path& dir) {
  std::map<fs::path, std::uintmax_t> out;
  for (const fs::path& file : RotatingLogFile({dir, "bus0", 1, 1}).files()) {
    out[file.filename()] = fs::file_size(file);
  }
  return out;
}

/// Records numbered frames, a few at a time, until `done` (false after 30 s).
template <typename Done>
bool record_until(FrameRecorder& recorder, std::uint32_t& n, Done done) {
  const auto deadline = SteadyClock::now() + std::chrono::seconds(30);
  while (!done()) {
    if (SteadyClock::now() > deadline) return false;
    for (int i = 0; i < 20; ++i, ++n) {
      recorder.record(FrameDirection::sent, CanFrame{n & 0x7FF, 8, {}}, WallTime{});
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // a bus's pace, not a wait
  }
  return true;
}

TEST(FrameRecorder, AFullDiskStopsRecordingKeepsEveryRecordingAndResumesWhenSpaceReturns) {
  SmallTmpfs disk("64k");
  if (!disk.mounted()) {
    GTEST_SKIP() << "cannot mount a 64 KiB tmpfs (" << disk.refused()
                 << "): the test needs root or CAP_SYS_ADMIN";
  }
  // The filler leaves room for about three and a half 8 KiB recordings.
  const fs::path filler = disk.path() / "filler";
  std::ofstream(filler) << std::string(36 * 1024, 'x');
  RecorderOptions options{disk.path()};
  options.max_file_bytes = 8 * 1024;
  options.max_files = 6;
  options.drain_interval = std::chrono::milliseconds(5);
  // Long enough that the files are listed before the first try again (which
  // may hold a file of its own for a moment).
  options.retry_interval = std::chrono::milliseconds(200);
  auto started = FrameRecorder::start("bus0", options);
  ASSERT_TRUE(started) << started.error();
  FrameRecorder& recorder = **started;
  std::uint32_t n = 0;

  ASSERT_TRUE(record_until(recorder, n, [&] { return recorder.figures().stopped; }));
  const auto kept = recordings(disk.path());
  ASSERT_GE(kept.size(), 3u);
  for (const auto& [name, size] : kept) {
    EXPECT_GT(size, 0u) << name;
    const auto lines = lines_of(disk.path() / name);
    ASSERT_FALSE(lines.empty()) << name;
    EXPECT_EQ(lines.back().back(), 'T') << name << " ends in part of a line";
  }
  // Each try to write again fails on the full disk; none may cost a recording
  // (more tries than max_files would have pushed every one of them out).
  const std::uint64_t errors = recorder.figures().write_errors;
  ASSERT_TRUE(record_until(recorder, n, [&] {
    return recorder.figures().write_errors >= errors + options.max_files + 2;
  }));
  EXPECT_TRUE(recorder.figures().stopped);
  const auto while_full = recordings(disk.path());
  for (const auto& [name, size] : kept) {
    ASSERT_TRUE(while_full.count(name)) << name << " was deleted";
    EXPECT_EQ(while_full.at(name), size) << name;
  }
  EXPECT_LE(while_full.size(), kept.size() + 1) << "the tries left files behind";

  fs::remove(filler);  // space returns
  const std::uint64_t recorded = recorder.figures().frames_recorded;
  ASSERT_TRUE(record_until(recorder, n, [&] {
    const auto figures = recorder.figures();
    return !figures.stopped && figures.frames_recorded > recorded;
  }));
  started->reset();
  const auto after = recordings(disk.path());
  for (const auto& [name, size] : kept) {
    ASSERT_TRUE(after.count(name)) << name << " was deleted";
    EXPECT_EQ(after.at(name), size) << name;
  }
  EXPECT_GT(after.size(), kept.size());  // recording went on in a new file
}

/// A backend that sends into a list and receives what the test queued, with
/// receive times when given.
class ListBus final : public Bus {
 public:
  const std::string& spec() const override { return spec_; }
  Result<void, BusError> send(const CanFrame& frame) override {
    if (refuse || sent.size() >= room) return dh3::fail(BusError::would_block);
    sent.push_back(frame);
    return {};
  }
  Result<void, BusError> receive(std::vector<CanFrame>& out, Duration) override {
    out.insert(out.end(), incoming.begin(), incoming.end());
    incoming.clear();
    times_ = incoming_times;
    incoming_times.clear();
    return {};
  }
  std::span<const WallTime> receive_times() const override { return times_; }
  void wake() override {}
  LinkState link_state() const override { return LinkState::up; }

  bool refuse = false;
  std::size_t room = SIZE_MAX;  ///< frames it takes before it says would_block
  std::vector<CanFrame> sent;
  std::vector<CanFrame> incoming;
  std::vector<WallTime> incoming_times;

 private:
  std::string spec_ = "list";
  std::vector<WallTime> times_;
};

TEST(RecordingBus, RecordsWhatTheBackendSentAndReceivedWithTheBackendsTimes) {
  TempDir dir;
  auto list = std::make_unique<ListBus>();
  ListBus& backend = *list;
  auto recorder = FrameRecorder::start("bus0", RecorderOptions{dir.path()});
  ASSERT_TRUE(recorder);
  auto bus = std::make_unique<RecordingBus>(std::move(list), std::move(*recorder));
  const CanFrame request{2, 8, {0x0F, 0x01, 0, 0, 0, 0, 0, 0}};
  const CanFrame reply{2, 8, {0x0F, 0x01, 0, 0, 0x03, 0, 0, 0}};
  ASSERT_TRUE(bus->send(request));
  backend.refuse = true;
  EXPECT_FALSE(bus->send(request));  // not on the bus: not recorded
  backend.incoming = {reply, reply};
  backend.incoming_times = {WallTime(std::chrono::seconds(7)), WallTime(std::chrono::seconds(8))};
  std::vector<CanFrame> frames;
  ASSERT_TRUE(bus->receive(frames, Duration::zero()));
  EXPECT_EQ(frames.size(), 2u);
  EXPECT_EQ(backend.sent.size(), 1u);
  const auto diagnostics = bus->diagnostics();
  ASSERT_TRUE(diagnostics.recorder.has_value());
  const fs::path file = dir.path() / "bus0.000001.log";
  bus.reset();
  const auto lines = lines_of(file);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_TRUE(lines[0].ends_with(" bus0 002#0F01000000000000 T")) << lines[0];
  EXPECT_EQ(lines[1], "(0000000007.000000) bus0 002#0F01000003000000 R");
  EXPECT_EQ(lines[2], "(0000000008.000000) bus0 002#0F01000003000000 R");
}

TEST(RecordingBus, ABurstIsSentOneByOneByDefaultAndOnlyWhatWasTakenIsRecorded) {
  TempDir dir;
  auto list = std::make_unique<ListBus>();
  ListBus& backend = *list;
  backend.room = 2;
  auto recorder = FrameRecorder::start("bus0", RecorderOptions{dir.path()});
  ASSERT_TRUE(recorder);
  auto bus = std::make_unique<RecordingBus>(std::move(list), std::move(*recorder));
  const std::vector<CanFrame> group{{1, 8, {0x06, 0x02, 0x01, 0, 0x3C, 0, 0, 0}},
                                    {2, 8, {0x06, 0x02, 0x01, 0, 0x3C, 0, 0, 0}},
                                    {3, 8, {0x06, 0x02, 0x01, 0, 0x3C, 0, 0, 0}}};
  const auto taken = bus->send_burst(group);
  ASSERT_TRUE(taken);
  EXPECT_EQ(taken.value(), 2u) << "the first two; the caller offers the third again";
  ASSERT_EQ(backend.sent.size(), 2u);
  EXPECT_EQ(backend.sent[1].id, 2u);
  const auto none = bus->send_burst(std::span(group).subspan(2));
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error(), BusError::would_block);
  EXPECT_EQ(bus->send_burst({}).value(), 0u);
  const fs::path file = dir.path() / "bus0.000001.log";
  bus.reset();
  const auto lines = lines_of(file);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_TRUE(lines[0].ends_with(" bus0 001#060201003C000000 T")) << lines[0];
  EXPECT_TRUE(lines[1].ends_with(" bus0 002#060201003C000000 T")) << lines[1];
}

}  // namespace
}  // namespace dh3::bus
