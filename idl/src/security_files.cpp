#include "dh3/contract/security_files.hpp"

#include <unistd.h>

#include <filesystem>

namespace dh3::contract {

bool SecurityFiles::wanted() const {
  return !identity_ca.empty() || !identity_certificate.empty() || !private_key.empty() ||
         !permissions_ca.empty() || !governance.empty() || !permissions.empty();
}

SecurityFiles security_files_in(const std::string& dir, const std::string& identity) {
  const std::filesystem::path base(dir);
  const auto own = base / identity;
  return SecurityFiles{(base / "identity_ca.pem").string(), (own / "cert.pem").string(),
                       (own / "key.pem").string(),          (base / "permissions_ca.pem").string(),
                       (base / "governance.p7s").string(),  (own / "permissions.p7s").string()};
}

Result<void, std::string> check_security_files(const SecurityFiles& files) {
  const std::pair<const char*, const std::string*> all[] = {
      {"identity CA certificate", &files.identity_ca},
      {"identity certificate", &files.identity_certificate},
      {"private key", &files.private_key},
      {"permissions CA certificate", &files.permissions_ca},
      {"governance document", &files.governance},
      {"permissions document", &files.permissions},
  };
  for (const auto& [what, path] : all) {
    if (path->empty()) return dh3::fail(std::string("DDS Security: no ") + what + " given");
    if (::access(path->c_str(), R_OK) != 0) {
      return dh3::fail(std::string("DDS Security: cannot read the ") + what + " '" + *path + "'");
    }
  }
  return {};
}

std::vector<std::pair<std::string, std::string>> security_properties(const SecurityFiles& files) {
  const auto uri = [](const std::string& path) {
    return "file://" + std::filesystem::absolute(path).lexically_normal().string();
  };
  const std::string auth = "dds.sec.auth.builtin.PKI-DH.";
  const std::string access = "dds.sec.access.builtin.Access-Permissions.";
  return {
      {"dds.sec.auth.plugin", "builtin.PKI-DH"},
      {auth + "identity_ca", uri(files.identity_ca)},
      {auth + "identity_certificate", uri(files.identity_certificate)},
      {auth + "private_key", uri(files.private_key)},
      {"dds.sec.access.plugin", "builtin.Access-Permissions"},
      {access + "permissions_ca", uri(files.permissions_ca)},
      {access + "governance", uri(files.governance)},
      {access + "permissions", uri(files.permissions)},
      {"dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC"},
  };
}

}  // namespace dh3::contract
