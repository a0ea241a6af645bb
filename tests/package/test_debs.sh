#!/usr/bin/env bash
# dh3's Debian packages made from this build tree, as the README says
# (deploy/packages/build-debs.sh): twice, at the project's version into DEBS
# and at a higher one into UPGRADE_DEBS (package.install upgrades to it).
# Checked: the six packages are there with the project's version, each holds
# what it promises (the service, its conffile, unit, sysusers file and
# profiles; the tools; dh3-web and its unit; the library; headers and CMake package; the Python
# module), their dependencies were computed (Fast DDS and the others by
# dpkg-shlibdeps, Python by dh_python3, the library by its shlibs), and
# lintian finds neither errors nor warnings.
#
#   test_debs.sh SOURCE_DIR BUILD_DIR DEBS UPGRADE_DEBS
set -uo pipefail
src=$1 build=$2 debs=$3 upgrade_debs=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAILED: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; }
started=$SECONDS

project_version=$(sed -n 's/^CMAKE_PROJECT_VERSION:[A-Z]*=//p' "$build/CMakeCache.txt")
if ! "$src/deploy/packages/build-debs.sh" --out "$debs" "$build" >"$work/build" 2>&1; then
  cat "$work/build"
  fail "build-debs.sh failed"
  exit 1
fi
grep '^build-debs:' "$work/build"
ok "build-debs.sh made the packages in $((SECONDS - started)) s"
if "$src/deploy/packages/build-debs.sh" --version-suffix +1 --out "$upgrade_debs" "$build" >"$work/build" 2>&1; then
  ok "build-debs.sh --version-suffix +1: the packages at $project_version+1 in $upgrade_debs"
else
  cat "$work/build"
  fail "build-debs.sh --version-suffix +1 failed"
fi

deb() { compgen -G "$debs/${1}_*.deb" | head -n 1; }
for p in dh3-service dh3-tools dh3-web libdh3client0.1 libdh3client-dev python3-dh3; do
  file=$(deb "$p")
  if [[ -z $file ]]; then
    fail "no package $p"
    continue
  fi
  v=$(dpkg-deb -f "$file" Version)
  [[ $v == "$project_version" ]] && ok "$p $v ($(($(stat -c %s "$file") / 1024)) KiB)" ||
    fail "$p has version $v, not the project's $project_version"
done

# has PACKAGE PATH...: the package holds every PATH.
has() {
  local p=$1 path
  shift
  dpkg-deb -c "$(deb "$p")" | awk '{print $6}' | sed 's|^\./|/|; s|/$||' >"$work/files"
  for path in "$@"; do
    grep -qx -- "$path" "$work/files" && ok "$p has $path" || fail "$p lacks $path"
  done
}
has dh3-service /usr/bin/dh3-service /etc/dh3/dh3.yaml /lib/systemd/system/dh3.service \
  /usr/lib/sysusers.d/dh3.conf /usr/share/dh3/dds/udp_only.xml /usr/share/dh3/dds/secure.xml \
  /usr/share/dh3/dds/discovery_client.xml /usr/share/man/man1/dh3-service.1.gz
has dh3-tools /usr/bin/dh3ctl /usr/bin/dh3-sim /usr/share/man/man1/dh3ctl.1.gz
has dh3-web /usr/bin/dh3-web /lib/systemd/system/dh3-web.service /usr/share/man/man1/dh3-web.1.gz
has libdh3client0.1 /usr/lib/libdh3client.so.0.1
has libdh3client-dev /usr/include/dh3/client.hpp /usr/lib/libdh3client.so \
  /usr/lib/cmake/dh3client/dh3clientConfig.cmake /usr/lib/cmake/dh3client/dh3clientTargets.cmake
has python3-dh3 /usr/lib/python3/dist-packages/dh3/__init__.py /usr/lib/python3/dist-packages/dh3/py.typed
# Read whole, not piped into grep -q: an early close would be a SIGPIPE under pipefail.
dpkg-deb -c "$(deb python3-dh3)" >"$work/files"
grep -q 'dist-packages/dh3/_dh3\.cpython-.*\.so$' "$work/files" &&
  ok "python3-dh3 has the extension module" || fail "python3-dh3 lacks dh3/_dh3.cpython-*.so"

dpkg-deb --ctrl-tarfile "$(deb dh3-service)" | tar -xO ./conffiles >"$work/conffiles" 2>/dev/null
grep -qx /etc/dh3/dh3.yaml "$work/conffiles" && ok "/etc/dh3/dh3.yaml is a conffile" ||
  fail "/etc/dh3/dh3.yaml is not a conffile: $(cat "$work/conffiles")"
dpkg-deb --ctrl-tarfile "$(deb dh3-service)" | tar -xO ./postinst >"$work/postinst" 2>/dev/null
grep -q 'systemd-sysusers.*dh3.conf' "$work/postinst" && ok "postinst makes the user (systemd-sysusers dh3.conf)" ||
  fail "postinst does not run systemd-sysusers"
grep -q 'deb-systemd-helper enable .*dh3.service' "$work/postinst" && ok "postinst enables dh3.service" ||
  fail "postinst does not enable dh3.service"
dpkg-deb --ctrl-tarfile "$(deb dh3-service)" | tar -xO ./postrm >"$work/postrm" 2>/dev/null
grep -q 'userdel dh3' "$work/postrm" && ok "postrm removes the user on purge" || fail "postrm keeps the user"
dpkg-deb --ctrl-tarfile "$(deb libdh3client0.1)" | tar -xO ./shlibs >"$work/shlibs" 2>/dev/null
grep -q '^libdh3client 0.1 libdh3client0.1 (>= ' "$work/shlibs" && ok "libdh3client0.1's shlibs: $(cat "$work/shlibs")" ||
  fail "libdh3client0.1 has no shlibs entry: $(cat "$work/shlibs")"

# depends PACKAGE REGEX...: each REGEX matches one of the package's dependencies.
depends() {
  local p=$1 want
  shift
  local got
  got=$(dpkg-deb -f "$(deb "$p")" Depends)
  for want in "$@"; do
    tr ',' '\n' <<<"$got" | sed 's/^ *//' | grep -qE -- "^($want)" && ok "$p depends on $want" ||
      fail "$p does not depend on $want: $got"
  done
}
depends dh3-service 'libfastrtps2\.9' 'libfastcdr1' 'libspdlog1\.10' 'libyaml-cpp0\.7' \
  'libprometheus-cpp-pull1\.0' 'libc6 \(>= ' 'systemd'
depends dh3-tools 'libdh3client0\.1 \(>= ' 'libc6 \(>= '
depends dh3-web 'libdh3client0\.1 \(>= ' 'libcpp-httplib0\.11'
depends libdh3client0.1 'libfastrtps2\.9' 'libfastcdr1'
depends libdh3client-dev "libdh3client0\\.1 \\(= $project_version\\)"
depends python3-dh3 'python3 \(>= 3\.' 'python3 \(<< 3\.' 'libdh3client0\.1 \(>= '

# lintian: neither errors nor warnings. Its notes (I:) are printed: the
# hardening ones say the tree was not built with dpkg-buildflags' hardening
# flags (docs/operations.md, "Installing on a cell PC").
lintian --tag-display-limit 0 --display-level '>=info' "$debs"/*.deb >"$work/lintian" 2>"$work/lintian.err"
lintian_status=$?
echo "lintian $(dpkg-query -W -f '${Version}' lintian 2>/dev/null) on the packages:"
sed 's/^/  /' "$work/lintian"
grep -v 'running with root privileges is not recommended' "$work/lintian.err" | sed 's/^/  lintian: /'
if ((lintian_status != 0)) || grep -q '^[EW]: ' "$work/lintian"; then
  fail "lintian reports $(grep -c '^E: ' "$work/lintian") error(s) and $(grep -c '^W: ' "$work/lintian") warning(s) (exit $lintian_status)"
else
  ok "lintian: no errors, no warnings ($(grep -c '^I: ' "$work/lintian") notes)"
fi

echo "package.debs took $((SECONDS - started)) s"
if ((failures)); then
  echo "$failures failure(s)"
  exit 1
fi
echo "packages: all checks passed"
