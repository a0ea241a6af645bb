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
// dh3/contract/security.hpp applies the files to a participant's QoS.

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
  [[nodiscard]] bool wanted() const;
};

/// The files of `identity` ("service", "operator", "monitor", ...) in a
/// directory laid out as make-test-pki.sh writes it.
[[nodiscard]] SecurityFiles security_files_in(const std::string& dir, const std::string& identity);

/// Every file is named and readable; otherwise a message naming the first
/// that is not (for a start-up error).
[[nodiscard]] Result<void, std::string> check_security_files(const SecurityFiles& files);

/// The participant properties that switch the builtin plugins on with these
/// files (absolute "file://" URIs: Fast DDS reads "file://" followed by a path).
[[nodiscard]] std::vector<std::pair<std::string, std::string>> security_properties(
    const SecurityFiles& files);

}  // namespace dh3::contract
