#pragma once
// The page's files, compiled into dh3-web (embed_assets.cmake writes the
// table from page/): the program is one file to install and needs nothing
// from the internet or a share directory to serve its page.

#include <string_view>
#include <vector>

namespace dh3::web {

struct WebAsset {
  std::string_view path;  ///< "/", "/app.js", "/api/openapi.json"
  std::string_view content_type;
  std::string_view body;
};

[[nodiscard]] const std::vector<WebAsset>& web_assets();
/// The asset at `path`, or nullptr.
[[nodiscard]] const WebAsset* find_asset(std::string_view path);

}  // namespace dh3::web
