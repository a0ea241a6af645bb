#include "py_client.hpp"

#include <cstdio>
#include <set>
#include <vector>

namespace dh3::python {

namespace {

std::mutex g_clients_mutex;
std::set<PyClient*> g_clients;

void destroy_client(dh3::Client* client) {
  if (Py_IsInitialized() && PyGILState_Check()) {
    py::gil_scoped_release released;
    delete client;
  } else {
    delete client;
  }
}

/// libdh3client's spelling of a duration (conversions.cpp).
std::string describe(Milliseconds duration) {
  if (duration.count() < 1000) return std::to_string(duration.count()) + " ms";
  char text[32];
  std::snprintf(text, sizeof text, "%.3g s", static_cast<double>(duration.count()) / 1000.0);
  return text;
}

}  // namespace

std::string widen_duration(std::string message, Milliseconds slice, Milliseconds whole) {
  const std::string from = " within " + describe(slice);
  const auto at = message.rfind(from);
  if (at != std::string::npos) message.replace(at, from.size(), " within " + describe(whole));
  return message;
}

PyClient::PyClient(dh3::ClientOptions options) {
  {
    py::gil_scoped_release released;
    client_ = ClientPtr(new dh3::Client(std::move(options)), &destroy_client);
  }
  std::lock_guard lock(g_clients_mutex);
  g_clients.insert(this);
}

PyClient::~PyClient() {
  {
    std::lock_guard lock(g_clients_mutex);
    g_clients.erase(this);
  }
  close();
}

void PyClient::close() {
  ClientPtr closing;
  {
    std::lock_guard lock(mutex_);
    closing = std::move(client_);
  }
  closing.reset();
}

ClientPtr PyClient::client() {
  ClientPtr current;
  {
    std::lock_guard lock(mutex_);
    current = client_;
  }
  if (!current) raise_error(dh3::Code::not_connected, "the client is closed");
  return current;
}

ClientPtr PyClient::current() {
  std::lock_guard lock(mutex_);
  return client_;
}

Milliseconds PyClient::effective(const OptionalSeconds& timeout) {
  return timeout ? to_milliseconds(*timeout, "timeout") : client()->default_timeout();
}

bool PyClient::wait_for_statuses(const OptionalSeconds& timeout) {
  const auto deadline = Clock::now() + effective(timeout);
  for (;;) {
    const auto left = std::chrono::duration_cast<Milliseconds>(deadline - Clock::now());
    bool done = false;
    auto current = client();  // anew each slice: close() ends the wait
    {
      py::gil_scoped_release released;
      done = current->wait_for_statuses(std::clamp(left, Milliseconds(1), kSlice));
    }
    if (done || left <= kSlice) return done;
    check_signals();
  }
}

PyHand PyClient::find_hand(const std::string& spec) {
  auto current = client();
  std::optional<dh3::Found<dh3::Hand>> found;
  {
    py::gil_scoped_release released;
    found.emplace(current->find_hand(spec));
  }
  return wrap(value_or_raise(std::move(*found)));
}

void close_every_client() {
  std::vector<PyClient*> clients;
  {
    std::lock_guard lock(g_clients_mutex);
    clients.assign(g_clients.begin(), g_clients.end());
  }
  for (auto* client : clients) client->close();
}

}  // namespace dh3::python
