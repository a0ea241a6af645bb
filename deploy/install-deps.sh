#!/usr/bin/env bash
# Installs what dh3 needs to build, test and run, from Debian's packages only.
# Idempotent: packages already present are left alone; apt lists are refreshed
# only when something is missing. Used by the README, .ci/run and the container
# image's build stage.
#
#   deploy/install-deps.sh            build + test dependencies (default)
#   deploy/install-deps.sh --build    only what building the programs needs (the
#                                     demo, the container image's build stage)
#   deploy/install-deps.sh --runtime  only what the service and dh3ctl need to run
#   deploy/install-deps.sh --packaging  only what deploy/packages/build-debs.sh needs
#                                     to make the Debian packages from a built tree
set -euo pipefail

# libprometheus-cpp-*: dh3-service's Prometheus endpoint (--metrics).
runtime_pkgs=(
  libfastrtps2.9 libfastcdr1 libspdlog1.10 libyaml-cpp0.7 fastdds-tools
  libprometheus-cpp-core1.0 libprometheus-cpp-pull1.0
  libcpp-httplib0.11   # dh3-web's HTTP server (client/dh3-web)
)
build_pkgs=(
  build-essential cmake ninja-build pkg-config
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools
  libspdlog-dev libfmt-dev libcli11-dev libyaml-cpp-dev
  prometheus-cpp-dev
  libcpp-httplib-dev nlohmann-json3-dev   # dh3-web: HTTP server, JSON request bodies
  pybind11-dev python3-dev   # the Python module dh3 (client/python); skipped when missing
)
# deploy/packages/build-debs.sh (and so the package test): debhelper packs
# the built tree, dh-python computes python3-dh3's dependencies, help2man
# makes the man pages from --help, lintian checks the packages.
packaging_pkgs=(debhelper dh-python help2man lintian)
test_pkgs=(
  libgtest-dev libgmock-dev
  clang libclang-rt-14-dev   # libFuzzer targets (tests/fuzz)
  cyclonedds-dev cyclonedds-tools   # another DDS vendor's participant against dh3-service (tests/integration/vendor)
  tshark   # tests/ros2: the ROS 2 topic and type names as announced on the wire
  iproute2 iputils-ping procps python3 python3-yaml openssl systemd
  curl   # tests/docs (docs.examples): the HTTP API examples of README.md and docs/
  python3-pytest   # the Python module's tests (client/python/tests, ctest label python)
  # tests/kernel: a real Linux kernel with CAN, vcan and vxcan as a process
  # (the build machines' kernel has no CAN), insmod, and candump/cangen.
  user-mode-linux kmod can-utils
  universal-ctags   # tests/style: function lengths for the size check of product code
  ccache   # tests/run-all.sh: the plain, ASan and TSan builds share compiled objects across runs
  nftables   # tests/scale: the plant's bridge counts discovery and data bytes apart
  python3-matplotlib   # tests/scale/plot.py: the plant's figures as PNG (BENCHMARKS.md)
  chromium chromium-driver python3-selenium   # tests/web: dh3-web's page in a headless browser
)

case ${1:-} in
  --runtime) want=("${runtime_pkgs[@]}") ;;
  --build) want=("${build_pkgs[@]}") ;;
  --packaging) want=("${packaging_pkgs[@]}") ;;
  "") want=("${build_pkgs[@]}" "${test_pkgs[@]}" "${packaging_pkgs[@]}") ;;
  *) echo "usage: $0 [--build|--runtime|--packaging]" >&2; exit 2 ;;
esac

missing=()
for p in "${want[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#want[@]} packages present"
  exit 0
fi

sudo=()
[[ $(id -u) -ne 0 ]] && sudo=(sudo)
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
