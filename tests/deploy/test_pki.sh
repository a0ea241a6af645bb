#!/usr/bin/env bash
# deploy/security/make-test-pki.sh: the PKI it makes is what DDS Security needs
# (certificates chain to their CA, documents are S/MIME-signed by the
# permissions CA and verify), the permissions say what the README says (each
# role its own topics, admin requests for admins only), every identity has a
# key of its own, the grants cover the domains asked for and no others, keys
# stay private, and it never writes into the source tree.
#   test_pki.sh SOURCE_DIR
set -uo pipefail
src=$1
script=$src/deploy/security/make-test-pki.sh
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAILED: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; }

pki=$work/pki
"$script" "$pki" || { echo "FAILED: make-test-pki.sh exited $?"; exit 1; }

for id in service operator admin monitor; do
  if openssl verify -CAfile "$pki/identity_ca.pem" "$pki/$id/cert.pem" >/dev/null; then
    ok "$id certificate chains to the identity CA"
  else
    fail "$id certificate does not verify against the identity CA"
  fi
  if openssl verify -CAfile "$pki/permissions_ca.pem" "$pki/$id/cert.pem" >/dev/null 2>&1; then
    fail "$id certificate verifies against the permissions CA too (the CAs are not separate)"
  fi
  cert_key=$(openssl x509 -in "$pki/$id/cert.pem" -noout -pubkey)
  own_key=$(openssl pkey -in "$pki/$id/key.pem" -pubout)
  [[ $cert_key == "$own_key" ]] && ok "$id key belongs to its certificate" ||
    fail "$id key does not belong to its certificate"
  subject=$(openssl x509 -in "$pki/$id/cert.pem" -noout -subject -nameopt RFC2253 | sed 's/^subject=//')
  grep -qF "<subject_name>$subject</subject_name>" "$pki/$id/permissions.xml" &&
    ok "$id permissions name its certificate's subject ($subject)" ||
    fail "$id permissions do not name '$subject'"
done

for doc in governance "service/permissions" "operator/permissions" "admin/permissions" \
  "monitor/permissions"; do
  if openssl smime -verify -in "$pki/$doc.p7s" -CAfile "$pki/permissions_ca.pem" -text \
    -out "$work/signed.xml" 2>/dev/null; then
    if cmp -s <(tr -d '\r' <"$work/signed.xml") "$pki/$doc.xml"; then
      ok "$doc.p7s verifies with the permissions CA and carries $doc.xml"
    else
      fail "$doc.p7s verifies but does not carry $doc.xml"
    fi
  else
    fail "$doc.p7s does not verify with the permissions CA"
  fi
  if openssl smime -verify -in "$pki/$doc.p7s" -CAfile "$pki/identity_ca.pem" -out /dev/null 2>/dev/null; then
    fail "$doc.p7s verifies with the identity CA (it must be the permissions CA's)"
  fi
done
# A changed document no longer verifies: the check above is not vacuous.
sed 's/<default>DENY<\/default>/<default>ALLOW<\/default>/' "$pki/monitor/permissions.p7s" >"$work/tampered.p7s"
if openssl smime -verify -in "$work/tampered.p7s" -CAfile "$pki/permissions_ca.pem" -out /dev/null 2>/dev/null; then
  fail "a tampered permissions document still verifies"
else
  ok "a tampered permissions document does not verify"
fi

# The permissions and governance, read as XML.
# The expected topics are read from the contract (idl/dh3.idl, module dh3::topics),
# so a topic added there and not to the script's permissions fails here.
python3 - "$pki" "$src/idl/dh3.idl" <<'PY' || failures=$((failures + 1))
import re, sys, xml.etree.ElementTree as ET
pki, idl = sys.argv[1], open(sys.argv[2]).read()
topics_module = re.search(r"module topics\s*\{(.*?)\};", idl, re.S).group(1)
topics = dict(re.findall(r'const string (\w+) = "([^"]+)";', topics_module))
requests = {t for name, t in topics.items() if name.endswith("_REQUEST")}
admin_requests = {topics["ADMIN_REQUEST"]}
replies = {t for name, t in topics.items() if name.endswith("_REPLY")}
status, event, info = topics["HAND_STATUS"], topics["HAND_EVENT"], topics["SERVICE_INFO"]
owner, lease = topics["SERVICE_OWNER"], topics["HAND_LEASE"]
assert len(topics) == len(requests | replies | {status, event, info, owner, lease}), f"a topic of no known role: {topics}"
# Every client reads who owns a name (and sees its death); a service also
# reads it, to meet any other service of its name. The lease topic is a
# service's and its standby's alone.
want = {
    "service": ({status, event, info, owner, lease} | replies, requests | {owner, lease}),
    "operator": (requests - admin_requests, {status, event, info, owner} | replies),
    "admin": (requests, {status, event, info, owner} | replies),
    "monitor": (set(), {status, event, owner}),
}
bad = 0
for identity, (pub, sub) in want.items():
    grant = ET.parse(f"{pki}/{identity}/permissions.xml").getroot().find("permissions/grant")
    rule = grant.find("allow_rule")
    got_pub = {t.text for t in rule.findall("publish/topics/topic")}
    got_sub = {t.text for t in rule.findall("subscribe/topics/topic")}
    ok = got_pub == pub and got_sub == sub and grant.findtext("default") == "DENY" \
        and not grant.findall("deny_rule")
    print(("ok: " if ok else "FAILED: ") + f"{identity} publishes {sorted(got_pub)}, subscribes {sorted(got_sub)}, default DENY")
    bad += not ok
rule = ET.parse(f"{pki}/governance.xml").getroot().find("domain_access_rules/domain_rule")
checks = {
    "allow_unauthenticated_participants": "false", "enable_join_access_control": "true",
    "discovery_protection_kind": "ENCRYPT", "liveliness_protection_kind": "ENCRYPT",
    "rtps_protection_kind": "ENCRYPT",
    "topic_access_rules/topic_rule/topic_expression": "*",
    "topic_access_rules/topic_rule/enable_discovery_protection": "true",
    "topic_access_rules/topic_rule/enable_read_access_control": "true",
    "topic_access_rules/topic_rule/enable_write_access_control": "true",
    "topic_access_rules/topic_rule/metadata_protection_kind": "ENCRYPT",
    "topic_access_rules/topic_rule/data_protection_kind": "ENCRYPT",
}
for path, value in checks.items():
    got = rule.findtext(path)
    if got != value:
        print(f"FAILED: governance {path} is {got}, expected {value}")
        bad += 1
if not bad:
    print("ok: governance: authenticated only, discovery and data protected and encrypted")
# The default grants the service's default domain (dds.domain: 0) only.
for doc in ["governance.xml"] + [f"{i}/permissions.xml" for i in want]:
    ranges = ET.parse(f"{pki}/{doc}").getroot().findall(".//domains/id_range")
    got = [(r.findtext("min"), r.findtext("max")) for r in ranges]
    if got != [("0", "0")]:
        print(f"FAILED: {doc} grants domains {got}, expected only 0")
        bad += 1
sys.exit(1 if bad else 0)
PY

# One identity per name, each with its own key, granted its role's topics;
# --domains grants those domains and no others.
named=$work/named
if "$script" --domains 7-9 --operator alice --operator bob --admin carol "$named" >/dev/null; then
  for id in alice bob carol; do
    [[ -s $named/$id/cert.pem && -s $named/$id/key.pem ]] || fail "no identity $id"
  done
  [[ -e $named/operator || -e $named/admin ]] && fail "named identities and the default ones too"
  keys=$(for id in alice bob carol; do openssl pkey -in "$named/$id/key.pem" -pubout | sha256sum; done |
    sort -u | wc -l)
  [[ $keys == 3 ]] && ok "alice, bob and carol have keys of their own" ||
    fail "alice, bob and carol share keys ($keys distinct)"
  subjects=$(for id in alice bob carol; do openssl x509 -in "$named/$id/cert.pem" -noout -subject; done)
  [[ $(sort -u <<<"$subjects" | wc -l) == 3 ]] && ok "each certificate has its own subject" ||
    fail "certificates share a subject: $subjects"
  grep -q "dh3/admin_request" "$named/carol/permissions.xml" && ok "admin carol may publish admin requests" ||
    fail "admin carol may not publish admin requests"
  for id in alice bob monitor; do
    grep -q "dh3/admin_request" "$named/$id/permissions.xml" && fail "$id may publish admin requests"
  done
  grep -q "<min>7</min><max>9</max>" "$named/bob/permissions.xml" &&
    grep -q "<min>7</min><max>9</max>" "$named/governance.xml" && ok "--domains 7-9 is what is granted" ||
    fail "--domains 7-9 is not what is granted"
else
  fail "make-test-pki.sh --operator alice --operator bob --admin carol failed"
fi
for bad_args in "--operator service" "--admin x --operator x" "--operator a/b" "--domains 5-300"; do
  # shellcheck disable=SC2086  # the arguments are meant to split
  if "$script" $bad_args "$work/refused" >/dev/null 2>&1; then
    fail "make-test-pki.sh accepted $bad_args"
  fi
done
[[ -e $work/refused ]] && fail "a refused call created its DIR"
ok "refuses names of its own identities, a name twice, a path and domains beyond 232"

# Private keys and their folders are the owner's alone.
while read -r mode path; do
  case $path in
    *key.pem) [[ $mode == 600 ]] || fail "$path has mode $mode, not 600" ;;
  esac
done < <(find "$pki" -type f -printf '%m %p\n')
while read -r mode path; do
  [[ $mode == 700 ]] || fail "folder $path has mode $mode, not 700"
done < <(find "$pki" -type d -printf '%m %p\n')
ok "private keys 0600, folders 0700"

# Never into the source tree (outside build*/), never over an existing PKI.
inside=$src/deploy/security/pki-test-$$
if "$script" "$inside" >/dev/null 2>&1; then
  fail "make-test-pki.sh wrote into the source tree ($inside)"
  rm -rf "$inside"
elif [[ -e $inside ]]; then
  fail "make-test-pki.sh refused but created $inside"
  rm -rf "$inside"
else
  ok "refuses a directory inside the source tree"
fi
if "$script" "$pki" >/dev/null 2>&1; then
  fail "make-test-pki.sh replaced an existing PKI without --force"
else
  ok "keeps an existing PKI unless --force"
fi
"$script" --force "$pki" >/dev/null && ok "--force replaces it" || fail "--force did not replace it"

# Keys copied into the tree by hand would still not be committed.
if command -v git >/dev/null && git -C "$src" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  for path in deploy/security/pki/service/key.pem deploy/security/ca.key.pem; do
    git -C "$src" check-ignore -q "$path" && ok "git ignores $path" || fail "git would commit $path"
  done
fi

if ((failures)); then
  echo "$failures failure(s)"
  exit 1
fi
echo "pki: all checks passed"
