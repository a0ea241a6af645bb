#include "event_stream.hpp"

#include <algorithm>

#include "client_json.hpp"

namespace dh3::web {
namespace {

/// A waiting alarm list is replaced by a newer one, as a hand's status is: no
/// hand's address is this (they have slashes).
const std::string kAlarmsKey = "alarms";

}  // namespace

std::string sse_message(std::string_view name, std::string_view json) {
  std::string text = "event: ";
  text += name;
  text += "\ndata: ";
  text += json;  // one line: the JSON writer escapes newlines
  text += "\n\n";
  return text;
}

EventStream::EventStream(Client& client, EventStreamOptions options)
    : client_(client), options_(options) {
  status_subscription_ = client_.subscribe_status([this](const HandStatus& s) { on_status(s); });
  event_subscription_ = client_.subscribe([this](const HandEvent& e) { on_event(e); });
}

EventStream::~EventStream() {
  status_subscription_.unsubscribe();
  event_subscription_.unsubscribe();
  close();
}

std::string EventStream::service_messages() const {
  std::string text;
  for (const auto& info : client_.services()) text += sse_message("service", json_text(Json(info)));
  return text;
}

std::string EventStream::heartbeat() const {
  std::string text = service_messages();
  return text.empty() ? ": keep-alive\n\n" : text;
}

std::shared_ptr<EventStream::Reader> EventStream::open() {
  std::string services = service_messages();
  std::lock_guard lock(mutex_);
  readers_.erase(std::remove_if(readers_.begin(), readers_.end(),
                                [](const std::weak_ptr<Reader>& r) { return r.expired(); }),
                 readers_.end());
  if (readers_.size() >= options_.max_readers) return nullptr;
  auto reader = std::make_shared<Reader>();
  // Under the lock, so no status between the snapshot and the registration
  // is lost; a status sent twice is harmless (update_seq orders them).
  for (const auto& status : client_.hands()) {
    reader->push(status.address.to_string(), sse_message("status", json_text(Json(status))),
                 options_.queue_limit);
  }
  if (!services.empty()) reader->push({}, std::move(services), options_.queue_limit);
  for (const auto& text : backlog_) reader->push({}, text, options_.queue_limit);
  if (!alarms_.empty()) reader->push(kAlarmsKey, alarms_, options_.queue_limit);
  reader->push({}, sse_message("ready", "{}"), options_.queue_limit);
  if (closed_) {
    std::lock_guard reader_lock(reader->mutex_);
    reader->ended_ = true;
  }
  readers_.push_back(reader);
  return reader;
}

void EventStream::close() {
  std::lock_guard lock(mutex_);
  closed_ = true;
  for (const auto& weak : readers_) {
    if (auto reader = weak.lock()) {
      std::lock_guard reader_lock(reader->mutex_);
      reader->ended_ = true;
      reader->changed_.notify_all();
    }
  }
}

void EventStream::publish_alarms(std::uint64_t version, std::string json) {
  std::string text = sse_message("alarms", json);
  {
    std::lock_guard lock(mutex_);
    if (version < alarms_version_) return;
    alarms_version_ = version;
    alarms_ = text;
  }
  // Two lists may still pass each other here: the page keeps the newer version.
  broadcast(kAlarmsKey, text);
}

void EventStream::on_status(const HandStatus& status) {
  broadcast(status.address.to_string(), sse_message("status", json_text(Json(status))));
}

void EventStream::on_event(const HandEvent& event) {
  std::string text = sse_message("event", json_text(Json(event)));
  {
    std::lock_guard lock(mutex_);
    backlog_.push_back(text);
    while (backlog_.size() > options_.backlog) backlog_.pop_front();
  }
  broadcast({}, text);
}

void EventStream::broadcast(const std::string& hand, const std::string& text) {
  std::lock_guard lock(mutex_);
  for (const auto& weak : readers_) {
    if (auto reader = weak.lock()) reader->push(hand, text, options_.queue_limit);
  }
}

void EventStream::Reader::push(std::string hand, std::string text, std::size_t limit) {
  std::lock_guard lock(mutex_);
  if (ended_) return;
  if (!hand.empty()) {
    for (auto& waiting : queue_) {
      if (waiting.hand == hand) {
        waiting.text = std::move(text);
        return;
      }
    }
  }
  if (queue_.size() >= limit) {
    ended_ = true;  // the browser reconnects and gets a fresh snapshot
    queue_.clear();
  } else {
    queue_.push_back(Message{std::move(hand), std::move(text)});
  }
  changed_.notify_all();
}

std::optional<std::string> EventStream::Reader::next(std::chrono::milliseconds wait) {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, wait, [this] { return ended_ || !queue_.empty(); });
  if (queue_.empty() && ended_) return std::nullopt;
  std::string text;
  for (auto& message : queue_) text += message.text;
  queue_.clear();
  return text;
}

}  // namespace dh3::web
