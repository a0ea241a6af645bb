// dh3-web as a user runs it: a child process serving HTTP against dh3-service
// on the simulator (three hands, hand 1 with an object at 40), driven with
// plain HTTP requests. Commands, every bad input and the missing token, the
// push stream, viewing behind the token, requests for another Host name (DNS
// rebinding), an access log that a request cannot forge lines in, a token
// file others may read, and the alarm a failed initialization raises.

#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <thread>

#include "integration/client/client_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

constexpr const char* kToken = "integration-token-0123456789";

/// dh3-web on this test's domain and a free port.
class WebProcess {
 public:
  /// `tokens`: the token file's text.
  explicit WebProcess(std::vector<std::string> extra = {}, const std::string& log_level = "warn",
                      const std::string& tokens = std::string(kToken) + "\n")
      : token_(tokens, ".token") {
    ::chmod(token_.path().c_str(), 0600);
    std::vector<std::string> args = {"--domain", std::to_string(test_domain()), "--listen",
                                     "127.0.0.1:0", "--token-file", token_.path(),
                                     "--timeout", "20", "--log-level", log_level};
    args.insert(args.end(), extra.begin(), extra.end());
    process_ = std::make_unique<Process>(DH3_WEB_PATH, args, Process::Stdin::dev_null);
    if (auto line = process_->wait_for_line("dh3-web: serving http://127.0.0.1:",
                                            std::chrono::seconds(20))) {
      const auto start = line->find("127.0.0.1:") + 10;
      port_ = std::stoi(line->substr(start, line->find('/', start) - start));
    }
  }
  [[nodiscard]] int port() const { return port_; }
  /// The next line of its stdout (the log) that holds `text`; nullopt if none
  /// comes within the deadline. Lines before it are kept in `passed`.
  std::optional<std::string> wait_for_log(std::string_view text, std::vector<std::string>& passed) {
    const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
    while (auto line = process_->read_line(std::chrono::duration_cast<std::chrono::milliseconds>(
               deadline - std::chrono::steady_clock::now()))) {
      if (line->find(text) != std::string::npos) return line;
      passed.push_back(*line);
    }
    return std::nullopt;
  }
  /// SIGTERM; the exit code, or nullopt if it did not exit normally in time.
  std::optional<int> stop() {
    process_->send_signal(SIGTERM);
    const auto status = process_->wait_exit(kClientDeadline);
    if (!status || !WIFEXITED(*status)) return std::nullopt;
    return WEXITSTATUS(*status);
  }
  [[nodiscard]] httplib::Client client() const {
    httplib::Client c("127.0.0.1", port_);
    c.set_read_timeout(30, 0);
    return c;
  }

 private:
  TempFile token_;
  std::unique_ptr<Process> process_;
  int port_ = 0;
};

httplib::Headers with_token() { return {{"Authorization", std::string("Bearer ") + kToken}}; }

class WebServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(service_.started());
    ASSERT_GT(web_.port(), 0) << "dh3-web did not say where it serves";
    ASSERT_TRUE(wait_for_hands(3));
  }

  /// GET /api/hands until it lists `count` hands.
  bool wait_for_hands(std::size_t count) {
    const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
    while (std::chrono::steady_clock::now() < deadline) {
      auto res = http_.Get("/api/hands");
      if (res && res->status == 200) {
        std::size_t seen = 0;
        for (auto at = res->body.find(R"("type":"status")"); at != std::string::npos;
             at = res->body.find(R"("type":"status")", at + 1)) {
          ++seen;
        }
        if (seen >= count) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }

  httplib::Result command(std::uint16_t id, const std::string& name, const std::string& body,
                          const httplib::Headers& headers = with_token()) {
    return http_.Post(("/api/hands/" + hand_spec(id) + "/" + name).c_str(), headers, body,
                      "application/json");
  }

  std::uint64_t requests_written() {
    auto res = http_.Get("/api/health");
    if (!res) return ~0ULL;
    const auto at = res->body.find(R"("requests_written":)");
    return std::stoull(res->body.substr(at + 19));
  }

  RunningService service_{sim_config()};
  WebProcess web_;
  httplib::Client http_ = web_.client();
};

TEST_F(WebServiceTest, ListsEveryHandAndOne) {
  auto all = http_.Get("/api/hands");
  ASSERT_TRUE(all);
  EXPECT_EQ(all->status, 200);
  EXPECT_EQ(all->get_header_value("Content-Type"), "application/json");
  EXPECT_THAT(all->body, HasSubstr(R"("service":")" + test_service_name()));
  for (std::uint16_t id = 1; id <= 3; ++id) {
    EXPECT_THAT(all->body, HasSubstr(R"("hand":")" + hand_spec(id)));
  }
  auto one = http_.Get(("/api/hands/" + hand_spec(2)).c_str());
  ASSERT_TRUE(one);
  EXPECT_EQ(one->status, 200);
  EXPECT_THAT(one->body, StartsWith(R"({"type":"status","hand":")" + hand_spec(2) + "\""));
  auto page = http_.Get("/");
  ASSERT_TRUE(page);
  EXPECT_THAT(page->body, HasSubstr("<title>dh3 web console</title>"));
  EXPECT_EQ(page->get_header_value("X-Frame-Options"), "DENY");
}

TEST_F(WebServiceTest, CommandsAnswerAsDh3ctlJson) {
  auto init = command(1, "init", "");
  ASSERT_TRUE(init);
  EXPECT_EQ(init->status, 200) << init->body;
  EXPECT_THAT(init->body, StartsWith(R"({"type":"reply","command":"init","hand":")" +
                                     hand_spec(1) + R"(","ok":true,"code":"OK")"));
  auto move = command(1, "move", R"({"position": 60})");
  ASSERT_TRUE(move);
  EXPECT_EQ(move->status, 200) << move->body;
  auto status = http_.Get(("/api/hands/" + hand_spec(1)).c_str());
  ASSERT_TRUE(status);
  EXPECT_THAT(status->body, HasSubstr(R"("target_position":60)"));
  auto grasp = command(1, "grasp", R"({"force": 40})");
  ASSERT_TRUE(grasp);
  EXPECT_EQ(grasp->status, 200) << grasp->body;
  EXPECT_THAT(grasp->body, HasSubstr(R"("grasp":"GRASPED")"));
  auto lease = command(1, "acquire-lease", R"({"ttl_ms": 30000})");
  ASSERT_TRUE(lease);
  EXPECT_EQ(lease->status, 200) << lease->body;
  EXPECT_THAT(lease->body, HasSubstr(R"("lease_holder":")"));
  // Another client is refused while dh3-web holds the lease.
  const Finished other = dh3ctl({"--json", "release", hand_spec(1), "100"});
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_THAT(other.text(), HasSubstr(R"("code":"DENIED")"));
  auto give_back = command(1, "release-lease", "{}");
  ASSERT_TRUE(give_back);
  EXPECT_EQ(give_back->status, 200) << give_back->body;
  auto release = command(1, "release", R"({"position": 100})");
  ASSERT_TRUE(release);
  EXPECT_EQ(release->status, 200) << release->body;
  // A failure of the hand's own is a reply with its HTTP status.
  auto early = command(3, "move", R"({"position": 50})");
  ASSERT_TRUE(early);
  EXPECT_EQ(early->status, 409);
  EXPECT_THAT(early->body, HasSubstr(R"("ok":false,"code":"NOT_INITIALIZED")"));
}

TEST_F(WebServiceTest, RefusesEveryBadInputAndNothingReachesTheBus) {
  auto init = command(2, "init", "");
  ASSERT_TRUE(init);
  ASSERT_EQ(init->status, 200) << init->body;
  auto before = http_.Get(("/api/hands/" + hand_spec(2)).c_str());
  ASSERT_TRUE(before);
  ASSERT_THAT(before->body, HasSubstr(R"("target_position":null)"));
  const std::uint64_t written = requests_written();

  struct Bad {
    std::string what;
    int status;
    std::string code;
    httplib::Result result;
  };
  const std::string hand = "/api/hands/" + hand_spec(2);
  const httplib::Headers wrong = {{"Authorization", "Bearer not-the-token-0123456789"}};
  std::vector<Bad> bad;
  bad.push_back({"no token", 401, "UNAUTHORIZED", command(2, "move", R"({"position":30})", {})});
  bad.push_back({"wrong token", 401, "UNAUTHORIZED", command(2, "move", R"({"position":30})", wrong)});
  bad.push_back({"malformed JSON", 400, "INVALID_ARGUMENT", command(2, "move", R"({"position":)")});
  bad.push_back({"not an object", 400, "INVALID_ARGUMENT", command(2, "move", "30")});
  bad.push_back({"unknown field", 400, "INVALID_ARGUMENT", command(2, "move", R"({"pos":30})")});
  bad.push_back({"wrong type", 400, "INVALID_ARGUMENT", command(2, "move", R"({"position":"30"})")});
  bad.push_back({"missing field", 400, "INVALID_ARGUMENT", command(2, "grasp", "{}")});
  bad.push_back({"out of range", 400, "INVALID_ARGUMENT", command(2, "move", R"({"position":150})")});
  bad.push_back({"force out of range", 400, "INVALID_ARGUMENT", command(2, "grasp", R"({"force":5})")});
  bad.push_back({"lease out of range", 400, "INVALID_ARGUMENT",
                 command(2, "acquire-lease", R"({"ttl_ms":-1})")});
  bad.push_back({"unknown command", 404, "UNKNOWN_COMMAND", command(2, "jump", "{}")});
  bad.push_back({"unknown hand", 404, "UNKNOWN_HAND",
                 http_.Post(("/api/hands/" + test_service_name() + "/bus0/9/move").c_str(),
                            with_token(), R"({"position":30})", "application/json")});
  bad.push_back({"unknown service", 404, "UNKNOWN_HAND",
                 http_.Post("/api/hands/nosuch/bus0/2/move", with_token(), R"({"position":30})",
                            "application/json")});
  bad.push_back({"bad hand id", 400, "INVALID_ARGUMENT",
                 http_.Post(("/api/hands/" + test_service_name() + "/bus0/two/move").c_str(),
                            with_token(), R"({"position":30})", "application/json")});
  bad.push_back({"wrong method", 405, "METHOD_NOT_ALLOWED",
                 http_.Get((hand + "/move").c_str(), with_token())});
  bad.push_back({"wrong method on a hand", 405, "METHOD_NOT_ALLOWED",
                 http_.Delete(hand.c_str(), with_token())});
  bad.push_back({"too large", 413, "PAYLOAD_TOO_LARGE",
                 command(2, "move", R"({"position":30,"pad":")" + std::string(70000, 'x') + "\"}")});
  bad.push_back({"admin without confirm", 400, "INVALID_ARGUMENT",
                 command(2, "set-can-id", R"({"can_id":7})")});
  for (const Bad& b : bad) {
    ASSERT_TRUE(b.result) << b.what << ": " << httplib::to_string(b.result.error());
    EXPECT_EQ(b.result->status, b.status) << b.what << ": " << b.result->body;
    EXPECT_THAT(b.result->body, HasSubstr(R"("ok":false,"code":")" + b.code + "\""))
        << b.what;
    EXPECT_THAT(b.result->body, HasSubstr(R"("message":")")) << b.what;
    EXPECT_EQ(b.result->get_header_value("Content-Type"), "application/json") << b.what;
  }
  EXPECT_EQ(bad[0].result->get_header_value("WWW-Authenticate"), "Bearer realm=\"dh3-web\"");
  EXPECT_THAT(bad[7].result->body, HasSubstr("MOVE value 150 is out of range for position"));

  EXPECT_EQ(requests_written(), written) << "a refused request left dh3-web";
  auto after = http_.Get(hand.c_str());
  ASSERT_TRUE(after);
  EXPECT_THAT(after->body, HasSubstr(R"("target_position":null)"));
  EXPECT_THAT(after->body, HasSubstr(R"("last_error":"OK")"));
}

TEST_F(WebServiceTest, StreamPushesStatusesAndEventsOfAnotherClientsMove) {
  ASSERT_EQ(command(3, "init", "")->status, 200);
  std::mutex mutex;
  std::string received;
  std::atomic<bool> seen_ready{false};
  std::atomic<bool> done{false};
  const std::string arrived = R"("hand":")" + hand_spec(3) + R"(","name":"","kind":"ARRIVED")";
  std::thread reader([&] {
    auto stream = web_.client();
    stream.Get("/api/stream", [&](const char* data, std::size_t size) {
      std::lock_guard lock(mutex);
      received.append(data, size);
      if (received.find("event: ready") != std::string::npos) seen_ready = true;
      if (received.find(arrived) != std::string::npos) done = true;
      return !done.load();
    });
  });
  const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
  while (!seen_ready && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(seen_ready);
  const Finished move = dh3ctl({"move", hand_spec(3), "30"});
  EXPECT_EQ(move.exit_code, 0) << move.text();
  while (!done && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(done) << "no ARRIVED event of the move on the stream";
  done = true;
  reader.join();
  std::lock_guard lock(mutex);
  EXPECT_THAT(received, HasSubstr("event: service\ndata: {\"type\":\"service\""));
  EXPECT_THAT(received, HasSubstr("event: status\ndata: {\"type\":\"status\",\"hand\":\"" +
                                  hand_spec(3) + "\""));
  EXPECT_THAT(received, HasSubstr(R"("target_position":30)"));
}

TEST_F(WebServiceTest, StopsCleanlyWhileAStreamIsOpen) {
  std::atomic<bool> opened{false};
  std::atomic<bool> ended{false};
  std::thread reader([&] {
    auto stream = web_.client();
    stream.Get("/api/stream", [&](const char*, std::size_t) {
      opened = true;
      return true;
    });
    ended = true;
  });
  const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
  while (!opened && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(opened);
  EXPECT_EQ(web_.stop(), 0);
  reader.join();
  EXPECT_TRUE(ended);
}

/// Open streams, each on its own connection and thread, until closed.
class OpenStreams {
 public:
  OpenStreams(const WebProcess& web, int count) {
    for (int i = 0; i < count; ++i) {
      threads_.emplace_back([this, &web] {
        auto http = web.client();
        bool counted = false;
        std::string received;
        http.Get("/api/stream", [&](const char* data, std::size_t size) {
          received.append(data, size);
          if (!counted && received.find("event: ready") != std::string::npos) {
            counted = true;
            ++ready_;
          }
          return !closing_.load();
        });
      });
    }
  }
  ~OpenStreams() { close(); }
  OpenStreams(const OpenStreams&) = delete;
  OpenStreams& operator=(const OpenStreams&) = delete;

  /// True once every stream got its snapshot.
  bool wait_ready(int count) const {
    const auto deadline = std::chrono::steady_clock::now() + kClientDeadline * 3;
    while (ready_ < count && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return ready_ >= count;
  }
  /// The readers end at their next message (a heartbeat at the latest).
  void close() {
    closing_ = true;
    for (auto& thread : threads_) {
      if (thread.joinable()) thread.join();
    }
  }

 private:
  std::atomic<int> ready_{0};
  std::atomic<bool> closing_{false};
  std::vector<std::thread> threads_;
};

TEST_F(WebServiceTest, SixtyFourOpenPagesLeaveCommandsAndHealthAnsweringAndTheNextGets503) {
  OpenStreams pages(web_, 64);
  ASSERT_TRUE(pages.wait_ready(64)) << "64 streams did not all get their snapshot";
  auto refused = http_.Get("/api/stream");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 503);
  EXPECT_THAT(refused->body, HasSubstr(R"("code":"TOO_MANY_STREAMS")"));
  auto health = http_.Get("/api/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
  auto init = command(2, "init", "");
  ASSERT_TRUE(init);
  EXPECT_EQ(init->status, 200) << init->body;
  auto stop = command(2, "stop", "");
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->status, 200) << stop->body;
  auto page = http_.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  pages.close();
  // Closed pages free their places (a worker notices at its next write).
  const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
  bool reopened = false;
  while (!reopened && std::chrono::steady_clock::now() < deadline) {
    auto again = web_.client();
    again.Get("/api/stream", [&](const char* data, std::size_t size) {
      reopened = std::string_view(data, size).find("event:") != std::string_view::npos;
      return false;
    });
    if (!reopened) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_TRUE(reopened) << "no stream served after the 64 were closed";
}

TEST_F(WebServiceTest, AConnectionThatSendsNoRequestIsClosed) {
  // A client that connects and never finishes its headers must not hold a
  // worker for good: dh3-web closes the connection (read timeout).
  auto socket = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(socket, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(web_.port()));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(socket, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  const char partial[] = "GET /api/health HTTP/1.1\r\nHost: 127.0.0.1\r\n";
  ASSERT_EQ(::send(socket, partial, sizeof partial - 1, 0),
            static_cast<ssize_t>(sizeof partial - 1));
  timeval wait{60, 0};
  ::setsockopt(socket, SOL_SOCKET, SO_RCVTIMEO, &wait, sizeof wait);
  // It may answer 400 first; then it closes. -1 is our own minute passing.
  char buffer[512];
  ssize_t got = 0;
  while ((got = ::recv(socket, buffer, sizeof buffer, 0)) > 0) {
  }
  ::close(socket);
  EXPECT_EQ(got, 0) << "dh3-web did not close a connection whose headers never ended";
}

TEST(WebViewing, CanNeedTheToken) {
  RunningService service{sim_config()};
  ASSERT_TRUE(service.started());
  WebProcess web({"--view-needs-token"});
  ASSERT_GT(web.port(), 0);
  auto http = web.client();
  for (const char* path : {"/api/hands", "/api/stream", "/api/health"}) {
    auto res = http.Get(path);
    ASSERT_TRUE(res) << path;
    EXPECT_EQ(res->status, 401) << path;
  }
  auto page = http.Get("/");  // the page holds no data; it asks for the token
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  auto listed = http.Get("/api/hands", with_token());
  ASSERT_TRUE(listed);
  EXPECT_EQ(listed->status, 200);
}

TEST(WebAlarms, AnInitializationThatFailsIsRaisedFromTheServicesEvent) {
  // The hands take a minute to initialize; the service gives them 300 ms.
  std::string config = sim_config(60000);
  const std::string patient = "init_timeout_ms: 120000";
  config.replace(config.find(patient), patient.size(), "init_timeout_ms: 300");
  RunningService service{config};
  ASSERT_TRUE(service.started());
  WebProcess web;
  ASSERT_GT(web.port(), 0);
  auto http = web.client();
  const std::string hand = hand_spec(2);
  const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
  for (;;) {
    auto seen = http.Get(("/api/hands/" + hand).c_str());
    if (seen && seen->status == 200 && seen->body.find(R"("online":true)") != std::string::npos) {
      break;
    }
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "dh3-web never saw " << hand;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // polling the hand
  }
  auto init = http.Post(("/api/hands/" + hand + "/init").c_str(), with_token(), "",
                        "application/json");
  ASSERT_TRUE(init);
  EXPECT_NE(init->status, 200) << init->body;
  // The failed command is one alarm; the service's INIT_FAILED event another.
  const std::string raised = "hand " + hand + " Error: initialization failed";
  std::string listed;
  while (listed.find(raised) == std::string::npos && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // polling the list
    if (auto res = http.Get("/api/alarms"); res && res->status == 200) listed = res->body;
  }
  EXPECT_THAT(listed, HasSubstr(raised));
  EXPECT_THAT(listed, HasSubstr(R"("key":"event:)" + hand + ":"));
  EXPECT_THAT(listed, HasSubstr("Command to hand " + hand + " failed: Error in init"));
}

TEST(WebTokens, EachRoleMayDoWhatItsRoleMayAndNoMore) {
  RunningService service{sim_config()};
  ASSERT_TRUE(service.started());
  const std::string viewer = "viewer-token-0123456789";
  const std::string admin = "admin-token-0123456789";
  WebProcess web({"--view-needs-token"}, "warn",
                 "view " + viewer + "\noperator " + kToken + "\nadmin " + admin + "\n");
  ASSERT_GT(web.port(), 0);
  auto http = web.client();
  const auto as = [](const std::string& token) {
    return httplib::Headers{{"Authorization", "Bearer " + token}};
  };
  const auto written = [&] {
    auto res = http.Get("/api/health", as(viewer));
    if (!res) return ~0ULL;
    return std::stoull(res->body.substr(res->body.find(R"("requests_written":)") + 19));
  };
  const std::string hand = "/api/hands/" + hand_spec(2);
  // Until dh3-web has seen the hand, a command would be 404.
  const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
  while (std::chrono::steady_clock::now() < deadline) {
    auto seen = http.Get(hand.c_str(), as(viewer));
    if (seen && seen->status == 200) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const std::uint64_t before = written();

  auto viewer_move =
      http.Post((hand + "/move").c_str(), as(viewer), R"({"position":30})", "application/json");
  ASSERT_TRUE(viewer_move);
  EXPECT_EQ(viewer_move->status, 403);
  EXPECT_THAT(viewer_move->body, HasSubstr("READ_ONLY_TOKEN"));
  auto operator_admin = http.Post((hand + "/set-baud").c_str(), as(kToken),
                                  R"({"index":0,"confirm":true})", "application/json");
  ASSERT_TRUE(operator_admin);
  EXPECT_EQ(operator_admin->status, 403);
  EXPECT_THAT(operator_admin->body, HasSubstr("ADMIN_TOKEN_NEEDED"));
  EXPECT_EQ(written(), before) << "a request refused by dh3-web left it";

  // The operator commands; the admin's administrative command reaches the
  // service, which refuses it (this one runs without allow_admin).
  auto init = http.Post((hand + "/init").c_str(), as(kToken), "", "application/json");
  ASSERT_TRUE(init);
  EXPECT_EQ(init->status, 200) << init->body;
  auto admin_baud = http.Post((hand + "/set-baud").c_str(), as(admin),
                              R"({"index":0,"confirm":true})", "application/json");
  ASSERT_TRUE(admin_baud);
  EXPECT_EQ(admin_baud->status, 403) << admin_baud->body;
  EXPECT_THAT(admin_baud->body, HasSubstr("--allow-admin"));
  EXPECT_EQ(written(), before + 2);
}

TEST(WebStartup, RefusesABadListenAddressAndAShortToken) {
  const Finished listen = run_program(DH3_WEB_PATH, {"--listen", "localhost"});
  EXPECT_EQ(listen.exit_code, 2);
  TempFile short_token("short\n", ".token");
  ::chmod(short_token.path().c_str(), 0600);
  const Finished token = run_program(DH3_WEB_PATH, {"--token-file", short_token.path()});
  EXPECT_EQ(token.exit_code, 2);
}

TEST(WebStartup, RefusesATokenFileOtherUsersMayRead) {
  TempFile token(std::string(kToken) + "\n", ".token");
  ::chmod(token.path().c_str(), 0644);
  const Finished shared = run_program(
      DH3_WEB_PATH, {"--domain", std::to_string(test_domain()), "--listen", "127.0.0.1:0",
                     "--token-file", token.path()});
  EXPECT_EQ(shared.exit_code, 2);
  EXPECT_THAT(shared.text(), Not(HasSubstr("dh3-web: serving")));
}

TEST_F(WebServiceTest, RefusesARequestForAnotherHostName) {
  // What a DNS-rebinding page sends: its own name, resolved to this machine.
  const httplib::Headers rebound = {{"Host", "attacker.example:" + std::to_string(web_.port())}};
  for (const char* path : {"/api/hands", "/api/health", "/api/stream", "/"}) {
    auto res = http_.Get(path, rebound);
    ASSERT_TRUE(res) << path;
    EXPECT_EQ(res->status, 421) << path;
    EXPECT_THAT(res->body, HasSubstr(R"("code":"MISDIRECTED_REQUEST")")) << path;
    EXPECT_THAT(res->body, Not(HasSubstr(hand_spec(1)))) << path;
  }
  auto moved = command(1, "move", R"({"position":30})",
                       {{"Authorization", std::string("Bearer ") + kToken},
                        {"Host", "attacker.example"}});
  ASSERT_TRUE(moved);
  EXPECT_EQ(moved->status, 421);
  auto local = http_.Get("/api/hands", {{"Host", "localhost:" + std::to_string(web_.port())}});
  ASSERT_TRUE(local);
  EXPECT_EQ(local->status, 200);
  EXPECT_THAT(local->body, HasSubstr(hand_spec(1)));
}

TEST(WebAccessLog, ARequestCannotForgeALine) {
  RunningService service{sim_config()};
  ASSERT_TRUE(service.started());
  WebProcess web({}, "info");
  ASSERT_GT(web.port(), 0);
  auto http = web.client();
  http.set_url_encode(false);  // the path goes out as written, %0a and all
  auto res = http.Get("/api/hands%0a127.0.0.1%20POST%20/api/hands/cell/bus0/1/move%20200");
  ASSERT_TRUE(res);
  std::vector<std::string> passed;
  const auto line = web.wait_for_log("/api/hands\\x0a127.0.0.1 POST", passed);
  ASSERT_TRUE(line.has_value()) << "no access log line for the request";
  EXPECT_THAT(*line, HasSubstr("/api/hands\\x0a127.0.0.1 POST /api/hands/cell/bus0/1/move 200 " +
                               std::to_string(res->status)));
  for (const auto& earlier : passed) {
    EXPECT_THAT(earlier, Not(HasSubstr("POST /api/hands/cell/bus0/1/move"))) << earlier;
  }
}

}  // namespace
}  // namespace dh3::test
