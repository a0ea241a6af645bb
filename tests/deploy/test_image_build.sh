#!/usr/bin/env bash
# The container image's build stage, run here: deploy/container/build-in-image.sh
# (the script the Dockerfile's build stage runs) into a build tree of this
# test, then the checks of what the runtime stage would get, which no
# container engine runs here.
#
#   test_image_build.sh SOURCE_DIR WORK_DIR CHECK_CONFIG
# JOBS (default 2) sets the build's parallelism.
set -euo pipefail
src=$1 work=$2 check_config=$3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"

echo "== build stage: deploy/container/build-in-image.sh"
JOBS=${JOBS:-2} "$src/deploy/container/build-in-image.sh" "$work/build" "$work/stage"

echo "== runtime stage: deploy/install-deps.sh --runtime finds its packages"
"$src/deploy/install-deps.sh" --runtime

echo "== what the runtime stage gets"
python3 "$here/check_image_stage.py" "$src" "$work/stage"

echo "== the manifests' programs are in the image"
python3 "$here/check_manifests.py" "$src" "$check_config" --stage "$work/stage"
