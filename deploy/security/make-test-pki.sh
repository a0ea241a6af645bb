#!/usr/bin/env bash
# A TEST public-key infrastructure for DDS Security (OMG DDS Security 1.1, as
# Fast DDS 2.9's builtin PKI-DH, Access-Permissions and AES-GCM-GMAC plugins
# read it). For trying security out and for the test suite; a real cell needs
# its own CAs, kept offline, and its own review of the permissions.
#
#   deploy/security/make-test-pki.sh [--force] [--days N] [--domains N|MIN-MAX]
#                                    [--operator NAME]... [--admin NAME]... [DIR]
#
# DIR defaults to $XDG_RUNTIME_DIR/dh3-pki, or build/pki in the source tree
# (ignored by git) when XDG_RUNTIME_DIR is unset. The script refuses any DIR
# inside the source tree except under a build*/ folder: private keys never end
# up where git could pick them up.
#
# What it writes (private keys 0600, directories 0700):
#
#   DIR/identity_ca.pem            identity CA certificate (trust anchor for PKI-DH)
#   DIR/permissions_ca.pem         permissions CA certificate (signs governance and permissions)
#   DIR/governance.xml, .p7s       the domain governance, and the same signed (S/MIME)
#   DIR/ca/*.key.pem               the two CAs' private keys
#   DIR/<identity>/cert.pem        identity certificate, signed by the identity CA
#   DIR/<identity>/key.pem         its private key
#   DIR/<identity>/permissions.xml, .p7s   its permissions, and the same signed
#
# for the identities
#   service   dh3-service: publishes status, events, service info and replies,
#             subscribes to command, group and admin requests
#   NAME      each --operator: a client that drives hands: publishes command
#             and group requests, subscribes to status, events, service info
#             and replies
#   NAME      each --admin: an operator that may also publish admin requests
#             (SET_CAN_ID, SET_BAUD_RATE; the service takes them, under DDS
#             Security, only from that topic and only with allow_admin)
#   monitor   read-only: subscribes to status and events, nothing else
#
# Each identity has its own key and certificate (subject "O=dh3 test PKI,
# CN=dh3 <role> <NAME>"; "CN=dh3 <role>" for the names "operator" and
# "admin") and permissions that grant it its role's topics only. Without
# --operator and --admin it makes one of each, named "operator" and "admin".
#
# --domains: the DDS domains every grant and the governance cover, one (N)
# or a range (MIN-MAX); default 0, the service's default domain (dds.domain).
# Give the domain the cell's service uses: a participant on another domain is
# refused by access control.
#
# Governance: no unauthenticated participants, join access control, discovery,
# liveliness and RTPS messages encrypted; every topic with read and write
# access control and its data and metadata encrypted.
#
# The dh3::contract::security_files_in(DIR, IDENTITY) helper
# (idl/include/dh3/contract/security.hpp) and deploy/dds/secure.xml expect this layout.
set -euo pipefail

repo=$(cd "$(dirname "$0")/../.." && pwd -P)
days=365
domains=0
force=0
dir=
operators=()
admins=()

usage() { sed -n '2,/^set -euo/p' "$0" | sed -e '/^set -euo/d' -e 's/^# \{0,1\}//'; }
while (($#)); do
  case $1 in
    --force) force=1 ;;
    --days) days=${2:?--days needs a number}; shift ;;
    --domains) domains=${2:?--domains needs N or MIN-MAX}; shift ;;
    --operator) operators+=("${2:?--operator needs a NAME}"); shift ;;
    --admin) admins+=("${2:?--admin needs a NAME}"); shift ;;
    -h | --help) usage; exit 0 ;;
    -*) echo "make-test-pki: unknown option $1" >&2; exit 2 ;;
    *) [[ -z $dir ]] || { echo "make-test-pki: one DIR only" >&2; exit 2; }; dir=$1 ;;
  esac
  shift
done
[[ $days =~ ^[1-9][0-9]*$ ]] || { echo "make-test-pki: --days must be a positive number" >&2; exit 2; }
[[ $domains =~ ^([0-9]+)(-([0-9]+))?$ ]] || { echo "make-test-pki: --domains must be N or MIN-MAX" >&2; exit 2; }
domain_min=$((10#${BASH_REMATCH[1]})) domain_max=$((10#${BASH_REMATCH[3]:-${BASH_REMATCH[1]}}))
((domain_min <= domain_max && domain_max <= 232)) ||
  { echo "make-test-pki: --domains must be within 0-232, MIN <= MAX" >&2; exit 2; }
if ((${#operators[@]} == 0 && ${#admins[@]} == 0)); then operators=(operator) admins=(admin); fi
declare -A named=()
for name in "${operators[@]}" "${admins[@]}"; do
  # A name is a folder and part of a certificate's subject.
  [[ $name =~ ^[A-Za-z0-9][A-Za-z0-9_.-]*$ ]] ||
    { echo "make-test-pki: identity name '$name': letters, digits, '_', '.', '-' only" >&2; exit 2; }
  case $name in service | monitor | ca)
    echo "make-test-pki: identity name '$name' is taken by the PKI itself" >&2; exit 2 ;;
  esac
  [[ -z ${named[$name]:-} ]] || { echo "make-test-pki: identity name '$name' given twice" >&2; exit 2; }
  named[$name]=1
done
command -v openssl >/dev/null || { echo "make-test-pki: openssl is not installed" >&2; exit 1; }

if [[ -z $dir ]]; then
  if [[ -n ${XDG_RUNTIME_DIR:-} ]]; then dir=$XDG_RUNTIME_DIR/dh3-pki; else dir=$repo/build/pki; fi
fi
# Resolved (symbolic links too) before anything is created.
dir=$(realpath -m "$dir")

# Inside the source tree only under a top-level build*/ folder (the root
# .gitignore's /build*/): anywhere else a key could be committed.
case $dir/ in
  "$repo"/build*/*) ;;
  "$repo"/*)
    echo "make-test-pki: refusing to write private keys into the source tree ($dir);" \
      "give a directory outside it, or under build*/" >&2
    exit 2
    ;;
esac
if [[ -e $dir/identity_ca.pem && $force -eq 0 ]]; then
  echo "make-test-pki: $dir already holds a PKI; --force replaces it" >&2
  exit 2
fi

umask 077
mkdir -p "$dir"
chmod 700 "$dir"
mkdir -p "$dir/ca"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

org="dh3 test PKI"
# Certificates of both CAs and all identities: ECDSA on P-256 with SHA-256,
# which PKI-DH supports (as it does RSA-2048).
new_key() { openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1" 2>/dev/null; }

make_ca() {  # make_ca NAME COMMON_NAME KEY_USAGE
  new_key "$dir/ca/$1.key.pem"
  openssl req -x509 -new -key "$dir/ca/$1.key.pem" -sha256 -days "$days" \
    -subj "/O=$org/CN=$2" \
    -addext "basicConstraints=critical,CA:TRUE" \
    -addext "keyUsage=critical,$3" \
    -out "$dir/$1.pem"
  chmod 644 "$dir/$1.pem"
}

make_identity() {  # make_identity NAME COMMON_NAME
  local out=$dir/$1
  mkdir -p "$out"
  new_key "$out/key.pem"
  openssl req -new -key "$out/key.pem" -subj "/O=$org/CN=$2" -out "$work/$1.csr"
  printf '%s\n' "basicConstraints=CA:FALSE" "keyUsage=critical,digitalSignature,keyAgreement" \
    >"$work/$1.ext"
  openssl x509 -req -in "$work/$1.csr" -CA "$dir/identity_ca.pem" \
    -CAkey "$dir/ca/identity_ca.key.pem" -set_serial "0x$(openssl rand -hex 12)" \
    -days "$days" -sha256 -extfile "$work/$1.ext" -out "$out/cert.pem" 2>/dev/null
  chmod 644 "$out/cert.pem"
}

# S/MIME, clear-signed with the permissions CA, as DDS Security requires for
# governance and permissions documents.
sign() {  # sign XML_FILE
  openssl smime -sign -text -in "$1" -out "${1%.xml}.p7s" \
    -signer "$dir/permissions_ca.pem" -inkey "$dir/ca/permissions_ca.key.pem"
  chmod 644 "$1" "${1%.xml}.p7s"
}

make_ca identity_ca "dh3 identity CA" keyCertSign,cRLSign
# The permissions CA signs documents itself (S/MIME), so it needs digitalSignature.
make_ca permissions_ca "dh3 permissions CA" keyCertSign,cRLSign,digitalSignature
common_name() {  # common_name ROLE NAME
  if [[ $2 == "$1" ]]; then echo "dh3 $1"; else echo "dh3 $1 $2"; fi
}
make_identity service "dh3 service"
for name in "${operators[@]}"; do make_identity "$name" "$(common_name operator "$name")"; done
for name in "${admins[@]}"; do make_identity "$name" "$(common_name admin "$name")"; done
make_identity monitor "dh3 monitor"

# Topic names: idl/dh3.idl, module dh3::topics.
status=dh3/hand_status
event=dh3/hand_event
info=dh3/service_info
request=dh3/command_request
reply=dh3/command_reply
group_request=dh3/group_request
group_reply=dh3/group_reply
owner=dh3/service_owner
lease=dh3/hand_lease
admin_request=dh3/admin_request

domains_xml="<domains><id_range><min>$domain_min</min><max>$domain_max</max></id_range></domains>"

cat >"$dir/governance.xml" <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<!-- dh3 test governance: only authenticated participants, everything encrypted. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-Security/20170801/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      $domains_xml
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF
sign "$dir/governance.xml"

not_before=$(date -u -d '1 day ago' +%Y-%m-%dT%H:%M:%S)
not_after=$(date -u -d "$days days" +%Y-%m-%dT%H:%M:%S)

topics_xml() {  # topics_xml TOPIC...
  local t
  printf '<topics>'
  for t in "$@"; do printf '<topic>%s</topic>' "$t"; done
  printf '</topics>'
}

permissions() {  # permissions IDENTITY PUBLISH_TOPICS SUBSCRIBE_TOPICS (space-separated; may be empty)
  local id=$1 subject publish="" subscribe=""
  # The grant names the certificate's subject exactly as RFC 2253 prints it.
  subject=$(openssl x509 -in "$dir/$id/cert.pem" -noout -subject -nameopt RFC2253 | sed 's/^subject=//')
  # shellcheck disable=SC2086  # word splitting of the topic lists is wanted
  [[ -n $2 ]] && publish="<publish>$(topics_xml $2)</publish>"
  # shellcheck disable=SC2086
  [[ -n $3 ]] && subscribe="<subscribe>$(topics_xml $3)</subscribe>"
  cat >"$dir/$id/permissions.xml" <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<!-- dh3 test permissions for "$id". Everything not allowed here is denied. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-Security/20170801/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="dh3_$id">
      <subject_name>$subject</subject_name>
      <validity>
        <not_before>$not_before</not_before>
        <not_after>$not_after</not_after>
      </validity>
      <allow_rule>
        $domains_xml${publish:+
        $publish}${subscribe:+
        $subscribe}
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
EOF
  sign "$dir/$id/permissions.xml"
}

# A service reads the owner topic too: a second service of its name must not serve.
# The lease topic is the service's and its standby's only (docs/hot-standby.md).
permissions service "$status $event $info $reply $group_reply $owner $lease" \
  "$request $group_request $admin_request $owner $lease"
for name in "${operators[@]}"; do
  permissions "$name" "$request $group_request" "$status $event $info $reply $group_reply $owner"
done
for name in "${admins[@]}"; do
  permissions "$name" "$request $group_request $admin_request" \
    "$status $event $info $reply $group_reply $owner"
done
permissions monitor "" "$status $event $owner"

identities=service
for name in "${operators[@]}"; do identities+=", $name (operator)"; done
for name in "${admins[@]}"; do identities+=", $name (admin)"; done
granted=$domain_min
((domain_max == domain_min)) || granted+="-$domain_max"
echo "make-test-pki: test PKI for DDS domain(s) $granted in $dir (identities: $identities, monitor)"
