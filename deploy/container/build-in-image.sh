#!/usr/bin/env bash
# The container image's build stage, as one script the Dockerfile runs (the
# test container.image builds the image with it). It also runs outside a
# container, on a Debian 12 machine, to see what the runtime stage gets.
#
#   deploy/container/build-in-image.sh BUILD_DIR STAGE_DIR
#
# Installs the build dependencies (deploy/install-deps.sh --build), configures and
# builds the source tree this script is in (Release, no tests), and installs
# into STAGE_DIR what the runtime image gets, laid out as in the image's root:
#
#   usr/local/bin/      dh3-service, dh3ctl, dh3-sim, pick_loop, event_watcher,
#                       dh3-healthcheck, dh3-discovery-server
#   usr/local/lib/      libdh3client.so*
#   usr/local/share/dh3/dds/   the Fast DDS XML profiles (udp_only, discovery_client, secure)
#   etc/dh3/dh3.yaml    the default configuration: the simulator (deploy/config/dh3-sim.yaml)
#
# JOBS (default: the number of processors) sets the build's parallelism.
set -euo pipefail
[[ $# -eq 2 ]] || { echo "usage: build-in-image.sh BUILD_DIR STAGE_DIR" >&2; exit 2; }
src=$(cd "$(dirname "$0")/../.." && pwd -P)
build=$1
stage=$2
jobs=${JOBS:-$(nproc)}
prefix=/usr/local

"$src/deploy/install-deps.sh" --build

# Warnings are errors in the development build (tests/run-all.sh); a release
# image must not fail to build over a new compiler's false positive at -O3.
# DH3_WERROR=ON builds with the development build's flags: outside a container,
# with CMAKE_CXX_COMPILER_LAUNCHER=ccache as tests/run-all.sh sets it and
# BUILD_DIR beside the development build, nothing is compiled twice (the image
# test stages the image's programs so: build-image.sh --prebuilt).
cmake -S "$src" -B "$build" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DDH3_BUILD_TESTS=OFF -DDH3_BUILD_PYTHON=OFF \
  -DDH3_WERROR="${DH3_WERROR:-OFF}" -DCMAKE_INSTALL_PREFIX="$prefix"
cmake --build "$build" -j "$jobs"

rm -rf "$stage"
DESTDIR="$stage" cmake --install "$build"
# The examples are built but not installed by the project; the compose file's
# client container runs pick_loop.
for example in pick_loop event_watcher; do
  install -D -m 0755 "$build/client/$example" "$stage$prefix/bin/$example"
done
# Headers and the CMake package are for building against libdh3client; the
# runtime image does not build anything.
rm -rf "$stage$prefix/include" "$stage$prefix/lib/cmake" "$stage$prefix/share/doc"

install -D -m 0755 "$src/deploy/container/healthcheck.sh" "$stage$prefix/bin/dh3-healthcheck"
install -D -m 0755 "$src/deploy/container/discovery-server.sh" "$stage$prefix/bin/dh3-discovery-server"
install -d -m 0755 "$stage$prefix/share/dh3/dds"
install -m 0644 "$src"/deploy/dds/*.xml "$stage$prefix/share/dh3/dds/"
install -D -m 0644 "$src/deploy/config/dh3-sim.yaml" "$stage/etc/dh3/dh3.yaml"
echo "build-in-image: staged into $stage"
