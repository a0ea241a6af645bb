#pragma once
// Every key of dh3-service's configuration, declared once: its path, type,
// range, one line of doc, the command-line option that also sets it, and the
// field it fills. A key's default is its field's own default member (the
// option structs': ServiceConfig, SchedulerOptions, SimSettings,
// RecorderOptions, ...), not written again here. The file parser walks the
// table, the command line sets the same keys through it (so a range or a rule
// is checked by one piece of code), `dh3-service --config-keys` prints the
// docs/configuration.md's table from it and `--help` takes its options' text from it.
// Built once on first use, then read-only: safe from any thread.

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "dh3/app/config.hpp"

namespace dh3::app {

enum class KeyType : std::uint8_t {
  text,
  integer,
  milliseconds,  ///< an integer number of milliseconds
  number,        ///< a real number
  boolean,
  list,
  map,
};

[[nodiscard]] std::string_view to_string(KeyType type);

/// The objects the keys being read belong to: the configuration, and the bus
/// and hand whose map is being read.
struct ConfigTarget {
  ServiceConfig* config = nullptr;
  BusSettings* bus = nullptr;
  HandSettings* hand = nullptr;
};

/// A value as read from the file or the command line, before it is stored.
using ConfigValue = std::variant<std::string, long long, double, bool, std::vector<std::string>>;

/// Fine, or what is wrong with a value (without the key: the caller names it).
using Checked = Result<void, std::string>;

/// Where a key's value goes: into a field of the target (leaves), or the
/// object a map or a list element makes (maps, lists of maps).
struct KeyField {
  std::function<void(ConfigTarget&, const ConfigValue&)> store;
  /// The field's value as text ("" when it holds nothing).
  std::function<std::string(ConfigTarget&)> shown;
  /// Maps and list elements: makes the object their keys fill.
  std::function<void(ConfigTarget&)> enter;
};

struct ConfigKey {
  /// Dotted path from the file's root; "[]" stands for every element of a
  /// list: "buses[].hands[].id".
  std::string_view path;
  KeyType type = KeyType::text;
  /// Integers, milliseconds and numbers: the inclusive range accepted.
  double min = 0;
  double max = 0;
  std::string_view doc;
  KeyField field;
  /// The command-line option that sets the key too ("" when none).
  std::string_view option;
  /// The key must be given where its parent is.
  bool required = false;
  /// Shown as the default where the field's own default does not say it
  /// (one that depends on another key, or a list's meaning when empty).
  std::string_view note;
  /// The rule of a text value (of each element of a list), besides its type.
  std::function<Checked(std::string_view)> check;
  /// The default as the table shows it: `note`, else the field's default
  /// ("" for none: required, or absent means off).
  std::string fallback;
};

/// Every key, parents before their children, in docs/configuration.md's order.
[[nodiscard]] std::span<const ConfigKey> config_keys();
/// The declaration of `path`; nullptr for a key that is not declared.
[[nodiscard]] const ConfigKey* find_config_key(std::string_view path);
/// The names of the keys directly under `parent` ("" for the file's root,
/// "dds", "buses[]", "buses[].sim", "buses[].hands[]").
[[nodiscard]] std::vector<std::string_view> child_keys(std::string_view parent);
/// docs/configuration.md's configuration table (Markdown), one row per key.
[[nodiscard]] std::string config_keys_table();
/// The key's command-line option as messages name it ("--domain").
[[nodiscard]] std::string option_name(const ConfigKey& key);
/// `--help`'s text for the option of the key at `path`: its doc and default.
[[nodiscard]] std::string option_help(std::string_view path);

/// A value's range (numbers) and rule (text, each element of a list) as the
/// key declares them.
[[nodiscard]] Checked check_value(const ConfigKey& key, const ConfigValue& value);

}  // namespace dh3::app
