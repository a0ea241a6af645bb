#include "ros_names.hpp"

#include <cctype>

namespace dh3::ros2 {

namespace {

bool token_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; }

/// Why `name` (fully qualified) is not a valid ROS name, or empty.
std::string broken_rule(const std::string& name) {
  if (name.size() < 2 || name.front() != '/') return "it must name something below \"/\"";
  if (name.back() == '/') return "it may not end with \"/\"";
  if (name.find("//") != std::string::npos) return "it may not hold \"//\"";
  if (name.find("__") != std::string::npos) return "it may not hold \"__\"";
  for (std::size_t i = 0; i < name.size(); ++i) {
    if (name[i] == '/') {
      if (std::isdigit(static_cast<unsigned char>(name[i + 1])) != 0) {
        return "a token may not start with a digit";
      }
    } else if (!token_char(name[i])) {
      return std::string("'") + name[i] + "' is not a letter, digit or '_'";
    }
  }
  return {};
}

void replace_all(std::string& text, const std::string& what, const std::string& with) {
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + with.size())) {
    text.replace(at, what.size(), with);
  }
}

}  // namespace

Result<std::string, std::string> resolve_name(const std::string& ros_namespace,
                                              const std::string& name) {
  if (ros_namespace.empty() || ros_namespace.front() != '/') {
    return fail("namespace \"" + ros_namespace + "\": it must start with \"/\"");
  }
  if (ros_namespace != "/") {
    if (auto why = broken_rule(ros_namespace); !why.empty()) {
      return fail("namespace \"" + ros_namespace + "\": " + why);
    }
  }
  std::string full = name;
  if (name.empty() || name.front() != '/') {
    full = (ros_namespace == "/" ? std::string() : ros_namespace) + "/" + name;
  }
  if (auto why = broken_rule(full); !why.empty()) return fail("name \"" + full + "\": " + why);
  return full;
}

std::string topic_on_dds(const std::string& fully_qualified) { return "rt" + fully_qualified; }

std::string expand_hand_pattern(const std::string& pattern, const HandAddress& hand) {
  std::string text = pattern;
  replace_all(text, "{service}", hand.service);
  replace_all(text, "{bus}", hand.bus);
  replace_all(text, "{id}", std::to_string(hand.can_id));
  for (char& c : text) {
    if (!token_char(c) && c != '/') c = '_';
  }
  return text;
}

}  // namespace dh3::ros2
