#pragma once
// DDS Security for dh3 participants: PKI-DH authentication, Access-Permissions
// access control and AES-GCM-GMAC encryption (Fast DDS's builtin plugins),
// switched on through the participant's properties.
//
// Six files make a participant's credentials: the identity CA's certificate
// (whom to trust), the participant's own certificate and private key, the
// permissions CA's certificate, and the governance and permissions documents
// signed by that CA (S/MIME). deploy/security/make-test-pki.sh writes a test
// set in the layout security_files_in() expects:
//
//   DIR/identity_ca.pem  DIR/permissions_ca.pem  DIR/governance.p7s
//   DIR/IDENTITY/cert.pem  DIR/IDENTITY/key.pem  DIR/IDENTITY/permissions.p7s
//
// A participant with security cannot talk to one without: with the governance
// of make-test-pki.sh it neither sees nor is seen by unauthenticated
// participants, and what it may publish or subscribe to is what its
// permissions allow (creating any other writer or reader fails locally).
//
// This header has no Fast DDS in it (configuration code may use it);
// dh3_security.hpp applies the files to a participant's QoS.

#include <unistd.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "dh3/base/result.hpp"

namespace dh3::contract {

struct SecurityFiles {
  std::string identity_ca;           ///< PEM certificate of the identity CA
  std::string identity_certificate;  ///< PEM certificate of this participant
  std::string private_key;           ///< PEM private key of this participant (unencrypted)
  std::string permissions_ca;        ///< PEM certificate of the permissions CA
  std::string governance;            ///< signed governance document (.p7s)
  std::string permissions;           ///< signed permissions document (.p7s)

  /// True if any file is named: security is wanted (and all six are then needed).
  [[nodiscard]] bool wanted() const {
    return !identity_ca.empty() || !identity_certificate.empty() || !private_key.empty() ||
           !permissions_ca.empty() || !governance.empty() || !permissions.empty();
  }
};

/// The files of `identity` ("service", "operator", "monitor", ...) in a
/// directory laid out as make-test-pki.sh writes it.
[[nodiscard]] inline SecurityFiles security_files_in(const std::string& dir,
                                                     const std::string& identity) {
  const std::filesystem::path base(dir);
  const auto own = base / identity;
  return SecurityFiles{(base / "identity_ca.pem").string(), (own / "cert.pem").string(),
                       (own / "key.pem").string(),          (base / "permissions_ca.pem").string(),
                       (base / "governance.p7s").string(),  (own / "permissions.p7s").string()};
}

/// Every file is named and readable; otherwise a message naming the first
/// that is not (for a start-up error).
[[nodiscard]] inline Result<void, std::string> check_security_files(const SecurityFiles& files) {
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

/// The participant properties that switch the builtin plugins on with these
/// files (absolute "file://" URIs: Fast DDS reads "file://" followed by a path).
[[nodiscard]] inline std::vector<std::pair<std::string, std::string>> security_properties(
    const SecurityFiles& files) {
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
