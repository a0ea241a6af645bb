#pragma once
// Scrapes a Prometheus endpoint the way a Prometheus server would (a plain
// HTTP GET on loopback) and reads single values out of the text format.
//
//   auto text = scrape_metrics(port);
//   EXPECT_EQ(metric_value(*text, R"(dh3_hand_online{bus="bus0",hand="1",name=""})"), 1.0);

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "support/raw_tcp_client.hpp"

namespace dh3::test {

/// The body of GET /metrics, or nullopt if the endpoint does not answer 200.
inline std::optional<std::string> scrape_metrics(
    std::uint16_t port, std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  RawTcpClient client(port);
  if (!client.connected()) return std::nullopt;
  const std::string request = "GET /metrics HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n";
  if (!client.send_bytes({request.begin(), request.end()})) return std::nullopt;
  const auto response = client.read_until_closed(timeout);
  if (!response || response->rfind("HTTP/1.1 200", 0) != 0) return std::nullopt;
  const auto body = response->find("\r\n\r\n");
  if (body == std::string::npos) return std::nullopt;
  return response->substr(body + 4);
}

/// The value of the series written exactly as `series` (name and labels as
/// the exporter writes them), or nullopt if the text has no such line.
inline std::optional<double> metric_value(std::string_view text, std::string_view series) {
  std::istringstream lines{std::string(text)};
  std::string line;
  while (std::getline(lines, line)) {
    if (line.size() > series.size() && line.compare(0, series.size(), series) == 0 &&
        line[series.size()] == ' ') {
      return std::stod(line.substr(series.size() + 1));
    }
  }
  return std::nullopt;
}

/// Scrapes until `done(text)` holds or `deadline` passes; the last text scraped.
inline std::string scrape_until(std::uint16_t port,
                                const std::function<bool(const std::string&)>& done,
                                std::chrono::milliseconds deadline = std::chrono::seconds(20)) {
  const auto until = std::chrono::steady_clock::now() + deadline;
  std::string text;
  while (std::chrono::steady_clock::now() < until) {
    if (auto body = scrape_metrics(port)) {
      text = std::move(*body);
      if (done(text)) break;
    }
  }
  return text;
}

}  // namespace dh3::test
