#!/usr/bin/env bash
# Installs the independent ROS 2 encoder the layout test compares with (npm,
# test-only, pinned) into DIR/node_modules. Does nothing when they are there;
# exits 0 without npm (the test then skips and says why).
#   tests/ros2/install-npm.sh DIR
set -euo pipefail
dir=${1:?usage: $0 DIR}
packages=(@foxglove/rosmsg2-serialization@3.1.0 @foxglove/rosmsg-msgs-common@3.2.3)
if ! command -v npm >/dev/null; then
  echo "install-npm: npm is not installed; the ROS 2 layout test will skip"
  exit 0
fi
if [[ -d $dir/node_modules/@foxglove/rosmsg2-serialization &&
  -d $dir/node_modules/@foxglove/rosmsg-msgs-common ]]; then
  echo "install-npm: present in $dir"
  exit 0
fi
mkdir -p "$dir"
npm install --no-audit --no-fund --prefix "$dir" "${packages[@]}"
