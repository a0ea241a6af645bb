// Clients started together in one process: as a cell controller
// that opens a dh3::Client per hand or per task at start-up. Each client is
// its own DDS participant; all of them start at the same moment against one
// dh3-service (default transports), and every one must be answered.
// tests/reliability/client_burst.sh does the same across processes.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <barrier>
#include <string>
#include <thread>
#include <vector>

#include "dh3/client.hpp"
#include "dh3/registers.hpp"
#include "reliability_fixture.hpp"

namespace dh3::test {
namespace {

// 32 clients everywhere, under ThreadSanitizer too, where they starve their
// own receive threads for seconds: a lapse of the service each of them then
// sees ends no call while its sockets hold what it has not read
// (client/src/lapse_judge.hpp), and the service's assertions it reads
// meanwhile overturn it.
constexpr int kClients = 32;

TEST(ClientBurst, ClientsStartedTogetherInOneProcessAreAllAnswered) {
  TempFile config(
      "buses:\n  - name: bus0\n    spec: sim\n    command_interval_ms: 2\n"
      "    hands: [{id: 1}, {id: 2}, {id: 3}]\n");
  ServiceProcess service({"--config", config.path(), "--log-level", "warn"});
  ASSERT_TRUE(service.started());
  {
    ClientOptions options;
    options.domain = test_domain();
    Client first(options);
    ASSERT_TRUE(first.wait_for_service(service.name(), std::chrono::seconds(30)));
  }

  std::barrier start(kClients);
  std::vector<std::string> failures(kClients);
  std::atomic<int> answered{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < kClients; ++i) {
    threads.emplace_back([&, i] {
      start.arrive_and_wait();
      ClientOptions options;
      options.domain = test_domain();
      options.participant_name = "burst-" + std::to_string(i);
      Client client(options);
      const auto id = static_cast<std::uint16_t>(1 + i % 3);
      const Reply reply = client.hand(HandAddress{service.name(), "bus0", id})
                              .read(reg::position, std::chrono::seconds(60));
      if (reply) {
        answered.fetch_add(1);
      } else {
        failures[static_cast<std::size_t>(i)] = std::string(to_string(reply.code)) + ": " + reply.message;
      }
    });
  }
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(answered.load(), kClients);
  for (int i = 0; i < kClients; ++i) {
    EXPECT_THAT(failures[static_cast<std::size_t>(i)], ::testing::IsEmpty()) << "client " << i;
  }
}

}  // namespace
}  // namespace dh3::test
