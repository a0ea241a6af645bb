#!/usr/bin/env bash
# Makes dh3's Debian packages from a tree CMake has built, with debhelper:
#
#   deploy/packages/build-debs.sh [--version-suffix SUFFIX] [--out DIR] [BUILD_DIR]
#
#   dh3-service       dh3-service, /etc/dh3/dh3.yaml (conffile; the simulator),
#                     the unit dh3.service (enabled and started), the user dh3
#                     (sysusers; removed on purge), the Fast DDS XML profiles
#   dh3-tools         dh3ctl, dh3-sim
#   dh3-web           dh3-web, the unit dh3-web.service (enabled and started),
#                     the user dh3-web, the token /etc/dh3/web.token (made at install)
#   libdh3client0.1   libdh3client.so.0.1 (the package is named after the soname)
#   libdh3client-dev  headers, the CMake package dh3client, example programs
#   python3-dh3       the Python module dh3
#
# BUILD_DIR (default: build) is the CMake tree the packages are made from
# (tests/run-all.sh's is Release); one that does not exist yet is configured
# as Release without the tests (build dependencies from
# deploy/install-deps.sh --build). The
# programs are built there if they are not up to date, and nothing is
# compiled again for the packages: the debian/ folder beside this script
# installs the tree with `cmake --install`.
# The version is the project's (CMake's project VERSION, read from the tree)
# followed by SUFFIX (e.g. +1: a higher version of the same tree, to try an
# upgrade). The packages go to DIR (default: BUILD_DIR/debs); earlier dh3
# packages there are removed first. Dependencies are computed (dpkg-shlibdeps,
# dh_python3). Installs the packaging tools if missing
# (deploy/install-deps.sh --packaging). JOBS (default 2) for the build step.
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd -P)
suffix=
out=
build=
while (($#)); do
  case $1 in
    --version-suffix) suffix=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -h | --help) sed -n '2,28s/^# \{0,1\}//p' "$0"; exit 0 ;;
    -*) echo "build-debs: unknown option $1" >&2; exit 2 ;;
    *) [[ -z $build ]] || { echo "build-debs: one BUILD_DIR only" >&2; exit 2; }; build=$1; shift ;;
  esac
done
build=${build:-build}
say() { echo "build-debs: $*"; }
if [[ ! -f $build/CMakeCache.txt ]]; then
  say "configuring $build (Release)"
  "$src/deploy/install-deps.sh" --build
  cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DDH3_BUILD_TESTS=OFF >/dev/null
fi
build=$(cd "$build" && pwd -P)
out=${out:-$build/debs}
cache=$build/CMakeCache.txt
cached() { sed -n "s/^$1:[A-Z]*=//p" "$cache"; }
version=$(cached CMAKE_PROJECT_VERSION)$suffix
[[ $version =~ ^[0-9][A-Za-z0-9.+~]*$ ]] || { echo "build-debs: '$version' is not a native Debian version" >&2; exit 1; }
say "dh3 $version from $build ($(cached CMAKE_BUILD_TYPE) build)"

"$src/deploy/install-deps.sh" --packaging

# What the packages install, built if it is not up to date (a no-op after the
# test command's build).
cmake --build "$build" -j "${JOBS:-2}" --target dh3-service dh3-sim dh3ctl dh3-web dh3client \
  pick_loop event_watcher dh3_python

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tree=$work/dh3-$version
mkdir -p "$tree"
cp -r "$src/deploy/packages/debian" "$tree/debian"
# The changelog carries the version; its date is the commit's, so the same
# tree makes the same packages.
commit=$(git -C "$src" describe --always --dirty 2>/dev/null || echo unknown)
date=$(git -C "$src" log -1 --format=%aD 2>/dev/null || date -R)
maintainer=$(sed -n 's/^Maintainer: //p' "$tree/debian/control")
cat >"$tree/debian/changelog" <<EOF
dh3 ($version) unstable; urgency=medium

  * Built from the dh3 repository at $commit.

 -- $maintainer  $date
EOF

say "dpkg-buildpackage -b (debhelper; log: $out/build-debs.log)"
mkdir -p "$out"
log=$out/build-debs.log
if ! (cd "$tree" && DH3_BUILD_DIR=$build DH3_SOURCE_DIR=$src dpkg-buildpackage -b -uc -us) >"$log" 2>&1; then
  tail -n 40 "$log" >&2
  echo "build-debs: dpkg-buildpackage failed (whole log: $log)" >&2
  exit 1
fi

packages=(dh3-service dh3-tools dh3-web libdh3client0.1 libdh3client-dev python3-dh3)
for p in "${packages[@]}"; do rm -f "$out/${p}_"*.deb; done
rm -f "$out"/dh3_*.buildinfo "$out"/dh3_*.changes
for p in "${packages[@]}"; do
  deb=("$work/${p}_${version}_"*.deb)
  [[ -f ${deb[0]} ]] || { echo "build-debs: no package $p was made" >&2; exit 1; }
  mv "${deb[0]}" "$out/"
  printf 'build-debs: %-40s %6d KiB  Depends: %s\n' "$(basename "${deb[0]}")" \
    $(($(stat -c %s "$out/$(basename "${deb[0]}")") / 1024)) "$(dpkg-deb -f "$out/$(basename "${deb[0]}")" Depends)"
done
mv "$work"/dh3_*.changes "$work"/dh3_*.buildinfo "$out/" 2>/dev/null || true
say "packages in $out"
