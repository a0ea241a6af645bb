#!/usr/bin/env bash
# The ROS 2 layout test: ros2_golden's bytes against npm's encoder.
#   run_golden.sh ROS2_GOLDEN NPM_DIR
set -euo pipefail
golden=$1
npm_dir=$2
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "SKIP: Node.js and npm are not installed: the ROS 2 message layouts are compared with npm's @foxglove/rosmsg2-serialization"
  exit 77
fi
if [[ ! -d $npm_dir/node_modules/@foxglove/rosmsg2-serialization ]]; then
  echo "npm's @foxglove encoder is not in $npm_dir: tests/run-all.sh installs it" \
    "(tests/ros2/install-npm.sh $npm_dir)"
  exit 1
fi
"$golden" >"$npm_dir/golden.txt"
NODE_PATH=$npm_dir/node_modules node "$(dirname "$0")/check_golden.js" <"$npm_dir/golden.txt"
