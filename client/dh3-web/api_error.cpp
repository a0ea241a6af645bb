#include "api_error.hpp"

#include "client_json.hpp"

namespace dh3::web {

std::string ApiError::json() const {
  return json_text(Json{{"type", "error"}, {"ok", false}, {"code", code}, {"message", message}});
}

}  // namespace dh3::web
