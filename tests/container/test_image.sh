#!/usr/bin/env bash
# The image, built for real: deploy/container/build-image.sh (installs podman
# and mmdebstrap if missing, makes the Debian base images from this machine's
# apt sources unless podman has them, builds deploy/container/Dockerfile with
# the build stage's script run on this machine: --prebuilt), then
# what a user of the image relies on: the health check survived the build, the
# user is the unprivileged 10001, every program the Compose file and the
# Kubernetes manifests run is in it and starts, apt left no cache behind.
# The other container tests run this image.
#
#   test_image.sh SOURCE_DIR CHECK_CONFIG
# Exit 77 (skipped) with the reason where no container engine can run.
SRC=$1 check_config=$2
source "$(dirname "$0")/lib.sh"
[[ $(id -u) -eq 0 ]] || skip "needs root (rootful podman; CI runs as root)"

# The build stage's context: a tree of only what its COPY lines copy configures.
mkdir -p "$work/context"
awk '/^FROM / && ++stages > 1 { exit }
     { line = line $0 } /\\$/ { sub(/\\$/, " ", line); next }
     { if (line ~ /^COPY / && line !~ /--from/) { n = split(line, w, /[ \t]+/)
         for (i = 2; i < n; i++) print w[i] }
       line = "" }' "$SRC/deploy/container/Dockerfile" >"$work/copied"
while read -r path; do
  mkdir -p "$work/context/$(dirname "$path")" && cp -a "$SRC/$path" "$work/context/$path"
done <"$work/copied"
if cmake -S "$work/context" -B "$work/context/build" -G Ninja -DDH3_BUILD_TESTS=OFF \
  -DDH3_BUILD_PYTHON=OFF >"$work/configure.log" 2>&1; then
  ok "the build stage's $(wc -l <"$work/copied") COPY sources configure the project"
else
  tail -n 20 "$work/configure.log"
  fail "the build stage's COPY lines leave out what the build needs"
fi

start=$SECONDS
# The build stage's script, run here: with the test command's compiler cache
# and flags (tests/run-all.sh) and its build tree beside the test command's,
# it compiles nothing again. The image is built around what it staged.
if DH3_WERROR=ON JOBS=2 "$SRC/deploy/container/build-in-image.sh" "$SRC/build-image" "$work/stage" \
  >"$work/stage.log" 2>&1; then
  ok "build-in-image.sh staged the image's programs in $((SECONDS - start)) s"
else
  tail -n 40 "$work/stage.log"
  fail "build-in-image.sh failed"
  finish image
fi
start=$SECONDS
# build-image.sh installs podman itself; only then can we ask whether it runs.
"$SRC/deploy/container/build-image.sh" --tag "$image" --prebuilt "$work/stage" >"$work/build.log" 2>&1
status=$?
grep -E '^build-image:|STEP [0-9]+/' "$work/build.log"
if ((status != 0)); then
  # build-image.sh installs podman itself; only then can one ask whether it runs.
  if ! podman info >"$work/info" 2>&1; then
    skip "podman cannot run here: $(tail -n 1 "$work/info")"
  fi
  tail -n 40 "$work/build.log"
  fail "build-image.sh failed (exit $status)"
  finish image
fi
ok "build-image.sh built $image in $((SECONDS - start)) s (base images, runtime stage)"

healthcheck=$(podman image inspect --format '{{json .Config.Healthcheck}}' "$image")
[[ $healthcheck == '{"Test":["CMD","dh3-healthcheck"]'* ]] &&
  ok "the HEALTHCHECK survived the build (Docker image format): $healthcheck" ||
  fail "no HEALTHCHECK dh3-healthcheck in the image: $healthcheck"
user=$(podman image inspect --format '{{.Config.User}}' "$image")
[[ $user == 10001:10001 ]] && ok "image user $user" || fail "image user is '$user', not 10001:10001"
for base in debian:bookworm debian:bookworm-slim; do
  podman image exists "$base" && ok "base $base is local" || fail "no local $base"
done
size=$(podman image inspect --format '{{.Size}}' "$image")
echo "image size: $((size / 1000000)) MB ($size bytes)"

# Every program the Compose file and the manifests run, and the image's own.
mapfile -t programs < <(python3 "$SRC/tests/deploy/check_manifests.py" "$SRC" "$check_config" \
  --print-programs | sed -n 's/^program //p')
((${#programs[@]} >= 4)) || fail "check_manifests.py named only ${#programs[@]} programs: ${programs[*]}"
client --entrypoint sh "$image" -c '
  for p in "$@"; do command -v "$p" >/dev/null && echo "in the image: $p" || echo "MISSING: $p"; done
' sh "${programs[@]}" dh3ctl dh3-sim event_watcher >"$work/programs" 2>&1
cat "$work/programs"
grep -q MISSING "$work/programs" && fail "programs missing from the image"
for run in "dh3-service --version" "dh3ctl --version" "dh3-sim --help" "pick_loop --help" \
  "event_watcher --help"; do
  if out=$(client --entrypoint "${run%% *}" "$image" ${run#* } 2>&1); then
    ok "runs: $run: $(head -n 1 <<<"$out")"
  else
    fail "$run: $out"
  fi
done

# apt's lists and package cache are not in the runtime image.
left=$(client --entrypoint sh "$image" -c \
  'ls /var/lib/apt/lists /var/cache/apt/archives 2>/dev/null | grep -c -e "_Packages" -e "\.deb$"')
[[ $left == 0 ]] && ok "no apt lists or packages left in the image" ||
  fail "$left apt list or package files left in the image"
finish image
