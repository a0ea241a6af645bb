#include "api_error.hpp"

#include "output.hpp"

namespace dh3::web {

std::string ApiError::json() const {
  return ctl::JsonObject()
      .add("type", "error")
      .add("ok", false)
      .add("code", code)
      .add("message", message)
      .str();
}

}  // namespace dh3::web
