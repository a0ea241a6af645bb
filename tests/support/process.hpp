#pragma once
// A child process for integration tests: started with fork/exec, its stdin and
// stdout are pipes held here (stderr is inherited so its logs show in the test
// output), and it is killed and reaped when this object goes away. The child
// also dies with the test process (PR_SET_PDEATHSIG), so a crashed test leaves
// no stray servers behind.
//
//   dh3::test::Process sim(DH3_SIM_PATH, {"--hands", "1"});
//   ASSERT_TRUE(sim.started());
//   auto line = sim.wait_for_line("listening ", std::chrono::seconds(10));

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace dh3::test {

class Process {
 public:
  enum class Stdin : std::uint8_t { pipe, dev_null };

  /// With Stdin::dev_null the child's stdin is at end of file from the start.
  Process(const std::string& path, const std::vector<std::string>& args,
          Stdin stdin_mode = Stdin::pipe) {
    // Writing to a child that already exited must fail, not kill the test.
    ::signal(SIGPIPE, SIG_IGN);
    start(path, args, stdin_mode);
  }
  ~Process() {
    close_fd(stdin_fd_);
    if (pid_ > 0 && !exit_status_) {
      ::kill(pid_, SIGKILL);
      int status = 0;
      while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
      }
    }
    close_fd(stdout_fd_);
  }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  [[nodiscard]] bool started() const { return pid_ > 0; }
  [[nodiscard]] pid_t pid() const { return pid_; }

  /// The next line of the child's stdout (without the newline); nullopt at end
  /// of file or if none is complete within `timeout`.
  std::optional<std::string> read_line(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      if (const std::size_t newline = buffer_.find('\n'); newline != std::string::npos) {
        std::string line = buffer_.substr(0, newline);
        buffer_.erase(0, newline + 1);
        return line;
      }
      if (stdout_fd_ < 0) return std::nullopt;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      pollfd poll_fd{stdout_fd_, POLLIN, 0};
      const int ready = ::poll(&poll_fd, 1, static_cast<int>(left.count()));
      if (ready < 0 && errno == EINTR) continue;
      if (ready <= 0) return std::nullopt;
      char chunk[4096];
      const ssize_t got = ::read(stdout_fd_, chunk, sizeof chunk);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) {
        close_fd(stdout_fd_);
        continue;  // hand out what is buffered, then report the end
      }
      buffer_.append(chunk, static_cast<std::size_t>(got));
    }
  }

  /// Reads lines until one starts with `prefix` and returns it; lines before
  /// it are dropped. nullopt on end of file or timeout.
  std::optional<std::string> wait_for_line(std::string_view prefix,
                                           std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      std::optional<std::string> line = read_line(std::max(left, std::chrono::milliseconds(0)));
      if (!line) return std::nullopt;
      if (line->starts_with(prefix)) return line;
    }
  }

  /// Writes `line` and a newline to the child's stdin.
  bool write_line(std::string_view line) {
    std::string text(line);
    text += '\n';
    std::string_view rest = text;
    while (!rest.empty()) {
      const ssize_t written = ::write(stdin_fd_, rest.data(), rest.size());
      if (written < 0 && errno == EINTR) continue;
      if (written <= 0) return false;
      rest.remove_prefix(static_cast<std::size_t>(written));
    }
    return true;
  }

  void close_stdin() { close_fd(stdin_fd_); }

  bool send_signal(int signal_number) { return pid_ > 0 && ::kill(pid_, signal_number) == 0; }

  /// Waits until the child exits, at most `timeout`; returns its waitpid status.
  std::optional<int> wait_exit(std::chrono::milliseconds timeout) {
    if (exit_status_) return exit_status_;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (pid_ > 0) {
      int status = 0;
      const pid_t done = ::waitpid(pid_, &status, WNOHANG);
      if (done == pid_) {
        exit_status_ = status;
        return exit_status_;
      }
      if (done < 0 && errno != EINTR) return std::nullopt;
      if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // polling, not a wait for time
    }
    return std::nullopt;
  }

 private:
  void start(const std::string& path, const std::vector<std::string>& args, Stdin stdin_mode) {
    int to_child[2];
    int from_child[2];
    if (::pipe2(to_child, O_CLOEXEC) != 0) return;
    if (::pipe2(from_child, O_CLOEXEC) != 0) {
      ::close(to_child[0]);
      ::close(to_child[1]);
      return;
    }
    // Everything the child needs is built before fork: it may only exec.
    std::vector<std::string> storage{path};
    storage.insert(storage.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& arg : storage) argv.push_back(arg.data());
    argv.push_back(nullptr);
    const pid_t parent = ::getpid();

    const pid_t pid = ::fork();
    if (pid == 0) {
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent) ::_exit(126);  // the test died before prctl
      if (stdin_mode == Stdin::dev_null) {
        const int null_fd = ::open("/dev/null", O_RDONLY);
        ::dup2(null_fd, STDIN_FILENO);
      } else {
        ::dup2(to_child[0], STDIN_FILENO);
      }
      ::dup2(from_child[1], STDOUT_FILENO);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    ::close(to_child[0]);
    ::close(from_child[1]);
    if (pid < 0) {
      ::close(to_child[1]);
      ::close(from_child[0]);
      return;
    }
    pid_ = pid;
    stdin_fd_ = to_child[1];
    stdout_fd_ = from_child[0];
  }

  static void close_fd(int& fd) {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }

  pid_t pid_ = -1;
  int stdin_fd_ = -1;
  int stdout_fd_ = -1;
  std::string buffer_;
  std::optional<int> exit_status_;
};

}  // namespace dh3::test
