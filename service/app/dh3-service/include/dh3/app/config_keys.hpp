#pragma once
// Every key of dh3-service's YAML configuration, declared once: its path,
// type, default, range and one line of doc. The parser takes its known keys
// and the ranges of numbers from here, `dh3-service --config-keys` prints the
// docs/configuration.md's table from it, and tests/unit/app/test_config_keys.cpp checks the
// docs/configuration.md's table and the defaults the parser gives against it.
// Pure data and lookups: safe from any thread.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

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

struct ConfigKey {
  /// Dotted path from the file's root; "[]" stands for every element of a
  /// list: "buses[].hands[].id".
  std::string_view path;
  KeyType type = KeyType::text;
  /// The default as docs/configuration.md shows it; "" when the key has none (required,
  /// or absent means off).
  std::string_view fallback;
  /// Integers, milliseconds and numbers: the inclusive range the parser
  /// accepts.
  double min = 0;
  double max = 0;
  std::string_view doc;
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

}  // namespace dh3::app
