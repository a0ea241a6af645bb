#!/usr/bin/env bash
# deploy/'s YAML files parse, name only files that exist, agree with each
# other, and carry only configurations dh3-service accepts.
#   test_manifests.sh SOURCE_DIR CHECK_CONFIG
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
python3 -c 'import yaml' 2>/dev/null || { echo "FAILED: python3 has no yaml module (Debian: python3-yaml)"; exit 1; }
exec python3 "$here/check_manifests.py" "$1" "$2"
