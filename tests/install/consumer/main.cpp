// The smallest useful client: join a domain, look for a service, and show that
// a call to a hand of a service that is not there ends with NO_SERVICE.
//   consumer DOMAIN   -> exit 0 when things behave as described

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <dh3/client.hpp>
#include <string>

int main(int argc, char** argv) {
  dh3::ClientOptions options;
  options.domain = argc > 1 ? std::atoi(argv[1]) : 0;
  options.default_timeout = std::chrono::milliseconds(300);
  dh3::Client client(options);
  if (!client.connected()) {
    std::fprintf(stderr, "cannot join the domain: %s\n", client.error().c_str());
    return 2;
  }
  const auto service = client.wait_for_service();
  if (service) {
    std::printf("found service %s\n", service->name.c_str());
    return 0;
  }
  std::printf("no service found: %s\n", service.message().c_str());
  const dh3::Reply reply = client.hand(dh3::HandAddress{"nobody", "bus0", 1}).initialize();
  if (reply.code != dh3::Code::no_service) {
    std::fprintf(stderr, "expected NO_SERVICE, got %s: %s\n",
                 std::string(dh3::to_string(reply.code)).c_str(), reply.message.c_str());
    return 3;
  }
  std::printf("initialize: %s: %s\n", std::string(dh3::to_string(reply.code)).c_str(),
              reply.message.c_str());
  return 0;
}
